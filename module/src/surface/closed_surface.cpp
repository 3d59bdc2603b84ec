#include <meccano/surface/closed_surface.hpp>

#include "mesh/topology_helpers.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace meccano {

bool is_closed(const TriangleSurface& surface) {
  detail::TopologyScratch scratch;
  return !surface.triangles.empty() && detail::triangle_topology(surface.triangles, scratch).boundary_edges == 0;
}

double enclosed_volume(const TriangleSurface& surface) {
  // The divergence theorem over the tets joining each triangle to a point of S (its first point), which
  // keeps the terms small far from the origin (UTM coordinates).
  if (surface.points.empty()) return 0.0;
  const Eigen::Vector3d origin = surface.points.front();
  double six_volumes = 0.0;
  for (const auto& t : surface.triangles)
    six_volumes +=
        (surface.points[t[0]] - origin).dot((surface.points[t[1]] - origin).cross(surface.points[t[2]] - origin));
  return six_volumes / 6.0;
}

TriangleSurface oriented_outward(TriangleSurface surface) {
  if (enclosed_volume(surface) < 0.0)
    for (auto& t : surface.triangles) std::swap(t[1], t[2]);
  return surface;
}

namespace {

Eigen::Vector3d on_edge(std::span<const Eigen::Vector3d> points, const EdgeCrossing& at) {
  return points[at.low] + at.fraction * (points[at.high] - points[at.low]);
}

}  // namespace

std::vector<Eigen::Vector3d> crossing_points(std::vector<Eigen::Vector3d> points,
                                             std::span<const EdgeCrossing> crossings) {
  const std::size_t count = points.size();
  points.reserve(count + crossings.size());
  for (const EdgeCrossing& at : crossings) points.push_back(on_edge(std::span(points).first(count), at));
  return points;
}

std::optional<PlaneCut> cut_by_plane(const TriangleSurface& surface, int axis, double offset) {
  PlaneCut cut;
  cut.points = surface.points;
  std::vector<double> height(cut.points.size());
  for (std::size_t v = 0; v < height.size(); ++v) height[v] = cut.points[v][axis] - offset;
  // Vertices nearly on the plane, seen from an edge that crosses it, count as on it (where they are: S
  // keeps its geometry): a crossing there would leave a sliver.
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (height[a] * height[b] >= 0.0) continue;
      const double span = std::abs(height[a] - height[b]);
      for (int v : {a, b})
        if (std::abs(height[v]) < cut_snap * span) height[v] = 0.0;
    }

  std::map<detail::Edge, int> crossing_of;  // ordered: the crossings' ids do not depend on hashing
  auto crossing = [&](int a, int b) {
    const auto [it, added] = crossing_of.try_emplace(detail::make_edge(a, b), static_cast<int>(cut.points.size()));
    if (added) {
      const int low = it->first.first, high = it->first.second;  // the same point from either triangle
      cut.crossings.push_back({low, high, height[low] / (height[low] - height[high])});
      cut.points.push_back(on_edge(cut.points, cut.crossings.back()));
    }
    return it->second;
  };
  for (const auto& t : surface.triangles) {
    std::array<int, 3> sign{};
    for (int k = 0; k < 3; ++k) sign[k] = (height[t[k]] > 0.0) - (height[t[k]] < 0.0);
    if (sign[0] == 0 && sign[1] == 0 && sign[2] == 0) return std::nullopt;
    // The triangle's polygon on each side: its vertices there (those on the plane on both), and the
    // crossings of its edges, in the triangle's own order; each is convex, so a fan triangulates it.
    std::array<std::vector<int>, 2> polygon;  // below, above
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (sign[k] <= 0) polygon[0].push_back(a);
      if (sign[k] >= 0) polygon[1].push_back(a);
      if (sign[k] * sign[(k + 1) % 3] < 0) {
        const int x = crossing(a, b);
        polygon[0].push_back(x);
        polygon[1].push_back(x);
      }
    }
    for (int side = 0; side < 2; ++side) {
      const std::vector<int>& p = polygon[side];
      auto& part = side == 0 ? cut.below : cut.above;
      for (std::size_t k = 2; k < p.size(); ++k) part.push_back({p[0], p[k - 1], p[k]});
    }
  }
  return cut;
}

TriangleSurface triangulate_star_shaped(const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& place, int n,
                                        std::string name) {
  TriangleSurface surface;
  surface.name = std::move(name);
  std::map<std::array<int, 3>, int> index;  // integer point on the octahedron, times n
  auto point = [&](const std::array<int, 3>& q) {
    const auto [it, added] = index.try_emplace(q, static_cast<int>(surface.points.size()));
    if (added) surface.points.push_back(place(Eigen::Vector3d(q[0], q[1], q[2]).normalized()));
    return it->second;
  };
  for (int face = 0; face < 8; ++face) {
    const std::array<int, 3> sign{face & 1 ? -1 : 1, face & 2 ? -1 : 1, face & 4 ? -1 : 1};
    auto at = [&](int a, int b) { return std::array<int, 3>{sign[0] * a, sign[1] * b, sign[2] * (n - a - b)}; };
    auto add = [&](std::array<int, 3> p, std::array<int, 3> q, std::array<int, 3> r) {
      // Out of the octahedron, decided on the octahedron itself (along the face's normal, `sign`).
      const Eigen::Vector3d u(q[0] - p[0], q[1] - p[1], q[2] - p[2]), v(r[0] - p[0], r[1] - p[1], r[2] - p[2]);
      if (u.cross(v).dot(Eigen::Vector3d(sign[0], sign[1], sign[2])) < 0) std::swap(q, r);
      surface.triangles.push_back({point(p), point(q), point(r)});
    };
    for (int a = 0; a < n; ++a)
      for (int b = 0; a + b < n; ++b) {
        add(at(a, b), at(a + 1, b), at(a, b + 1));
        if (a + b + 2 <= n) add(at(a + 1, b), at(a + 1, b + 1), at(a, b + 1));
      }
  }
  return surface;
}

}  // namespace meccano
