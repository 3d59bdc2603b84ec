// Projection of S_M onto S (paper §4.3) on every test surface, box and resolution of the stage tests:
// every S_M node lands on S, rim nodes on the rim of S, the mesh stays conforming; and the Hausdorff
// distance between S and the projected S_M shrinks as l_r halves.

#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/stages/pipeline.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

namespace meccano {
namespace {

InsertionResult insert_until_projection(std::span<const TriangleSurface> surfaces, const Box& box, double resolution) {
  InsertionOptions options;
  options.resolution = resolution;
  options.last_stage = Stage::projection;
  return insert_surfaces(make_cube_meccano(box, 0), surfaces, options);
}

// The projected S_M of surface s as a surface of its own.
TriangleSurface projected_interface(const InsertionResult& result, int s) {
  TriangleSurface projected;
  const SurfaceInsertion& inserted = result.surfaces[s];
  const ApproximationFaces faces =
      approximation_faces(result.mesh, inserted.volumetric, s, inserted.healing_stats.side);
  std::vector<int> local(result.mesh.points.size(), -1);
  for (const auto& t : faces.triangles) {
    std::array<int, 3> triangle{};
    for (int k = 0; k < 3; ++k) {
      if (local[t[k]] < 0) {
        local[t[k]] = static_cast<int>(projected.points.size());
        projected.points.push_back(result.mesh.points[t[k]]);
      }
      triangle[k] = local[t[k]];
    }
    projected.triangles.push_back(triangle);
  }
  return projected;
}

using Case = testing::SurfaceCase;

class ProjectionOn : public ::testing::TestWithParam<Case> {};

// Checked after every surface is projected: a later surface's projection must not move an earlier one's nodes.
TEST_P(ProjectionOn, PutsEveryNodeOnSAndTheRimOnTheRim) {
  const Case& c = GetParam();
  const InsertionResult result = insert_until_projection(c.surfaces, c.box, c.resolution);
  const double tolerance = 1e-12 * c.box.diagonal();
  for (std::size_t s = 0; s < c.surfaces.size(); ++s) {
    SCOPED_TRACE("surface " + std::to_string(s + 1));
    const TriangleSurface& surface = c.surfaces[s];
    const SurfaceProjection& projection = result.surfaces[s].projections.front();
    const TriangleBVH tree(surface);
    ASSERT_GT(projection.stats.nodes, 0);
    for (std::size_t i = 0; i < projection.nodes.size(); ++i) {
      const Eigen::Vector3d& x = result.mesh.points[projection.nodes[i]];
      ASSERT_LE(std::sqrt(tree.closest_point(x).squared_distance), tolerance) << "node off S";
      if (projection.on_rim[i]) {
        ASSERT_LE(testing::distance_to_rim(surface, x), tolerance) << "rim node off the rim of S";
      }
    }
    EXPECT_LE(projection.stats.largest_distance_after, tolerance);
  }
  const auto check = verify_mesh(result.mesh, {.physical = false});
  EXPECT_TRUE(check.ok()) << check.summary();
}

INSTANTIATE_TEST_SUITE_P(AllSurfacesAndBoxes, ProjectionOn, ::testing::ValuesIn(testing::surface_cases(16, true)),
                         [](const ::testing::TestParamInfo<Case>& param) { return param.param.name; });

// Hausdorff distance between S and the projected S_M, approximated on vertices and centroids of both.
double hausdorff(const TriangleSurface& a, const TriangleSurface& b) {
  const TriangleBVH tree_a(a), tree_b(b);
  double worst = 0;
  auto one_way = [&](const TriangleSurface& from, const TriangleBVH& to) {
    for (const auto& t : from.triangles) {
      const Eigen::Vector3d c = (from.points[t[0]] + from.points[t[1]] + from.points[t[2]]) / 3;
      worst = std::max(worst, std::sqrt(to.closest_point(c).squared_distance));
    }
  };
  one_way(a, tree_b);
  one_way(b, tree_a);
  return worst;
}

TEST(Projection, HausdorffDistanceShrinksAsTheResolutionHalves) {
  const TriangleSurface surface = testing::paper_like_patch(96);
  std::vector<double> distances;
  for (double resolution : {1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64}) {
    const InsertionResult result = insert_until_projection({&surface, 1}, {{0, 0, 0}, {1, 1, 1}}, resolution);
    distances.push_back(hausdorff(surface, projected_interface(result, 0)));
  }
  for (std::size_t i = 1; i < distances.size(); ++i) {
    const double rate = std::log2(distances[i - 1] / distances[i]);
    EXPECT_GT(rate, 1.0) << "level " << i << ": " << distances[i - 1] << " -> " << distances[i];
  }
}

// The rim gap against a brute-force directed Hausdorff distance: S's rim a wavy loop, S_M's a square
// loop that covers the loop's left part only, both densely sampled, so the early exit is exercised.
TEST(Projection, RimGapIsTheFarthestRimVertexOfSFromTheRimOfSM) {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> surface_rim, approximation_rim;
  for (int k = 0; k < 200; ++k) {
    const double angle = 2 * std::numbers::pi * k / 200;
    surface_rim.push_back(static_cast<int>(points.size()));
    points.emplace_back(std::cos(angle), std::sin(angle), 0.05 * std::sin(7 * angle));
  }
  const std::array<Eigen::Vector3d, 4> square = {Eigen::Vector3d(-1.1, -1.1, 0), Eigen::Vector3d(0.3, -1.1, 0),
                                                 Eigen::Vector3d(0.3, 1.1, 0), Eigen::Vector3d(-1.1, 1.1, 0)};
  for (int side = 0; side < 4; ++side)
    for (int k = 0; k < 50; ++k) {
      approximation_rim.push_back(static_cast<int>(points.size()));
      points.push_back(square[side] + (square[(side + 1) % 4] - square[side]) * k / 50.0);
    }
  double farthest = 0.0;
  int vertex = -1;
  for (int v : surface_rim) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < approximation_rim.size(); ++k)
      for (int sample = 0; sample <= 100; ++sample) {
        const Eigen::Vector3d& a = points[approximation_rim[k]];
        const Eigen::Vector3d& b = points[approximation_rim[(k + 1) % approximation_rim.size()]];
        nearest = std::min(nearest, (a + (b - a) * sample / 100.0 - points[v]).norm());
      }
    if (nearest > farthest) {
      farthest = nearest;
      vertex = v;
    }
  }
  const RimGap gap = rim_gap(points, surface_rim, points, approximation_rim);
  EXPECT_EQ(gap.vertex, vertex);
  EXPECT_NEAR(gap.distance, farthest, 1e-3);  // the samples are 1e-3 apart along the square's sides
  EXPECT_NEAR(gap.distance, 0.7, 0.01);       // (1, 0, 0) lies 0.7 beyond the side x = 0.3
  EXPECT_EQ(rim_gap(points, surface_rim, points, surface_rim).distance, 0.0);
}

// A roof folded by 2 atan(0.3) = 33 degrees along x = 0.5. Followed (surface/creases.hpp), the fold is a path of
// S_M edges: its nodes stay on the ridge through smoothing, and every face lies on one of the two planes
// but some within two cells of the rim (nodes joined to a rim node stay off the ridge). Not followed, faces across
// the ridge are chords tilted by up to 16 degrees.
TEST(Creases, ARoofKeepsItsRidgeThroughSmoothing) {
  const TriangleSurface roof = testing::graph_patch(
      [](double x, double y) { return 0.45 + 0.3 * std::abs(x - 0.5) + 0.02 * y; }, {0.1, 0.9}, {0.1, 0.9}, 16, "roof");
  const Eigen::Vector3d left = Eigen::Vector3d(0.3, -0.02, 1).normalized();
  const Eigen::Vector3d right = Eigen::Vector3d(-0.3, -0.02, 1).normalized();
  const auto faces_off_both_planes = [&](double crease_angle) {
    InsertionOptions options;
    options.resolution = 1.0 / 16;
    options.projection.crease_angle = crease_angle;
    const InsertionResult result = insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&roof, 1}, options);
    EXPECT_TRUE(verify_mesh(result.mesh).ok());
    const SurfaceProjection& projection = result.surfaces[0].projections.front();
    for (std::size_t i = 0; i < projection.nodes.size(); ++i) {
      if (projection.creases.line_of[i] < 0) continue;
      const Eigen::Vector3d& x = result.mesh.points[projection.nodes[i]];
      EXPECT_NEAR(x.x(), 0.5, 1e-12) << "crease node " << projection.nodes[i] << " left the ridge";
      EXPECT_NEAR(x.z(), 0.45 + 0.02 * x.y(), 1e-12);
    }
    // Faces off both planes; with the ridge followed, all of them within two cells of the rim.
    int off = 0;
    const std::vector<SurfaceInterface> interfaces = surface_interfaces(result);
    for (const InterfaceFace& face : interfaces[0].faces) {
      if (std::min(std::acos(std::min(1.0, face.normal.dot(left))), std::acos(std::min(1.0, face.normal.dot(right)))) <
          1e-6)
        continue;
      ++off;
      double from_rim = 1.0;
      for (VertexId v : face.vertices) {
        const Eigen::Vector3d& x = result.mesh.points[v];
        from_rim = std::min({from_rim, x.x() - 0.1, 0.9 - x.x(), x.y() - 0.1, 0.9 - x.y()});
      }
      if (crease_angle < 180) {
        EXPECT_LT(from_rim, 2.0 * options.resolution) << "a face across the ridge inside S";
      }
    }
    return std::pair{off, projection.creases.stats};
  };
  const auto [followed_off, followed] = faces_off_both_planes(default_crease_angle);
  const auto [ignored_off, ignored] = faces_off_both_planes(180);
  EXPECT_EQ(followed.lines, 1);
  EXPECT_NEAR(followed.sharpest, 2 * std::atan(0.3) * 180 / std::numbers::pi, 1.0);
  EXPECT_GT(followed.nodes, 6);
  EXPECT_EQ(ignored.lines, 0);
  EXPECT_GT(ignored_off, 4 * followed_off + 10) << "the fold no longer cuts S_M's faces: the test lost its point";
}

}  // namespace
}  // namespace meccano
