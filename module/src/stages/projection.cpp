#include <meccano/stages/projection.hpp>

#include <meccano/error.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/surface_approximation.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/rim_chords.hpp>

#include "mesh/topology_helpers.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <tuple>

namespace meccano {

RimGap rim_gap(std::span<const Eigen::Vector3d> surface_points, std::span<const int> surface_rim,
               std::span<const Eigen::Vector3d> approximation_points, std::span<const int> approximation_rim) {
  // The directed Hausdorff distance with the usual early exit: a vertex closer to some segment than the
  // largest distance so far cannot be the farthest. The scan starts at the segment nearest to the previous
  // vertex, which is usually near this one too, so most vertices stop after a few segments.
  RimGap gap;
  const std::size_t segments = approximation_rim.size();
  if (segments == 0 || surface_rim.empty()) return gap;
  double largest = -1.0;  // squared
  std::size_t start = 0;
  for (int v : surface_rim) {
    double nearest = std::numeric_limits<double>::infinity();
    std::size_t nearest_segment = start;
    for (std::size_t step = 0; step < segments && nearest > largest; ++step) {
      const std::size_t k = (start + step) % segments;
      const double distance = squared_distance_to_segment(surface_points[v], approximation_points[approximation_rim[k]],
                                                          approximation_points[approximation_rim[(k + 1) % segments]]);
      if (distance < nearest) {
        nearest = distance;
        nearest_segment = k;
      }
    }
    start = nearest_segment;
    if (nearest > largest) {
      largest = nearest;
      gap.vertex = v;
    }
  }
  gap.distance = std::sqrt(largest);
  return gap;
}

bool keeps_orientation(const SurfaceProjection& projection, const std::array<int, 3>& triangle, int moved,
                       const Eigen::Vector2d& uv, double least_area) {
  std::array<Eigen::Vector2d, 3> corner;
  for (int c = 0; c < 3; ++c) corner[c] = triangle[c] == moved ? uv : projection.uv[triangle[c]];
  return cross2(corner[1] - corner[0], corner[2] - corner[0]) * projection.orientation > least_area;
}

namespace {

// S_M's nodes pulled most of the way to their closest points p on S, x' = p + 0.2 (x - p), for its
// Floater weights: the two parameterizations then nearly agree, so φ ∘ φ_M^{-1} moves nodes onto S
// instead of also sliding them along it (the staircase has up to √3 times S's area, unevenly spread).
// Measured on the cube example: the largest move falls with l_r (0.095 to 0.016 from l_r = 1/8 to 1/64)
// instead of staying near 0.06, and half as many tets are inverted. The remaining 0.2 keeps apart nodes
// beyond the rim of S, which share their closest point. Any positive weights keep the map one-to-one.
std::vector<Eigen::Vector3d> pulled_towards_surface(const TetMesh& mesh, std::span<const std::array<int, 3>> triangles,
                                                    const TriangleBVH& tree) {
  constexpr double kept_offset = 0.2;
  std::vector<Eigen::Vector3d> pulled = mesh.points;
  for (const auto& t : triangles)
    for (int v : t) {
      const Eigen::Vector3d p = tree.closest_point(mesh.points[v]).point;
      pulled[v] = p + kept_offset * (mesh.points[v] - p);
    }
  return pulled;
}

// The rim gap of S_M (its triangles over the mesh's points); throws UncoveredSurfaceError above `max_gap`.
RimGap require_rim_covered(const TriangleSurface& surface, std::span<const int> surface_rim,
                           const std::vector<Eigen::Vector3d>& points, std::span<const std::array<int, 3>> triangles,
                           double max_gap) {
  const RimGap gap = rim_gap(surface.points, surface_rim, points, rim_loop(DiskView(points, triangles)));
  if (gap.distance <= max_gap) return gap;
  const Eigen::Vector3d& x = surface.points[gap.vertex];
  std::ostringstream message;
  message.precision(10);  // UTM coordinates to the millimetre
  message << "S_M leaves part of S uncovered: rim vertex " << gap.vertex + 1 << " of S at (" << x.x() << ", " << x.y()
          << ", " << x.z() << ") is " << gap.distance << " from S_M's rim (at most " << max_gap
          << " allowed); S is probably narrower there than V_M's cubes";
  throw UncoveredSurfaceError(message.str());
}

// The S_M nodes (sorted), their parameters and rim flags from S_M's own parameterization, and S_M's
// triangles over them.
void take_parameters(SurfaceProjection& result, std::span<const std::array<int, 3>> triangles,
                     const SquareParameterization& own, std::span<const RimAnchor> anchors, std::size_t mesh_points) {
  for (const auto& t : triangles) result.nodes.insert(result.nodes.end(), t.begin(), t.end());
  std::sort(result.nodes.begin(), result.nodes.end());
  result.nodes.erase(std::unique(result.nodes.begin(), result.nodes.end()), result.nodes.end());
  std::vector<std::uint8_t> rim(mesh_points, 0);
  for (int v : own.rim) rim[v] = 1;
  for (const RimAnchor& anchor : anchors) rim[anchor.vertex] = pinned_rim_node;
  result.uv.resize(result.nodes.size());
  result.on_rim.resize(result.nodes.size());
  for (std::size_t i = 0; i < result.nodes.size(); ++i) {
    result.uv[i] = own.uv[result.nodes[i]];
    result.on_rim[i] = rim[result.nodes[i]];
  }
  result.orientation = own.orientation;
  for (const auto& t : triangles) {
    std::array<int, 3>& local = result.triangles.emplace_back();
    for (int k = 0; k < 3; ++k)
      local[k] =
          static_cast<int>(std::lower_bound(result.nodes.begin(), result.nodes.end(), t[k]) - result.nodes.begin());
  }
}

// One disk of S_M (`triangles`, over the mesh's numbering, oriented like S) onto one disk of S (`target`,
// parameterized), with S_M's corners and anchors given: steps 1-3 once the corners are chosen. `pulled`
// holds S_M's nodes pulled towards S.
SurfaceProjection project_disk(TetMesh& mesh, std::span<const std::array<int, 3>> triangles,
                               const TriangleSurface& target, SquareParameterization target_parameterization,
                               const std::vector<Eigen::Vector3d>& pulled, const std::array<int, 4>& own_corners,
                               std::span<const RimAnchor> own_anchors, const TriangleBVH& tree,
                               const ProjectionOptions& options) {
  SurfaceProjection result;
  result.surface = std::make_unique<ParametricSurface>(target, std::move(target_parameterization));
  const SquareParameterization own =
      parameterize_to_square(DiskView(pulled, triangles), own_corners, options.weights, own_anchors);
  take_parameters(result, triangles, own, own_anchors, mesh.points.size());
  result.creases = follow_creases(crease_lines(target, result.surface->parameterization().uv, options.crease_angle),
                                  result.triangles, result.uv, result.on_rim, result.orientation);
  result.stats.creases = result.creases.stats;
  move_nodes_onto_surface(mesh, result, tree);
  result.stats.rim_nodes = static_cast<std::int64_t>(own.rim.size());
  return result;
}

// Where a rim runs on the box. The label of a rim edge is the set of box planes both its ends lie on (0
// inside the box); an arc is a maximal run of edges with one label, and a transition the rim vertex where
// one arc ends and the next begins. A surface clipped by the box has its transitions where its rim passes
// from one box face to the next (on a box edge) or into the box.
struct BoxArcs {
  std::vector<int> start;           // loop positions of the transitions, increasing
  std::vector<std::uint8_t> label;  // of the arc that begins there; one label and no start for a uniform rim
};

// `planes`: the box planes of each rim vertex, in loop order. Throws MeshingError, naming the vertex
// through `name`, where the rim touches the box planes at a vertex whose rim edges do not run on them:
// such a node would have to stay on the box and follow the rim of S inside it.
BoxArcs box_arcs(std::span<const std::uint8_t> planes, const std::function<std::string(int)>& name) {
  const int n = static_cast<int>(planes.size());
  const auto label = [&](int i) { return static_cast<std::uint8_t>(planes[i] & planes[(i + 1) % n]); };
  BoxArcs arcs;
  for (int i = 0; i < n; ++i) {
    const std::uint8_t in = label((i + n - 1) % n), out = label(i);
    if ((in | out) != planes[i])
      throw MeshingError("the rim of " + name(i) + " touches the box where its rim edges do not run on it");
    if (in != out) {
      arcs.start.push_back(i);
      arcs.label.push_back(out);
    }
  }
  if (arcs.start.empty()) arcs.label.push_back(label(0));
  return arcs;
}

std::string describe_labels(std::span<const std::uint8_t> labels) {
  std::string text;
  for (std::uint8_t label : labels) text += (text.empty() ? "" : ", ") + std::to_string(label);
  return text;
}

// S_M's corners and anchors for an S whose rim runs on the box (at least one transition): S_M's arcs are
// matched to S's (same labels in the same cyclic order, the rotation whose transitions lie nearest to
// S's), every transition of S_M is pinned at its partner's perimeter coordinate (a corner where that is
// one of S's corners), and S's other corners go to the S_M rim node of the matched arc nearest to them.
struct MatchedRim {
  std::array<int, 4> corners{};
  std::vector<RimAnchor> anchors;
};

MatchedRim match_box_arcs(const TriangleSurface& surface, std::span<const int> surface_rim, const BoxArcs& surface_arcs,
                          const SquareParameterization& surface_parameterization, const TetMesh& mesh,
                          std::span<const int> rim, const BoxArcs& arcs) {
  const int m = static_cast<int>(surface_arcs.start.size());
  if (static_cast<int>(arcs.start.size()) != m)
    throw MeshingError("the rim of S_M runs on the box in " + std::to_string(arcs.start.size()) +
                       " arcs where S's runs in " + std::to_string(m) + " (box planes of S's arcs: " +
                       describe_labels(surface_arcs.label) + "; of S_M's: " + describe_labels(arcs.label) +
                       "): where S's rim dips into the box and back by less than V_M's tets, S_M runs on along the "
                       "box (snap_rim_to_box, the tool's --snap-to-box, sets such a rim onto the box)");
  int rotation = -1;
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < m; ++r) {
    double cost = 0.0;
    for (int j = 0; j < m && cost < best; ++j)
      cost =
          surface_arcs.label[j] != arcs.label[(j + r) % m]
              ? std::numeric_limits<double>::infinity()
              : cost + (surface.points[surface_rim[surface_arcs.start[j]]] - mesh.points[rim[arcs.start[(j + r) % m]]])
                           .norm();
    if (cost < best) {
      best = cost;
      rotation = r;
    }
  }
  if (rotation < 0)
    throw MeshingError("the rim of S_M meets the box faces in another order than S's rim (box planes of S's arcs: " +
                       describe_labels(surface_arcs.label) + "; of S_M's: " + describe_labels(arcs.label) + ")");

  const int n = static_cast<int>(rim.size());
  std::vector<double> length(1, 0.0);  // chord length along S_M's rim from position 0, closing the loop
  for (int i = 0; i < n; ++i)
    length.push_back(length.back() + (mesh.points[rim[(i + 1) % n]] - mesh.points[rim[i]]).norm());
  const auto arc_length = [&](int from, int to) {
    return to >= from ? length[to] - length[from] : length[n] - length[from] + length[to];
  };
  std::vector<double> at(m);
  for (int j = 0; j < m; ++j)
    at[j] = perimeter_coordinate(surface_parameterization.uv[surface_rim[surface_arcs.start[j]]]);

  // Perimeter from coordinate a forward to b; S's transitions need not start at its corner 0.
  const auto forward = [](double a, double b) { return b >= a ? b - a : b - a + 4.0; };
  MatchedRim matched;
  std::array<int, 4> position{};  // of each corner along S_M's rim
  for (int k = 0; k < 4; ++k) {
    int j = 0;  // the arc of S holding corner k
    while (!(forward(at[j], k) < forward(at[j], at[(j + 1) % m]))) ++j;
    const int from = arcs.start[(j + rotation) % m], to = arcs.start[(j + 1 + rotation) % m];
    if (at[j] == k) {
      position[k] = from;
      continue;
    }
    // The rim node of the matched arc nearest to S's corner (chord-length shares differ between S's rim
    // and S_M's staircase by up to kilometres along a fault's deep rim).
    const Eigen::Vector3d& target = surface.points[surface_parameterization.corners[k]];
    const auto miss = [&](int i) { return (mesh.points[rim[i]] - target).squaredNorm(); };
    int nearest = -1;
    for (int i = (from + 1) % n; i != to; i = (i + 1) % n)
      if (nearest < 0 || miss(i) < miss(nearest)) nearest = i;
    if (nearest < 0)
      throw MeshingError("an arc of S_M's rim on the box has no node for corner " + std::to_string(k) +
                         " of the square");
    position[k] = nearest;
  }
  double previous = 0.0;
  for (int k = 0; k < 4; ++k) {
    matched.corners[k] = rim[position[k]];
    const double along = arc_length(position[0], position[k]);
    if (k > 0 && !(along > previous))
      throw MeshingError("two corners of the square fall on one node of S_M's rim, or out of order");
    previous = along;
  }
  for (int j = 0; j < m; ++j)
    if (at[j] != std::floor(at[j])) matched.anchors.push_back({rim[arcs.start[(j + rotation) % m]], at[j]});
  return matched;
}

// The triangles of S_M, oriented like S, over the mesh's numbering.
std::vector<std::array<int, 3>> approximation_triangles(const TetMesh& mesh, const TetRegion& volumetric, int index,
                                                        int side) {
  const ApproximationFaces faces = approximation_faces(mesh, volumetric, index, side);
  return {faces.triangles.begin(), faces.triangles.end()};
}

// A disk whose interior edges never join two rim vertices: Floater's map of it onto the square is then
// one-to-one for any four corners, so both halves of a closed surface can share theirs.
bool is_disk_without_chords(std::span<const std::array<int, 3>> triangles) {
  detail::TopologyScratch scratch;
  const detail::TriangleTopology topology = detail::triangle_topology(triangles, scratch);
  if (topology.components != 1 || topology.overloaded_edges != 0 || topology.pinched_vertices != 0 ||
      topology.euler() != 1 || detail::count_boundary_loops(scratch) != 1)
    return false;
  std::vector<VertexId> rim;
  for (const detail::Edge& e : scratch.boundary) rim.insert(rim.end(), {e.first, e.second});
  std::ranges::sort(rim);
  const auto on_rim = [&](VertexId v) { return std::ranges::binary_search(rim, v); };
  for (std::size_t i = 0; i + 1 < scratch.edges.size(); ++i) {
    const detail::Edge& e = scratch.edges[i].first;
    if (scratch.edges[i + 1].first == e && on_rim(e.first) && on_rim(e.second)) return false;
  }
  return true;
}

// A closed S_M and S cut by one coordinate plane into halves that are disks: [0] below, [1] above.
struct ClosedCut {
  std::array<std::vector<std::array<int, 3>>, 2> approximation;  // S_M's halves, over the mesh's numbering
  std::array<TriangleSurface, 2> surface;                        // S's halves over one point array
  std::vector<EdgeCrossing> crossings;                           // the cut's points on S's edges
  std::array<std::vector<std::array<int, 3>>, 2> cut_triangles;  // S's halves before their chords were split
};

// S_M cut by the computational plane grid[axis] = level: each triangle goes to the side of its
// centroid. Empty unless every edge between the halves lies in the plane (the cut follows S_M's edges)
// and each half is a disk without chords.
std::optional<std::array<std::vector<std::array<int, 3>>, 2>> cut_approximation(
    const TetMesh& mesh, std::span<const std::array<int, 3>> triangles, int axis, std::int64_t level) {
  std::array<std::vector<std::array<int, 3>>, 2> halves;
  for (const auto& t : triangles) {
    const std::int64_t sum = mesh.grid[t[0]][axis] + mesh.grid[t[1]][axis] + mesh.grid[t[2]][axis];
    halves[sum >= 3 * level].push_back(t);
  }
  if (halves[0].empty() || halves[1].empty()) return std::nullopt;
  std::vector<std::pair<detail::Edge, int>> edges;
  for (int half = 0; half < 2; ++half)
    for (const auto& t : halves[half])
      for (int k = 0; k < 3; ++k) edges.push_back({detail::make_edge(t[k], t[(k + 1) % 3]), half});
  std::ranges::sort(edges);
  for (std::size_t i = 0; i + 1 < edges.size(); ++i)
    if (edges[i].first == edges[i + 1].first && edges[i].second != edges[i + 1].second &&
        (mesh.grid[edges[i].first.first][axis] != level || mesh.grid[edges[i].first.second][axis] != level))
      return std::nullopt;
  if (!is_disk_without_chords(halves[0]) || !is_disk_without_chords(halves[1])) return std::nullopt;
  return halves;
}

// One half of `surface` over the points of its cut, with its rim chords split (a vertex of S on the cut
// can leave one).
TriangleSurface surface_half(const TriangleSurface& surface, std::vector<Eigen::Vector3d> points,
                             std::vector<std::array<int, 3>> triangles) {
  TriangleSurface half;
  half.name = surface.name;
  half.source = surface.source;
  half.points = std::move(points);
  half.triangles = std::move(triangles);
  return split_rim_chords(half);
}

// S cut by the physical plane x[axis] = offset into two disks; empty if the plane cuts S in more than one
// loop, or along a triangle.
std::optional<PlaneCut> cut_surface(const TriangleSurface& surface, int axis, double offset,
                                    std::array<TriangleSurface, 2>& halves) {
  std::optional<PlaneCut> cut = cut_by_plane(surface, axis, offset);
  if (!cut) return std::nullopt;
  for (int half = 0; half < 2; ++half) {
    const auto& triangles = half == 0 ? cut->below : cut->above;
    if (triangles.empty()) return std::nullopt;
    halves[half] = surface_half(surface, cut->points, triangles);
    if (!is_disk_without_chords(halves[half].triangles)) return std::nullopt;
  }
  return cut;
}

// The coordinate plane through S_M's nodes nearest to the middle of S_M along some axis that cuts both
// S_M and S into two disks. Planes are tried by their distance from the middle, as a share of S_M's
// extent along their axis.
ClosedCut cut_closed_surface(const TetMesh& mesh, std::span<const std::array<int, 3>> triangles,
                             const TriangleSurface& surface) {
  struct Candidate {
    double off_middle;
    int axis;
    std::int64_t level;
  };
  std::vector<Candidate> candidates;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<std::int64_t> levels;
    for (const auto& t : triangles)
      for (int v : t) levels.push_back(mesh.grid[v][axis]);
    std::ranges::sort(levels);
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    if (levels.size() < 3) continue;
    const double low = static_cast<double>(levels.front()), high = static_cast<double>(levels.back());
    for (std::size_t i = 1; i + 1 < levels.size(); ++i)
      candidates.push_back(
          {std::abs(static_cast<double>(levels[i]) - 0.5 * (low + high)) / (high - low), axis, levels[i]});
  }
  std::ranges::sort(candidates, {}, [](const Candidate& c) { return std::tuple(c.off_middle, c.axis, c.level); });
  for (const Candidate& c : candidates) {
    auto approximation = cut_approximation(mesh, triangles, c.axis, c.level);
    if (!approximation) continue;
    const double offset = mesh.meccano.to_physical(GridPoint{c.level, c.level, c.level})[c.axis];
    ClosedCut closed;
    closed.approximation = std::move(*approximation);
    std::optional<PlaneCut> cut = cut_surface(surface, c.axis, offset, closed.surface);
    if (!cut) continue;
    closed.crossings = std::move(cut->crossings);
    closed.cut_triangles = {std::move(cut->below), std::move(cut->above)};
    return closed;
  }
  throw MeshingError("no coordinate plane through the nodes of S_M cuts both S_M and the closed surface into two "
                     "disks (" +
                     std::to_string(candidates.size()) + " planes tried)");
}

}  // namespace

void move_nodes_onto_surface(TetMesh& mesh, SurfaceProjection& projection, const TriangleBVH& tree) {
  ProjectionStats& stats = projection.stats;
  const auto count = static_cast<std::int64_t>(projection.nodes.size());
  std::vector<Eigen::Vector3d> moved(projection.nodes.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t i = 0; i < count; ++i)
    moved[i] = projection.surface->evaluate(projection.surface->locate(projection.uv[i]));
  for (std::int64_t i = 0; i < count; ++i) {
    const VertexId v = projection.nodes[i];
    // A rim node on the box lands on S's rim on the same box planes: keep its coordinates there exact.
    const std::uint8_t planes = mesh.meccano.box_planes(mesh.grid[v]);
    for (int axis = 0; axis < 3; ++axis)
      if (planes & (3u << (2 * axis))) moved[i][axis] = mesh.points[v][axis];
    stats.largest_move = std::max(stats.largest_move, (moved[i] - mesh.points[v]).norm());
    mesh.points[v] = moved[i];
    stats.largest_distance_after =
        std::max(stats.largest_distance_after, std::sqrt(tree.closest_point(moved[i]).squared_distance));
  }
  stats.nodes = count;
}

SurfaceProjection project_onto_surface(TetMesh& mesh, const TetRegion& volumetric, int index, int side,
                                       const TriangleSurface& surface, const TriangleBVH& tree,
                                       const ProjectionOptions& options) {
  const std::vector<std::array<int, 3>> triangles = approximation_triangles(mesh, volumetric, index, side);
  const DiskView target(surface);
  const std::vector<int> surface_rim = rim_loop(target);
  const double gap = require_rim_covered(surface, surface_rim, mesh.points, triangles, options.max_rim_gap).distance;

  // Both rims, walked the same way round S's mean normal, and where they run on the box.
  const std::vector<Eigen::Vector3d> pulled = pulled_towards_surface(mesh, triangles, tree);
  const Eigen::Vector3d normal = vector_area(surface.points, surface_rim);
  std::vector<int> rim = rim_loop(DiskView(pulled, triangles));
  if (vector_area(pulled, rim).dot(normal) < 0.0) std::ranges::reverse(rim);
  std::vector<std::uint8_t> planes;
  for (int v : surface_rim) planes.push_back(box_sides(surface.points[v], mesh.meccano.box));
  const BoxArcs surface_arcs =
      box_arcs(planes, [&](int i) { return "S at its vertex " + std::to_string(surface_rim[i] + 1); });
  planes.clear();
  for (int v : rim) planes.push_back(mesh.meccano.box_planes(mesh.grid[v]));
  const BoxArcs arcs = box_arcs(planes, [&](int i) { return "S_M at node " + std::to_string(rim[i]); });

  std::array<int, 4> surface_corners{}, approximation_corners{};
  std::vector<RimAnchor> anchors;
  std::optional<SquareParameterization> surface_parameterization;
  if (!surface_arcs.start.empty()) {
    // S clipped by the box: the arcs on each box face map onto each other, their ends pinned.
    surface_corners = corners_by_arc_length(target, surface_rim[surface_arcs.start.front()]);
    surface_parameterization = parameterize_to_square(target, surface_corners, options.weights);
    MatchedRim matched = match_box_arcs(surface, surface_rim, surface_arcs, *surface_parameterization, mesh, rim, arcs);
    approximation_corners = matched.corners;
    anchors = std::move(matched.anchors);
  } else {
    // A rim inside the box, or all of it on one box face: S's corners by arc length, S_M's nearest to them.
    if (surface_arcs.label.front() != arcs.label.front() || !arcs.start.empty())
      throw MeshingError("the rim of S_M runs on the box where S's does not (box planes of S's rim: " +
                         describe_labels(surface_arcs.label) + "; of S_M's arcs: " + describe_labels(arcs.label) + ")");
    surface_corners = corners_by_arc_length(target);
    surface_parameterization = parameterize_to_square(target, surface_corners, options.weights);
    std::array<Eigen::Vector3d, 4> targets;
    for (int k = 0; k < 4; ++k) targets[k] = surface.points[surface_corners[k]];
    approximation_corners = matching_corners(DiskView(pulled, triangles), targets, normal);
  }

  SurfaceProjection result = project_disk(mesh, triangles, surface, std::move(*surface_parameterization), pulled,
                                          approximation_corners, anchors, tree, options);
  result.surface_index = index;
  result.stats.rim_gap = gap;
  result.stats.inverted_tets = count_inverted(mesh);
  return result;
}

std::vector<SurfaceProjection> project_closed_onto_surface(TetMesh& mesh, const TetRegion& volumetric, int index,
                                                           const TriangleSurface& surface, const TriangleBVH& tree,
                                                           const ProjectionOptions& options) {
  const std::vector<std::array<int, 3>> triangles = approximation_triangles(mesh, volumetric, index, +1);
  const ClosedCut cut = cut_closed_surface(mesh, triangles, surface);
  // Corners on the cut, shared by both halves: S's by arc length along it, S_M's nearest to them.
  const std::vector<Eigen::Vector3d> pulled = pulled_towards_surface(mesh, triangles, tree);
  const TriangleSurface& lower = cut.surface[0];
  const auto surface_corners = corners_by_arc_length(lower);
  const Eigen::Vector3d normal = vector_area(lower.points, rim_loop(lower));
  std::array<Eigen::Vector3d, 4> targets;
  for (int k = 0; k < 4; ++k) targets[k] = lower.points[surface_corners[k]];
  const auto approximation_corners = matching_corners(DiskView(pulled, cut.approximation[0]), targets, normal);

  std::vector<SurfaceProjection> halves;
  for (int half = 0; half < 2; ++half)
    halves.push_back(project_disk(mesh, cut.approximation[half], cut.surface[half],
                                  parameterize_to_square(cut.surface[half], surface_corners, options.weights), pulled,
                                  approximation_corners, {}, tree, options));
  const std::int64_t inverted = count_inverted(mesh);
  for (int half = 0; half < 2; ++half) {
    halves[half].surface_index = index;
    halves[half].stats.inverted_tets = inverted;
    halves[half].cut_crossings = cut.crossings;
    halves[half].cut_triangles = cut.cut_triangles[half];
  }
  return halves;
}

TriangleSurface projection_target(const SurfaceProjection& projection, const TriangleSurface& surface) {
  if (projection.cut_triangles.empty()) return split_rim_chords(surface);
  return surface_half(surface, crossing_points(surface.points, projection.cut_crossings), projection.cut_triangles);
}

}  // namespace meccano
