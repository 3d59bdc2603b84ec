#include <meccano/stages/projection.hpp>

#include <meccano/error.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/surface_approximation.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

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
                     const SquareParameterization& own, std::size_t mesh_points) {
  for (const auto& t : triangles) result.nodes.insert(result.nodes.end(), t.begin(), t.end());
  std::sort(result.nodes.begin(), result.nodes.end());
  result.nodes.erase(std::unique(result.nodes.begin(), result.nodes.end()), result.nodes.end());
  std::vector<std::uint8_t> rim(mesh_points, 0);
  for (int v : own.rim) rim[v] = 1;
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

// Every S_M node moves to φ of its parameters.
void move_nodes_onto_surface(TetMesh& mesh, SurfaceProjection& result, const TriangleBVH& tree) {
  ProjectionStats& stats = result.stats;
  const auto count = static_cast<std::int64_t>(result.nodes.size());
  std::vector<Eigen::Vector3d> moved(result.nodes.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t i = 0; i < count; ++i) moved[i] = result.surface->evaluate(result.surface->locate(result.uv[i]));
  for (std::int64_t i = 0; i < count; ++i) {
    const VertexId v = result.nodes[i];
    stats.largest_move = std::max(stats.largest_move, (moved[i] - mesh.points[v]).norm());
    mesh.points[v] = moved[i];
    stats.largest_distance_after =
        std::max(stats.largest_distance_after, std::sqrt(tree.closest_point(moved[i]).squared_distance));
  }
  stats.nodes = count;
}

}  // namespace

SurfaceProjection project_onto_surface(TetMesh& mesh, const TetRegion& volumetric, int index, int side,
                                       const TriangleSurface& surface, const TriangleBVH& tree,
                                       const ProjectionOptions& options) {
  // S_M as a disk over the mesh's numbering, oriented like S.
  const ApproximationFaces faces = approximation_faces(mesh, volumetric, index, side);
  const std::vector<std::array<int, 3>> triangles(faces.triangles.begin(), faces.triangles.end());
  const DiskView target(surface);
  const std::vector<int> surface_rim = rim_loop(target);
  SurfaceProjection result;
  result.stats.rim_gap =
      require_rim_covered(surface, surface_rim, mesh.points, triangles, options.max_rim_gap).distance;

  // Matching corners: S's by arc length, S_M's nearest to them around the same mean normal.
  const std::vector<Eigen::Vector3d> pulled = pulled_towards_surface(mesh, triangles, tree);
  const DiskView approximation(pulled, triangles);
  const auto surface_corners = corners_by_arc_length(target);
  const Eigen::Vector3d normal = vector_area(surface.points, surface_rim);
  std::array<Eigen::Vector3d, 4> targets;
  for (int k = 0; k < 4; ++k) targets[k] = surface.points[surface_corners[k]];
  const auto approximation_corners = matching_corners(approximation, targets, normal);

  result.surface =
      std::make_unique<ParametricSurface>(target, parameterize_to_square(target, surface_corners, options.weights));
  const SquareParameterization own = parameterize_to_square(approximation, approximation_corners, options.weights);
  take_parameters(result, triangles, own, mesh.points.size());
  result.creases = follow_creases(crease_lines(surface, result.surface->parameterization().uv, options.crease_angle),
                                  result.triangles, result.uv, result.on_rim, result.orientation);
  result.stats.creases = result.creases.stats;
  move_nodes_onto_surface(mesh, result, tree);
  result.stats.rim_nodes = static_cast<std::int64_t>(own.rim.size());
  result.stats.inverted_tets = count_inverted(mesh);
  return result;
}

}  // namespace meccano
