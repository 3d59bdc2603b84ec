// Lifting the worst tets after SUS (improvement.hpp): slivers made on purpose are lifted, the equilateral
// minimum never falls and the meccano one not below min(before, threshold), box nodes stay on their sides, the result does not depend on the thread count, and
// on real insertions the S_M nodes stay on S (test_smoothing and test_real_surfaces run the pipeline,
// which improves by default).

#include <meccano/cube_meccano.hpp>
#include <meccano/geometry.hpp>
#include <meccano/improvement.hpp>
#include <meccano/mesh_check.hpp>
#include <meccano/pipeline.hpp>
#include <meccano/quality.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

namespace meccano {
namespace {

// A valid meccano mesh with slivers: every fourth inner node pushed most of the way towards one of its
// neighbours, so the tets around that edge are nearly flat but keep their orientation.
TetMesh mesh_with_slivers() {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 6);
  const VertexTets stars = vertex_to_tets(mesh);
  const GridPoint upper = mesh.meccano.upper_corner();
  auto inner = [&](VertexId v) {
    for (int axis = 0; axis < 3; ++axis)
      if (mesh.grid[v][axis] == 0 || mesh.grid[v][axis] == upper[axis]) return false;
    return true;
  };
  for (VertexId v = 0; v < mesh.num_vertices(); v += 4) {
    if (!inner(v)) continue;
    const VertexId neighbour = mesh.tets[stars.of(v)[0]][0] == v ? mesh.tets[stars.of(v)[0]][1] : mesh.tets[stars.of(v)[0]][0];
    const Eigen::Vector3d before = mesh.points[v];
    for (double fraction : {0.97, 0.9, 0.8, 0.6}) {  // the largest move that keeps the mesh valid
      mesh.points[v] = before + fraction * (mesh.points[neighbour] - before);
      const auto& star = stars.of(v);
      if (std::none_of(star.begin(), star.end(), [&](TetId t) { return is_inverted(mesh, t); })) break;
      mesh.points[v] = before;
    }
  }
  return mesh;
}

TEST(Improvement, LiftsSliversWithoutMakingAnyStarWorse) {
  TetMesh mesh = mesh_with_slivers();
  const QualitySummary before = summarize_quality(mesh);
  ASSERT_EQ(before.inverted, 0);
  ASSERT_LT(before.equilateral.min, 0.1) << "the test lost its slivers";
  const std::vector<Eigen::Vector3d> start = mesh.points;
  const GridPoint upper = mesh.meccano.upper_corner();

  const ImprovementStats stats = improve_worst_tets(mesh, {});
  const QualitySummary after = summarize_quality(mesh);
  EXPECT_TRUE(verify_mesh(mesh, {.physical = true}).ok());
  EXPECT_EQ(after.inverted, 0);
  EXPECT_NEAR(stats.min_quality_before, before.equilateral.min, 1e-12);
  EXPECT_NEAR(stats.min_quality_after, after.equilateral.min, 1e-12);
  EXPECT_GT(after.equilateral.min, 0.3) << "the slivers stayed";
  const double threshold = ImprovementOptions{}.threshold;
  EXPECT_GE(after.meccano.min, std::min(before.meccano.min, threshold)) << "the paper's measure was traded away";
  EXPECT_LT(stats.tets_below_after, stats.tets_below_before);
  EXPECT_GT(stats.nodes_moved, 0);
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    for (int axis = 0; axis < 3; ++axis)
      if (mesh.grid[v][axis] == 0 || mesh.grid[v][axis] == upper[axis]) {
        ASSERT_EQ(mesh.points[v][axis], start[v][axis]) << "a box node left its side";
      }
}

TEST(Improvement, LeavesAMeshWithoutBadTetsAlone) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 6);
  const std::vector<Eigen::Vector3d> start = mesh.points;
  const ImprovementStats stats = improve_worst_tets(mesh, {});
  EXPECT_EQ(stats.passes, 0);
  EXPECT_EQ(mesh.points, start);
}

// In band mode only nodes within the band around the surfaces move, as in SUS: with no surface, none.
TEST(Improvement, MovesOnlyTheBandInBandMode) {
  TetMesh mesh = mesh_with_slivers();
  const std::vector<Eigen::Vector3d> start = mesh.points;
  const ImprovementStats stats = improve_worst_tets(mesh, {}, {}, {.mode = SmoothingMode::band});
  EXPECT_GT(stats.tets_below_before, 0);
  EXPECT_EQ(stats.nodes_moved, 0);
  EXPECT_EQ(mesh.points, start);
}

TEST(Improvement, GivesTheSameMeshWithOneAndTwoThreads) {
  std::vector<std::vector<Eigen::Vector3d>> results;
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    TetMesh mesh = mesh_with_slivers();
    improve_worst_tets(mesh, {});
    results.push_back(mesh.points);
  }
  EXPECT_EQ(results[0], results[1]);
}

// Through the pipeline: the improvement runs by default, keeps the interface on S and never leaves the
// worst tet worse than SUS did; `Improvement::none` leaves SUS's mesh.
TEST(Improvement, RunsAfterSmoothingAndKeepsTheInterfaceOnS) {
  const auto cases = testing::surface_cases(16, false);
  const auto& c = cases.front();
  InsertionOptions options;
  options.resolution = c.resolution;
  options.improve = Improvement::none;
  const InsertionResult plain = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
  options.improve = Improvement::smooth;
  const InsertionResult improved = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
  EXPECT_FALSE(plain.improvement.has_value());
  ASSERT_TRUE(improved.improvement.has_value());
  EXPECT_NEAR(improved.improvement->min_quality_before, plain.quality_after_smoothing.equilateral.min, 1e-12);
  EXPECT_GE(improved.quality_after_smoothing.equilateral.min, plain.quality_after_smoothing.equilateral.min);
  EXPECT_GE(improved.quality_after_smoothing.meccano.min,
            std::min(plain.quality_after_smoothing.meccano.min, options.improvement.threshold));
  EXPECT_TRUE(verify_mesh(improved.mesh, {.physical = true}).ok());
  for (std::size_t s = 0; s < c.surfaces.size(); ++s) {
    const TriangleBVH tree(c.surfaces[s]);
    for (VertexId v : improved.surfaces[s].projection.nodes)
      ASSERT_LE(std::sqrt(tree.closest_point(improved.mesh.points[v]).squared_distance), 1e-12 * c.box.diagonal());
  }
}

}  // namespace
}  // namespace meccano
