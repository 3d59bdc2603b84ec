#include <meccano/surface/rim_chords.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace meccano {
namespace {

using Triangle = std::array<int, 3>;

std::uint64_t edge_key(int a, int b) {
  const auto [lo, hi] = std::minmax(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(lo)) << 32) | static_cast<std::uint32_t>(hi);
}

// The triangles on each edge, kept up to date while triangles are split.
class EdgeTriangles {
 public:
  explicit EdgeTriangles(const std::vector<Triangle>& triangles) {
    for (int t = 0; t < static_cast<int>(triangles.size()); ++t) add(triangles[t], t);
  }
  const std::vector<int>& on(int a, int b) const { return map_.at(edge_key(a, b)); }
  void add(const Triangle& triangle, int t) {
    for (int k = 0; k < 3; ++k) map_[edge_key(triangle[k], triangle[(k + 1) % 3])].push_back(t);
  }
  void remove(const Triangle& triangle, int t) {
    for (int k = 0; k < 3; ++k) {
      auto found = map_.find(edge_key(triangle[k], triangle[(k + 1) % 3]));
      std::erase(found->second, t);
      if (found->second.empty()) map_.erase(found);
    }
  }
  // Interior edges (two triangles) whose ends are both rim vertices, in a fixed order.
  std::vector<std::pair<int, int>> rim_chords(std::size_t vertex_count) const {
    std::vector<std::uint8_t> on_rim(vertex_count, 0);
    for (const auto& [key, triangles] : map_)
      if (triangles.size() == 1) on_rim[ends(key).first] = on_rim[ends(key).second] = 1;
    std::vector<std::pair<int, int>> chords;
    for (const auto& [key, triangles] : map_) {
      const auto [a, b] = ends(key);
      if (triangles.size() == 2 && on_rim[a] && on_rim[b]) chords.emplace_back(a, b);
    }
    std::ranges::sort(chords);  // the map's order depends on the library; the split must not
    return chords;
  }

 private:
  static std::pair<int, int> ends(std::uint64_t key) {
    return {static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffU)};
  }
  std::unordered_map<std::uint64_t, std::vector<int>> map_;
};

// Triangle t rotated so that its edge a-b (in either direction) comes first.
Triangle chord_first(const Triangle& t, int a, int b) {
  for (int k = 0;; ++k) {
    const int next = t[(k + 1) % 3];
    if ((t[k] == a && next == b) || (t[k] == b && next == a)) return {t[k], next, t[(k + 2) % 3]};
  }
}

}  // namespace

int count_rim_chords(const TriangleSurface& surface) {
  return static_cast<int>(EdgeTriangles(surface.triangles).rim_chords(surface.points.size()).size());
}

TriangleSurface split_rim_chords(const TriangleSurface& surface) {
  TriangleSurface split = surface;
  EdgeTriangles edges(split.triangles);
  // Splitting a chord adds edges to the new vertex only, which is interior: no chord appears, and the
  // others stay edges (of the halves), so one pass over the chords found at the start splits them all.
  for (const auto& [a, b] : edges.rim_chords(surface.points.size())) {
    const int m = static_cast<int>(split.points.size());
    split.points.push_back(0.5 * (split.points[a] + split.points[b]));
    const std::vector<int> sides = edges.on(a, b);  // a copy: the splits below change the map
    for (const int t : sides) {
      // In t's own cyclic order the chord runs p -> q, r opposite: (p, q, r) becomes (p, m, r) and
      // (m, q, r), both in t's orientation.
      const auto [p, q, r] = chord_first(split.triangles[t], a, b);
      edges.remove(split.triangles[t], t);
      split.triangles[t] = {p, m, r};
      edges.add(split.triangles[t], t);
      split.triangles.push_back({m, q, r});
      edges.add(split.triangles.back(), static_cast<int>(split.triangles.size()) - 1);
    }
  }
  return split;
}

}  // namespace meccano
