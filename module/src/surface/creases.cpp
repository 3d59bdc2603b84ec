#include <meccano/surface/creases.hpp>

#include <meccano/geometry/geometry.hpp>

#include "mesh/topology_helpers.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace meccano {
namespace {

using detail::Edge;
using detail::edges_with_triangles;
using Eigen::Vector2d;
using Eigen::Vector3d;


// The crease edges of S (with their angles) and the vertices on its rim.
struct CreaseGraph {
  std::vector<std::vector<std::pair<int, double>>> neighbours;  // per vertex: (vertex across, angle)
  std::vector<std::uint8_t> on_rim;
};

CreaseGraph crease_graph(const TriangleSurface& surface, double angle) {
  std::vector<Vector3d> normals;
  normals.reserve(surface.triangles.size());
  for (const auto& [a, b, c] : surface.triangles)
    normals.push_back(
        (surface.points[b] - surface.points[a]).cross(surface.points[c] - surface.points[a]).normalized());
  CreaseGraph graph{std::vector<std::vector<std::pair<int, double>>>(surface.points.size()),
                    std::vector<std::uint8_t>(surface.points.size(), 0)};
  const auto edges = edges_with_triangles(surface.triangles);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    const auto [a, b] = edges[i].first;
    if (j - i == 1) {
      graph.on_rim[a] = graph.on_rim[b] = 1;
    } else if (j - i == 2) {
      const Vector3d& n = normals[edges[i].second];
      const Vector3d& m = normals[edges[i + 1].second];
      const double degrees = std::atan2(n.cross(m).norm(), n.dot(m)) * 180.0 / std::numbers::pi;
      if (degrees > angle) {
        graph.neighbours[a].push_back({b, degrees});
        graph.neighbours[b].push_back({a, degrees});
      }
    }
    i = j;
  }
  return graph;
}

// A point of P where a line crosses an S_M edge, at arc length s along the line.
using Crossing = CreaseCrossing;

// S_M's edges in a uniform grid over P, for the crossings of a segment.
class EdgeGrid {
 public:
  EdgeGrid(std::span<const std::array<int, 3>> triangles, std::span<const Vector2d> uv) : uv_(uv) {
    for (const auto& [edge, t] : edges_with_triangles(triangles))
      if (edges_.empty() || edges_.back() != edge) edges_.push_back(edge);
    size_ = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(edges_.size()))));
    cells_.resize(static_cast<std::size_t>(size_) * size_);
    for (int e = 0; e < static_cast<int>(edges_.size()); ++e) {
      const auto [lo, hi] = cell_range(uv_[edges_[e].first], uv_[edges_[e].second]);
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) cells_[static_cast<std::size_t>(j) * size_ + i].push_back(e);
    }
    seen_.assign(edges_.size(), -1);
  }

  // The crossings of segment p -> q (arc length s0 at p) with S_M edges, appended to `out`.
  void crossings(int line, const Vector2d& p, const Vector2d& q, double s0, int segment, std::vector<Crossing>& out) {
    const auto [lo, hi] = cell_range(p, q);
    const Vector2d d = q - p;
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i)
        for (int e : cells_[static_cast<std::size_t>(j) * size_ + i]) {
          if (seen_[e] == segment) continue;
          seen_[e] = segment;
          const auto [a, b] = edges_[e];
          const Vector2d& u = uv_[a];
          const Vector2d& w = uv_[b];
          // p + t d = u + r (w - u), t and r in [0, 1].
          const double denominator = cross2(d, w - u);
          if (denominator == 0.0) continue;  // parallel: an end on the line is found by the edges around it
          const double t = cross2(u - p, w - u) / denominator;
          const double r = cross2(u - p, d) / denominator;
          if (t < 0.0 || t > 1.0 || r < 0.0 || r > 1.0) continue;
          out.push_back({line, s0 + t * d.norm(), a, b, r, p + t * d});
        }
  }

 private:
  std::pair<std::array<int, 2>, std::array<int, 2>> cell_range(const Vector2d& p, const Vector2d& q) const {
    const auto cell = [this](double x) { return std::clamp(static_cast<int>(x * size_), 0, size_ - 1); };
    return {{cell(std::min(p.x(), q.x())), cell(std::min(p.y(), q.y()))},
            {cell(std::max(p.x(), q.x())), cell(std::max(p.y(), q.y()))}};
  }

  std::span<const Vector2d> uv_;
  std::vector<Edge> edges_;
  int size_ = 1;
  std::vector<std::vector<int>> cells_;
  std::vector<int> seen_;  // the last segment that tested each edge
};

// S_M's node adjacency and triangles around each node, for the path rules and the fold test.
struct Neighbourhood {
  std::vector<std::vector<int>> nodes;      // sorted
  std::vector<std::vector<int>> triangles;  // around each node

  bool joined(int a, int b) const { return std::ranges::binary_search(nodes[a], b); }
};

Neighbourhood neighbourhood(std::span<const std::array<int, 3>> triangles, std::size_t node_count) {
  Neighbourhood around{std::vector<std::vector<int>>(node_count), std::vector<std::vector<int>>(node_count)};
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t)
    for (int k = 0; k < 3; ++k) {
      const int v = triangles[t][k];
      around.triangles[v].push_back(t);
      around.nodes[v].push_back(triangles[t][(k + 1) % 3]);
      around.nodes[v].push_back(triangles[t][(k + 2) % 3]);
    }
  for (auto& list : around.nodes) {
    std::ranges::sort(list);
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return around;
}

double signed_area(const std::array<int, 3>& triangle, std::span<const Vector2d> uv) {
  return 0.5 * cross2(uv[triangle[1]] - uv[triangle[0]], uv[triangle[2]] - uv[triangle[0]]);
}

// A node of a path, its place on the line (the mean arc length of the crossings that chose it), and
// those crossings, nearest to it first.
struct PathNode {
  int node;
  double s = 0.0;
  std::vector<Crossing> crossings;
};

// The path of S_M nodes along a line: the nearer end of each crossed edge that may still join a line.
std::vector<PathNode> path_along(std::vector<Crossing> crossings, std::span<const Vector2d> uv,
                                 std::span<const std::uint8_t> may_join, std::span<const int> line_of) {
  std::ranges::sort(crossings, {}, &Crossing::s);
  const auto free = [&](int v) { return may_join[v] && line_of[v] < 0; };
  std::vector<PathNode> path;
  for (const Crossing& crossing : crossings) {
    int near = crossing.a, far = crossing.b;
    if ((uv[far] - crossing.at).squaredNorm() < (uv[near] - crossing.at).squaredNorm()) std::swap(near, far);
    const int chosen = free(near) ? near : free(far) ? far : -1;
    if (chosen < 0) continue;
    if (path.empty() || path.back().node != chosen) path.push_back({chosen, 0.0, {}});
    path.back().crossings.push_back(crossing);
  }
  for (PathNode& step : path) {
    for (const Crossing& crossing : step.crossings) step.s += crossing.s / static_cast<double>(step.crossings.size());
    std::ranges::sort(step.crossings, {}, [&](const Crossing& c) { return (uv[step.node] - c.at).squaredNorm(); });
  }
  return path;
}

// Drops the middle node of three consecutive path nodes that are joined in pairs (a triangle of S_M
// would lie on the line), and a node met twice (the path would turn back on itself).
void drop_flat_triangles(std::vector<PathNode>& path, const Neighbourhood& around) {
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 1; i + 1 < path.size(); ++i)
      if (around.joined(path[i - 1].node, path[i + 1].node) || path[i - 1].node == path[i + 1].node) {
        path.erase(path.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
  }
}

// Whether S_M's triangles around `node` keep their orientation and a tenth of their area with the node
// at `to`.
bool keeps_triangles(int node, const Vector2d& to, std::span<const std::array<int, 3>> triangles,
                     std::span<Vector2d> uv, const Neighbourhood& around, int orientation) {
  const Vector2d from = uv[node];
  bool fine = true;
  for (int t : around.triangles[node]) {
    const double before = signed_area(triangles[t], uv) * orientation;
    uv[node] = to;
    const double after = signed_area(triangles[t], uv) * orientation;
    uv[node] = from;
    if (!(after > 0.1 * before)) fine = false;
  }
  return fine;
}

// Moves the nodes of a path onto line `l` of `result`, recording them there. A node goes to its place or
// to one of its crossings, whichever keeps its triangles; one refused now may fit once its path
// neighbours are on the line, so passes repeat until none moves. A node still refused then gives way
// to the far end of one of its crossings, if that one is joined to both path neighbours and fits.
void snap_path(int l, std::vector<PathNode>& path, std::span<const std::array<int, 3>> triangles,
               std::span<Vector2d> uv, std::span<const std::uint8_t> may_join, int orientation,
               const Neighbourhood& around, CreaseNodes& result) {
  const CreaseLine& line = result.lines[l];
  // Strictly inside the line: its ends are where the crease fades or meets another one.
  const auto place = [&](double s) { return std::clamp(s, 1e-9 * line.length(), (1.0 - 1e-9) * line.length()); };
  const auto snap = [&](int node, double s) {
    if (!keeps_triangles(node, line.at(place(s)), triangles, uv, around, orientation)) return false;
    uv[node] = line.at(place(s));
    result.line_of[node] = l;
    result.parameter[node] = place(s);
    ++result.stats.nodes;
    return true;
  };
  const auto snap_somewhere = [&](const PathNode& step) {
    if (snap(step.node, step.s)) return true;
    return std::ranges::any_of(step.crossings, [&](const Crossing& crossing) { return snap(step.node, crossing.s); });
  };
  std::vector<std::uint8_t> done(path.size(), 0);
  for (bool moved = true; moved;) {
    moved = false;
    for (std::size_t i = 0; i < path.size(); ++i)
      if (!done[i] && snap_somewhere(path[i])) done[i] = moved = true;
  }
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (done[i]) continue;
    for (const Crossing& crossing : path[i].crossings) {
      const int other = crossing.a == path[i].node ? crossing.b : crossing.a;
      const bool fits = may_join[other] && result.line_of[other] < 0 &&
                        (i == 0 || around.joined(path[i - 1].node, other)) &&
                        (i + 1 == path.size() || around.joined(other, path[i + 1].node));
      if (fits && snap(other, crossing.s)) {
        path[i].node = other;
        done[i] = 1;
        break;
      }
    }
    result.stats.refused += !done[i];
  }
}

}  // namespace

std::size_t CreaseLine::segment(double s) const {
  const auto end =
      std::min<std::size_t>(std::ranges::upper_bound(arc, std::clamp(s, 0.0, length())) - arc.begin(), arc.size() - 1);
  return end == 0 ? 0 : end - 1;
}

Vector2d CreaseLine::at(double s) const {
  s = std::clamp(s, 0.0, length());
  const std::size_t i = segment(s);
  const double span = arc[i + 1] - arc[i];
  const double t = span > 0.0 ? (s - arc[i]) / span : 0.0;
  return uv[i] + t * (uv[i + 1] - uv[i]);
}

Vector2d CreaseLine::direction(double s) const {
  const std::size_t i = segment(s);
  return (uv[i + 1] - uv[i]).normalized();
}

std::vector<CreaseLine> crease_lines(const TriangleSurface& surface, std::span<const Vector2d> uv, double angle) {
  const CreaseGraph graph = crease_graph(surface, angle);
  const auto vertex_count = static_cast<int>(surface.points.size());
  std::vector<std::vector<std::uint8_t>> used(vertex_count);
  for (int v = 0; v < vertex_count; ++v) used[v].assign(graph.neighbours[v].size(), 0);
  const auto is_end = [&](int v) { return graph.neighbours[v].size() != 2 || graph.on_rim[v]; };
  // Marks the crease edge (a, b) as walked, in both directions.
  const auto take = [&](int a, int k) {
    used[a][k] = 1;
    const int b = graph.neighbours[a][k].first;
    for (std::size_t m = 0; m < graph.neighbours[b].size(); ++m)
      if (graph.neighbours[b][m].first == a) used[b][m] = 1;
  };
  std::vector<CreaseLine> lines;
  const auto walk_from = [&](int start, int k) {
    CreaseLine& line = lines.emplace_back();
    line.vertices.push_back(start);
    for (int v = start;;) {
      line.angle = std::max(line.angle, graph.neighbours[v][k].second);
      take(v, k);
      v = graph.neighbours[v][k].first;
      line.vertices.push_back(v);
      if (is_end(v)) break;
      k = used[v][0] ? 1 : 0;  // two crease edges at v, one of them just walked
      if (used[v][k]) break;   // a closed loop back at its start
    }
  };
  for (int v = 0; v < vertex_count; ++v)
    if (is_end(v))
      for (std::size_t k = 0; k < graph.neighbours[v].size(); ++k)
        if (!used[v][k]) walk_from(v, static_cast<int>(k));
  for (int v = 0; v < vertex_count; ++v)  // closed loops: every vertex has two crease edges
    if (!graph.neighbours[v].empty() && !used[v][0]) walk_from(v, 0);
  for (CreaseLine& line : lines) {
    line.arc.push_back(0.0);
    for (const int v : line.vertices) line.uv.push_back(uv[v]);
    for (std::size_t i = 1; i < line.uv.size(); ++i)
      line.arc.push_back(line.arc.back() + (line.uv[i] - line.uv[i - 1]).norm());
  }
  return lines;
}

CreaseNodes follow_creases(std::vector<CreaseLine> lines, std::span<const std::array<int, 3>> triangles,
                           std::span<Vector2d> uv, std::span<const std::uint8_t> on_rim, int orientation) {
  CreaseNodes result;
  result.lines = std::move(lines);
  result.line_of.assign(uv.size(), -1);
  result.parameter.assign(uv.size(), 0.0);
  CreaseStats& stats = result.stats;
  stats.lines = static_cast<std::int64_t>(result.lines.size());
  if (result.lines.empty()) return result;

  const Neighbourhood around = neighbourhood(triangles, uv.size());
  EdgeGrid grid(triangles, uv);  // the crossings are found before any node of this surface moves
  std::vector<std::vector<Crossing>> crossings(result.lines.size());
  for (std::size_t l = 0, segment = 0; l < result.lines.size(); ++l) {
    const CreaseLine& line = result.lines[l];
    for (std::size_t i = 0; i + 1 < line.uv.size(); ++i, ++segment)
      grid.crossings(static_cast<int>(l), line.uv[i], line.uv[i + 1], line.arc[i], static_cast<int>(segment),
                     crossings[l]);
    stats.crossings += static_cast<std::int64_t>(crossings[l].size());
    stats.sharpest = std::max(stats.sharpest, line.angle);
  }
  std::vector<std::size_t> order(result.lines.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::ranges::stable_sort(order, std::greater<>(), [&](std::size_t l) { return result.lines[l].angle; });
  // A node on the rim, or joined to one, stays off the lines: held on a line between rim nodes, which
  // slide along the rim only, its tets could not be smoothed (2-4 degree slivers on a fault at E/70).
  std::vector<std::uint8_t> may_join(uv.size(), 0);
  for (std::size_t v = 0; v < uv.size(); ++v)
    may_join[v] = !on_rim[v] && std::ranges::none_of(around.nodes[v], [&](int w) { return on_rim[w] != 0; });
  for (const std::size_t l : order) {
    std::vector<PathNode> path = path_along(std::move(crossings[l]), uv, may_join, result.line_of);
    drop_flat_triangles(path, around);
    snap_path(static_cast<int>(l), path, triangles, uv, may_join, orientation, around, result);
  }
  // What is left: the line passing through an S_M edge rather than along S_M edges.
  stats.straddling = static_cast<std::int64_t>(straddling_crossings(result, triangles, uv).size());
  return result;
}

std::vector<CreaseCrossing> straddling_crossings(const CreaseNodes& creases,
                                                 std::span<const std::array<int, 3>> triangles,
                                                 std::span<const Vector2d> uv) {
  std::vector<CreaseCrossing> straddling;
  if (creases.lines.empty()) return straddling;
  EdgeGrid grid(triangles, uv);
  for (std::size_t l = 0, segment = 0; l < creases.lines.size(); ++l) {
    const CreaseLine& line = creases.lines[l];
    std::vector<Crossing> crossings;
    for (std::size_t i = 0; i + 1 < line.uv.size(); ++i, ++segment)
      grid.crossings(static_cast<int>(l), line.uv[i], line.uv[i + 1], line.arc[i], static_cast<int>(segment),
                     crossings);
    std::ranges::sort(crossings, {}, &Crossing::s);
    const auto on_line = [&](int v) { return creases.line_of[v] == static_cast<int>(l); };
    for (const Crossing& crossing : crossings)
      if (!on_line(crossing.a) && !on_line(crossing.b)) straddling.push_back(crossing);
  }
  return straddling;
}

}  // namespace meccano
