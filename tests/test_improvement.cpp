// Lifting the worst tets after SUS (stages/improvement.hpp): slivers made on purpose are lifted, the equilateral
// minimum never falls and the meccano one not below min(before, threshold), box nodes stay on their sides,
// the result does not depend on the thread count, and on real insertions the S_M nodes stay on S
// (test_smoothing and test_real_surfaces run the pipeline, which improves by default). The shape passes
// widen the worst dihedral angles without lowering either mean ratio's minimum. Flips: the mesh
// stays conforming with its box sides tagged and flipped tets leave the bisection hierarchy
// (test_flips_pipeline runs them through the pipeline).

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/mesh/bisection.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/improvement.hpp>
#include <meccano/stages/pipeline.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>

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
    const VertexId neighbour =
        mesh.tets[stars.of(v)[0]][0] == v ? mesh.tets[stars.of(v)[0]][1] : mesh.tets[stars.of(v)[0]][0];
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
  const double threshold = ImprovementOptions{}.lowest_threshold();
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

// With first_threshold below threshold the stage runs twice (the worst tets first): the same mesh as the
// two stages one after the other, their work added, the counts before taken against the final threshold.
TEST(Improvement, ALadderIsTheStageAtTheFirstThresholdThenAtTheThreshold) {
  ImprovementOptions options;
  options.topology = true;
  ASSERT_GT(options.first_threshold, 0.0);
  ASSERT_LT(options.first_threshold, options.threshold);
  TetMesh laddered = mesh_with_slivers(), stepwise = mesh_with_slivers();
  std::int64_t below = 0;
  for (TetId t = 0; t < laddered.num_tets(); ++t)
    below += mean_ratio_equilateral(oriented_points(laddered, t)) < options.threshold;
  const double smallest = summarize_quality(laddered).equilateral.min;

  const ImprovementStats ladder = improve_worst_tets(laddered, {}, options);
  ImprovementOptions first = options, then = options;
  first.threshold = options.first_threshold;
  first.first_threshold = then.first_threshold = 0.0;
  const ImprovementStats lifted = improve_worst_tets(stepwise, {}, first);
  const ImprovementStats finished = improve_worst_tets(stepwise, {}, then);

  EXPECT_EQ(laddered.points, stepwise.points);
  EXPECT_EQ(laddered.tets, stepwise.tets);
  EXPECT_TRUE(verify_mesh(laddered, {.physical = true}).ok());
  EXPECT_GT(finished.node_updates, 0) << "the second stage had nothing to do: the case no longer tests the ladder";
  EXPECT_EQ(ladder.passes, lifted.passes + finished.passes);
  EXPECT_EQ(ladder.node_updates, lifted.node_updates + finished.node_updates);
  EXPECT_EQ(ladder.shape_node_updates, lifted.shape_node_updates + finished.shape_node_updates);
  EXPECT_EQ(ladder.flips.operations(), lifted.flips.operations() + finished.flips.operations());
  EXPECT_EQ(ladder.tets_below_before, below);
  EXPECT_EQ(ladder.min_quality_before, smallest);
  EXPECT_EQ(ladder.tets_below_after, finished.tets_below_after);
  EXPECT_EQ(ladder.min_quality_after, finished.min_quality_after);
  EXPECT_EQ(ladder.floors.mean_ratio, options.threshold);
  EXPECT_EQ(ladder.first_threshold, options.first_threshold);
  EXPECT_EQ(ladder.floors.min_dihedral_deg, options.min_dihedral);
  EXPECT_EQ(ladder.floors.max_dihedral_deg, options.max_dihedral);
  EXPECT_EQ(finished.first_threshold, 0.0) << "one stage";
}

// A mesh with no tet below first_threshold has no worst tets to lift first: the ladder is the stage at
// the threshold alone, and says so.
TEST(Improvement, ALadderWithNoTetBelowItsFirstThresholdIsOneStage) {
  ImprovementOptions options;
  options.topology = true;
  const TetMesh slivers = mesh_with_slivers();
  const double smallest = summarize_quality(slivers).equilateral.min;
  ASSERT_GT(smallest, 0.0);
  ASSERT_LT(smallest, options.threshold);
  options.first_threshold = smallest;  // nothing is below it
  ImprovementOptions one_stage = options;
  one_stage.first_threshold = 0.0;
  TetMesh laddered = slivers, single = slivers;

  const ImprovementStats ladder = improve_worst_tets(laddered, {}, options);
  const ImprovementStats stage = improve_worst_tets(single, {}, one_stage);

  EXPECT_GT(stage.node_updates, 0) << "the stage had nothing to do: the case tests nothing";
  EXPECT_EQ(laddered.points, single.points);
  EXPECT_EQ(laddered.tets, single.tets);
  EXPECT_EQ(ladder.node_updates, stage.node_updates);
  EXPECT_EQ(ladder.flips.operations(), stage.flips.operations());
  EXPECT_EQ(ladder.first_threshold, 0.0);
  EXPECT_EQ(ladder.min_quality_before, smallest);
  EXPECT_EQ(ladder.min_quality_after, stage.min_quality_after);
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
            std::min(plain.quality_after_smoothing.meccano.min, options.improvement.lowest_threshold()));
  EXPECT_TRUE(verify_mesh(improved.mesh, {.physical = true}).ok());
  for (std::size_t s = 0; s < c.surfaces.size(); ++s) {
    const TriangleBVH tree(c.surfaces[s]);
    for (VertexId v : improved.surfaces[s].projections.front().nodes)
      ASSERT_LE(std::sqrt(tree.closest_point(improved.mesh.points[v]).squared_distance), 1e-12 * c.box.diagonal());
  }
}


// The shape passes, on curved, creased, irregular and stacked surfaces: against the same insertion without
// them, the worst dihedral angle against its floor (15° or 150°) improves (the cases' worst tets miss them),
// neither mean ratio's minimum falls below what the passes keep, the mesh stays valid, and the S_M nodes
// stay on S.
TEST(Improvement, ShapePassesWidenTheWorstAnglesAndKeepTheInterfaceOnS) {
  const std::vector<std::string> names{"spherical_cap_unit_cube_lr32", "paper_like_unit_cube_lr32",
                                       "perturbed_paper_like_unit_cube_lr16", "stacked_pair_2x1x1_box_lr16"};
  int tried = 0;
  for (const auto& c : testing::surface_cases(16, false)) {
    if (std::find(names.begin(), names.end(), c.name) == names.end()) continue;
    SCOPED_TRACE(c.name);
    ++tried;
    InsertionOptions options;
    options.resolution = c.resolution;
    options.improve = Improvement::smooth;
    // One stage: with the ladder (first_threshold) the second stage's Newton passes move nodes the first
    // stage's shape passes placed, and on the spherical cap they gave back 0.4 % of its worst angle.
    options.improvement.first_threshold = 0.0;
    options.improvement.min_dihedral = 0.0;
    options.improvement.max_dihedral = 180.0;
    const InsertionResult plain = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
    options.improvement.min_dihedral = ImprovementOptions{}.min_dihedral;
    options.improvement.max_dihedral = ImprovementOptions{}.max_dihedral;
    const InsertionResult shaped = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
    ASSERT_EQ(plain.improvement->shape_passes, 0);
    ASSERT_GT(shaped.improvement->shape_passes, 0);
    const QualitySummary& before = plain.quality_after_smoothing;
    const QualitySummary& after = shaped.quality_after_smoothing;
    // The worst angle against its floor: the passes raise the mesh's worst, and may trade an angle that
    // is better than it (the smallest angle for the largest, say).
    auto worst_angle_ratio = [](const QualitySummary& q) {
      return std::min(q.min_dihedral_deg / 15.0, (180.0 - q.max_dihedral_deg) / 30.0);
    };
    ASSERT_LT(worst_angle_ratio(before), 1.0) << "no tet missed the floors";
    EXPECT_GT(worst_angle_ratio(after), worst_angle_ratio(before));
    EXPECT_LT(shaped.improvement->tets_outside_floors_after, shaped.improvement->tets_outside_floors_before);
    const double threshold = options.improvement.lowest_threshold();
    EXPECT_GE(after.equilateral.min, std::min(before.equilateral.min, threshold));
    EXPECT_GE(after.meccano.min, std::min(before.meccano.min, threshold));
    EXPECT_TRUE(verify_mesh(shaped.mesh, {.physical = true}).ok());
    for (std::size_t s = 0; s < c.surfaces.size(); ++s) {
      const TriangleBVH tree(c.surfaces[s]);
      for (VertexId v : shaped.surfaces[s].projections.front().nodes)
        ASSERT_LE(std::sqrt(tree.closest_point(shaped.mesh.points[v]).squared_distance), 1e-12 * c.box.diagonal());
    }
  }
  EXPECT_EQ(tried, static_cast<int>(names.size()));
}

// The box-side faces as (sorted vertices, tag): flips must keep every one.
std::map<std::array<VertexId, 3>, FaceTag> box_faces(const TetMesh& mesh) {
  std::map<std::array<VertexId, 3>, FaceTag> faces;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f)
      if (mesh.neighbours[t][f] == no_tet) {
        std::array<VertexId, 3> key{mesh.tets[t][face_vertices[f][0]], mesh.tets[t][face_vertices[f][1]],
                                    mesh.tets[t][face_vertices[f][2]]};
        std::sort(key.begin(), key.end());
        faces.emplace(key, mesh.face_tags[t][f]);
      }
  return faces;
}

TEST(Flips, MendSliversWithoutTouchingTheBoxAndEndTheHierarchyWhereTheyAct) {
  TetMesh mesh = mesh_with_slivers();
  const QualitySummary before = summarize_quality(mesh);
  const auto box_before = box_faces(mesh);
  const std::vector<Eigen::Vector3d> points = mesh.points;
  const int tets_before = mesh.num_tets();

  const FlipStats stats = flip_worst_tets(mesh, {});
  const QualitySummary after = summarize_quality(mesh);
  const MeshInvariantReport check = verify_mesh(mesh, {.physical = true});
  EXPECT_TRUE(check.ok()) << check.summary();
  EXPECT_GT(stats.operations(), 0);
  EXPECT_GT(stats.flips_2_3 + stats.flips_3_2, 0);
  EXPECT_GT(stats.flips_4_4 + stats.edge_removals, 0);
  EXPECT_EQ(stats.surface_edge_flips, 0);
  EXPECT_EQ(mesh.num_tets(), tets_before + stats.tets_created - stats.tets_removed);
  EXPECT_GT(after.equilateral.min, before.equilateral.min);
  EXPECT_EQ(mesh.points, points) << "flips move no node";
  EXPECT_EQ(box_faces(mesh), box_before);

  std::int64_t remeshed = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t) remeshed += !mesh.bisectable(t);
  EXPECT_GT(remeshed, 0);
  EXPECT_LE(remeshed, stats.tets_created);
  const auto first_remeshed =
      std::find_if(mesh.kinds.begin(), mesh.kinds.end(), [](TetKind k) { return !k.bisectable(); });
  const TetId t = static_cast<TetId>(first_remeshed - mesh.kinds.begin());
  EXPECT_EQ(mesh.level(t), -1);
  const std::vector<TetId> marked{t};
  EXPECT_THROW(refine_marked(mesh, marked), MeshingError);
}

TEST(Flips, NeverLowerTheWorstTetAndAreRepeatable) {
  TetMesh once = mesh_with_slivers();
  TetMesh twice = mesh_with_slivers();
  flip_worst_tets(once, {});
  flip_worst_tets(twice, {});
  EXPECT_EQ(once.tets, twice.tets);
  EXPECT_EQ(once.neighbours, twice.neighbours);
  const double min_once = summarize_quality(once).equilateral.min;
  flip_worst_tets(once, {});
  EXPECT_GE(summarize_quality(once).equilateral.min, min_once);
  EXPECT_TRUE(verify_mesh(once, {.physical = true}).ok());
}

}  // namespace
}  // namespace meccano
