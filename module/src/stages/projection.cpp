#include <meccano/stages/projection.hpp>

#include <meccano/mesh/quality.hpp>
#include <meccano/stages/surface_approximation.hpp>

#include <algorithm>
#include <cmath>

namespace meccano {

bool keeps_orientation(const SurfaceProjection& projection, const std::array<int, 3>& triangle, int moved,
                       const Eigen::Vector2d& uv) {
  std::array<Eigen::Vector2d, 3> corner;
  for (int c = 0; c < 3; ++c) corner[c] = triangle[c] == moved ? uv : projection.uv[triangle[c]];
  return cross2(corner[1] - corner[0], corner[2] - corner[0]) * projection.orientation > 0.0;
}

SurfaceProjection project_onto_surface(TetMesh& mesh, const TetRegion& volumetric, int index, int side,
                                       const TriangleSurface& surface, const TriangleBVH& tree,
                                       const ProjectionOptions& options) {
  // S_M as a disk over the mesh's numbering, oriented like S. Its Floater weights are computed with each
  // node pulled most of the way to its closest point p on S, x' = p + 0.2 (x - p), not on the staircase:
  // the two parameterizations then nearly agree, so φ ∘ φ_M^{-1} moves nodes onto S instead of also
  // sliding them along it (the staircase has up to √3 times S's area, unevenly spread). Measured on
  // the cube example: the largest move falls with l_r (0.095 to 0.016 from l_r = 1/8 to 1/64) instead
  // of staying near 0.06, and half as many tets are inverted. The remaining 0.2 keeps apart nodes
  // beyond the rim of S, which share their closest point. Any positive weights keep the map one-to-one.
  constexpr double kept_offset = 0.2;
  const ApproximationFaces faces = approximation_faces(mesh, volumetric, index, side);
  std::vector<std::array<int, 3>> triangles(faces.triangles.begin(), faces.triangles.end());
  std::vector<Eigen::Vector3d> pulled = mesh.points;
  for (const auto& t : triangles)
    for (int v : t) {
      const Eigen::Vector3d p = tree.closest_point(mesh.points[v]).point;
      pulled[v] = p + kept_offset * (mesh.points[v] - p);
    }
  const DiskView approximation(pulled, triangles);
  const DiskView target(surface);

  // Matching corners: S's by arc length, S_M's nearest to them around the same mean normal.
  const auto surface_corners = corners_by_arc_length(target);
  const std::vector<int> surface_rim = rim_loop(target);
  const Eigen::Vector3d normal = vector_area(surface.points, surface_rim);
  std::array<Eigen::Vector3d, 4> targets;
  for (int k = 0; k < 4; ++k) targets[k] = surface.points[surface_corners[k]];
  const auto approximation_corners = matching_corners(approximation, targets, normal);

  SurfaceProjection result;
  result.surface =
      std::make_unique<ParametricSurface>(target, parameterize_to_square(target, surface_corners, options.weights));
  const SquareParameterization own = parameterize_to_square(approximation, approximation_corners, options.weights);

  for (const auto& t : triangles) result.nodes.insert(result.nodes.end(), t.begin(), t.end());
  std::sort(result.nodes.begin(), result.nodes.end());
  result.nodes.erase(std::unique(result.nodes.begin(), result.nodes.end()), result.nodes.end());
  std::vector<std::uint8_t> rim(mesh.points.size(), 0);
  for (int v : own.rim) rim[v] = 1;

  ProjectionStats& stats = result.stats;
  const auto count = static_cast<std::int64_t>(result.nodes.size());
  result.uv.resize(result.nodes.size());
  result.on_rim.resize(result.nodes.size());
  for (std::int64_t i = 0; i < count; ++i) {
    const VertexId v = result.nodes[i];
    result.uv[i] = own.uv[v];
    result.on_rim[i] = rim[v];
  }
  result.orientation = own.orientation;
  for (const auto& t : triangles) {
    std::array<int, 3>& local = result.triangles.emplace_back();
    for (int k = 0; k < 3; ++k)
      local[k] =
          static_cast<int>(std::lower_bound(result.nodes.begin(), result.nodes.end(), t[k]) - result.nodes.begin());
  }
  result.creases = follow_creases(crease_lines(surface, result.surface->parameterization().uv, options.crease_angle),
                                  result.triangles, result.uv, result.on_rim, result.orientation);
  stats.creases = result.creases.stats;
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
  stats.rim_nodes = static_cast<std::int64_t>(own.rim.size());
  stats.inverted_tets = count_inverted(mesh);
  return result;
}

}  // namespace meccano
