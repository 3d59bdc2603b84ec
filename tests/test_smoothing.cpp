// Simultaneous untangling and smoothing (paper §4.4): the distortion's derivatives, the freedom of box
// and surface nodes, and the whole pipeline on every test surface, box and resolution: no inverted tet,
// S_M's nodes on S and its rim on the rim of S, S_M still a disk embedded in P, the paper's quality, and
// the same mesh whatever the thread count.

#include <meccano/error.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/report/insertion_report.hpp>
#include <meccano/stages/improvement.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/stages/smoothing.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>

#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>

namespace meccano {
namespace {

TEST(Distortion, DerivativesMatchFiniteDifferences) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  auto random_point = [&] { return Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)); };
  for (int trial = 0; trial < 50; ++trial) {
    TetPoints p{random_point(), random_point(), random_point(), random_point()};  // inverted about half the time
    Eigen::Matrix3d target;
    target << random_point(), random_point(), random_point();
    if (std::abs(target.determinant()) < 0.05) continue;
    if (target.determinant() < 0) target.col(0) = -target.col(0);
    const Eigen::Matrix3d inverse = target.inverse();
    const double delta = trial % 2 ? 1e-2 : 0.3;
    for (int k = 0; k < 4; ++k) {
      const Distortion exact = regularised_distortion(p, inverse, k, delta);
      const double step = 1e-6;
      Eigen::Vector3d gradient;
      Eigen::Matrix3d hessian;
      for (int i = 0; i < 3; ++i) {
        TetPoints plus = p, minus = p;
        plus[k][i] += step;
        minus[k][i] -= step;
        const Distortion up = regularised_distortion(plus, inverse, k, delta);
        const Distortion down = regularised_distortion(minus, inverse, k, delta);
        gradient[i] = (up.value - down.value) / (2 * step);
        hessian.col(i) = (up.gradient - down.gradient) / (2 * step);
      }
      EXPECT_LE((gradient - exact.gradient).norm(), 1e-5 * (1 + exact.gradient.norm()))
          << "trial " << trial << " vertex " << k;
      EXPECT_LE((hessian - exact.hessian).norm(), 1e-5 * (1 + exact.hessian.norm()))
          << "trial " << trial << " vertex " << k;
    }
  }
}

TEST(Distortion, IsOneAndStationaryForARotatedScaledTarget) {
  Eigen::Matrix3d target;
  target << 1, 0, 0.5, 0, 1, 0.5, 0, 0, 1;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d edges = 2.5 * rotation * target;
  const TetPoints p{Eigen::Vector3d(0.3, -1, 2), Eigen::Vector3d(0.3, -1, 2) + edges.col(0),
                    Eigen::Vector3d(0.3, -1, 2) + edges.col(1), Eigen::Vector3d(0.3, -1, 2) + edges.col(2)};
  for (int k = 0; k < 4; ++k) {
    const Distortion d = regularised_distortion(p, target.inverse(), k, 0.0);
    EXPECT_NEAR(d.value, 1.0, 1e-12);
    EXPECT_LE(d.gradient.norm(), 1e-12);
    EXPECT_GE(d.hessian.eigenvalues().real().minCoeff(), -1e-12);
  }
}

TEST(Smoothing, LeavesAnUntouchedMeccanoAlone) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1.3, 1}}, 3);  // non-cubic cells: the target is the cell
  const std::vector<Eigen::Vector3d> before = mesh.points;
  const SmoothingStats stats = smooth_mesh(mesh, {});
  EXPECT_EQ(stats.inverted_after, 0);
  ASSERT_FALSE(stats.sweeps.empty());
  EXPECT_NEAR(stats.sweeps.back().min_quality, 1.0, 1e-12);
  for (std::size_t v = 0; v < before.size(); ++v) EXPECT_LE((mesh.points[v] - before[v]).norm(), 1e-12);
}

// Box nodes move within their side (their fixed coordinates stay bit for bit), corners not at all.
TEST(Smoothing, UntanglesAScrambledMeshAndKeepsBoxNodesOnTheirSides) {
  const Box box{{0, 0, 0}, {2, 1, 1}};
  TetMesh mesh = make_cube_meccano(box, 6);
  const std::vector<Eigen::Vector3d> before = mesh.points;
  const GridPoint upper = mesh.meccano.upper_corner();
  std::mt19937 random(5);
  std::uniform_real_distribution<double> shift(-0.12, 0.12);  // 0.48 of the finest edge (1/4)
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    for (int axis = 0; axis < 3; ++axis)
      if (mesh.grid[v][axis] != 0 && mesh.grid[v][axis] != upper[axis]) mesh.points[v][axis] += shift(random);
  const SmoothingStats stats = smooth_mesh(mesh, {});
  ASSERT_GT(stats.inverted_before, 0);
  EXPECT_EQ(stats.inverted_after, 0);
  EXPECT_GT(stats.box_nodes, 0);
  EXPECT_TRUE(verify_mesh(mesh, {.physical = true}).ok());
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    for (int axis = 0; axis < 3; ++axis)
      if (mesh.grid[v][axis] == 0 || mesh.grid[v][axis] == upper[axis]) {
        ASSERT_EQ(mesh.points[v][axis], before[v][axis]);
      }
}

// With no sweeps (a moved interface's step when the move inverted nothing) SUS only counts.
TEST(Smoothing, WithNoSweepsMovesNothingAndCountsTheInvertedTets) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 3);
  const GridPoint upper = mesh.meccano.upper_corner();
  const auto inner = std::ranges::find_if(mesh.grid, [&](const GridPoint& g) {
    return std::ranges::all_of(std::array{0, 1, 2}, [&](int axis) { return g[axis] != 0 && g[axis] != upper[axis]; });
  });
  ASSERT_NE(inner, mesh.grid.end());
  mesh.points[static_cast<std::size_t>(inner - mesh.grid.begin())].x() += 1.0;  // out of the box
  const std::int64_t inverted = count_inverted(mesh);
  ASSERT_GT(inverted, 0);
  const std::vector<Eigen::Vector3d> before = mesh.points;
  const SmoothingStats stats = smooth_mesh(mesh, {}, {.max_sweeps = 0});
  EXPECT_EQ(mesh.points, before);
  EXPECT_EQ(stats.inverted_before, inverted);
  EXPECT_EQ(stats.inverted_after, inverted);
  EXPECT_FALSE(stats.untangled());
  EXPECT_TRUE(stats.sweeps.empty());
}

TEST(Smoothing, ReportsAMeshItCannotUntangle) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);  // every node is a box corner: all fixed
  mesh.points[0] = {2, 2, 2};                                   // past the opposite corner: every tet turns inside out
  const SmoothingStats stats = smooth_mesh(mesh, {}, {.max_sweeps = 3});
  EXPECT_GT(stats.inverted_after, 0);
  EXPECT_FALSE(stats.untangled());
  EXPECT_LE(stats.sweeps.size(), 3u);
}

// --- the whole pipeline ------------------------------------------------------------------------------

InsertionResult insert(std::span<const TriangleSurface> surfaces, const Box& box, double resolution,
                       SmoothingOptions smoothing = {}) {
  InsertionOptions options;
  options.resolution = resolution;
  options.smoothing = smoothing;
  return insert_surfaces(make_cube_meccano(box, 0), surfaces, options);
}

// S_M's triangles keep the orientation of the projection in P: S_M is still embedded in S.
std::int64_t folded_triangles(const SurfaceProjection& projection) {
  std::int64_t folded = 0;
  for (const auto& t : projection.triangles) {
    const Eigen::Vector2d a = projection.uv[t[1]] - projection.uv[t[0]], b = projection.uv[t[2]] - projection.uv[t[0]];
    folded += (a.x() * b.y() - a.y() * b.x()) * projection.orientation <= 0.0;
  }
  return folded;
}

using Case = testing::SurfaceCase;

// The stage tests' cases at their coarser resolutions (l_r = 1/16 in the unit cube and the 2x1x1 box,
// perturbed surfaces at 1/24), which keeps the suite fast.
std::vector<Case> smoothing_cases() {
  std::vector<Case> cases;
  for (Case& c : testing::surface_cases(16, true))
    if (c.name.ends_with("_lr16") || c.name.ends_with("_perturbed_lr24")) cases.push_back(std::move(c));
  return cases;
}

class SmoothingOn : public ::testing::TestWithParam<Case> {};

// Quality at least the paper's (min 0.29, mean 0.88 less 0.005) on the smooth surfaces; the randomly perturbed
// ones (noisy triangles, folded S) are held to untangling and the interface invariants, their quality
// is recorded in doc/results.md.
// No tet inverted, the mesh valid, every S_M node on S and its rim nodes on the rim of S, S_M embedded in
// P and still a healed disk.
void expect_untangled_with_interfaces_on_s(const InsertionResult& result, const Case& c) {
  EXPECT_TRUE(result.smoothing.untangled());
  const auto check = verify_mesh(result.mesh, {.physical = true});
  ASSERT_TRUE(check.ok()) << check.summary();
  const double tolerance = 1e-12 * c.box.diagonal();
  for (std::size_t s = 0; s < c.surfaces.size(); ++s) {
    SCOPED_TRACE("surface " + std::to_string(s + 1));
    const SurfaceProjection& projection = result.surfaces[s].projections.front();
    const TriangleBVH tree(c.surfaces[s]);
    for (std::size_t i = 0; i < projection.nodes.size(); ++i) {
      const Eigen::Vector3d& x = result.mesh.points[projection.nodes[i]];
      ASSERT_LE(std::sqrt(tree.closest_point(x).squared_distance), tolerance) << "node off S";
      if (projection.on_rim[i]) {
        ASSERT_LE(testing::distance_to_rim(c.surfaces[s], x), tolerance) << "rim node off the rim";
      }
    }
    EXPECT_EQ(folded_triangles(projection), 0);
    EXPECT_TRUE(check_surface_approximation(result.mesh, result.surfaces[s].volumetric, static_cast<int>(s)).healed());
  }
  EXPECT_EQ(result.quality_after_smoothing.inverted, 0);
}

TEST_P(SmoothingOn, UntanglesKeepsTheInterfaceOnSAndReachesThePapersQuality) {
  const Case& c = GetParam();
  const InsertionResult result = insert(c.surfaces, c.box, c.resolution);
  expect_untangled_with_interfaces_on_s(result, c);
  if (!c.name.ends_with("_perturbed_lr24")) {
    EXPECT_GE(result.quality_after_smoothing.meccano.min, 0.29);
    // The paper's 0.88 within issue 18's tolerance of 0.005 on either measure: the improvement trades a
    // little of the paper's mean for the equilateral floors (0.8792 on the spherical cap in the 2x1x1 box).
    EXPECT_GE(result.quality_after_smoothing.meccano.mean, 0.88 - 0.005);
  }
}

INSTANTIATE_TEST_SUITE_P(CoarseCases, SmoothingOn, ::testing::ValuesIn(smoothing_cases()),
                         [](const ::testing::TestParamInfo<Case>& param) { return param.param.name; });

// The stretched cap's case, and the options that stop SUS after 6 sweeps on it.
Case stretched_cap() {
  for (Case& c : testing::surface_cases(16, false))
    if (c.name == "spherical_cap_2x1x1_box_lr16") return std::move(c);
  throw std::logic_error("no test case spherical_cap_2x1x1_box_lr16");
}
InsertionOptions six_sweeps(const Case& c) {
  InsertionOptions options;
  options.resolution = c.resolution;
  options.smoothing.max_sweeps = 6;
  return options;
}

// The cap stretched into the 2x1x1 box at l_r = 1/16 untangles after 8 sweeps with S_M on the positive
// side and after 4 on the negative side (before S_M's triangles had a floor on their area in P, the
// positive side kept about 190 flat tets for good). With at most 6 sweeps, and without the untangling
// flips (--improve smooth), the positive side stays tangled, and the insertion runs again with S_M on the
// negative side, which untangles. With the side fixed, the failure is reported.
TEST(Smoothing, TriesTheOtherSideWhenOneCannotBeUntangled) {
  const Case c = stretched_cap();
  InsertionOptions options = six_sweeps(c);
  options.improve = Improvement::smooth;
  const InsertionResult result = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
  EXPECT_TRUE(result.smoothing.untangled());
  EXPECT_EQ(result.surfaces[0].healing_stats.side, -1);
  EXPECT_NE(result.side_retry.find("could not untangle"), std::string::npos) << result.side_retry;
  EXPECT_NE(insertion_report_json(result, Stage::smoothing).find("\"side_retry\""), std::string::npos);

  options.approximation.side_rule = SideRule::positive_only;
  options.finer_retries = 0;  // a finer l_r would untangle it
  try {
    insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
    ADD_FAILURE() << "a tangled mesh was returned";
  } catch (const MeshingError& failure) {
    EXPECT_NE(std::string(failure.what()).find("tets are still inverted"), std::string::npos) << failure.what();
  }
}

// The same cap and 6 sweeps with --improve topology: the tets the sweeps leave inverted are flipped, SUS
// runs again from there and untangles the positive side itself.
TEST(Smoothing, FlipsAroundTheTetsSweepsLeaveInvertedAndUntanglesAgain) {
  const Case c = stretched_cap();
  InsertionOptions options = six_sweeps(c);
  options.approximation.side_rule = SideRule::positive_only;
  options.finer_retries = 0;
  const InsertionResult result = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
  expect_untangled_with_interfaces_on_s(result, c);
  EXPECT_GE(result.untangling_flip_rounds, 1);
  EXPECT_GT(result.untangling_flips.operations(), 0);
  EXPECT_GT(result.smoothing.sweeps.size(), 6u);  // the sweeps of both SUS runs
  EXPECT_NE(insertion_report_json(result, Stage::smoothing).find("\"untangling_flips\""), std::string::npos);
}

TEST(Smoothing, GivesTheSameMeshWithOneAndTwoThreads) {
  const TriangleSurface surface = testing::paper_like_patch(48);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const InsertionResult one = insert({&surface, 1}, {{0, 0, 0}, {1, 1, 1}}, 1.0 / 24);
  omp_set_num_threads(2);
  const InsertionResult two = insert({&surface, 1}, {{0, 0, 0}, {1, 1, 1}}, 1.0 / 24);
  omp_set_num_threads(threads);
  ASSERT_EQ(one.mesh.points.size(), two.mesh.points.size());
  for (std::size_t v = 0; v < one.mesh.points.size(); ++v)
    ASSERT_EQ(one.mesh.points[v], two.mesh.points[v]) << "node " << v;
  EXPECT_EQ(one.mesh.tets, two.mesh.tets);
  EXPECT_EQ(one.smoothing.sweeps.size(), two.smoothing.sweeps.size());
}

// Each node's edge ring from S_M's nodes (0 on S_M, -1 if unreached), found independently of the pipeline.
std::vector<int> edge_rings_from_interface(const InsertionResult& result) {
  std::vector<int> ring(result.mesh.points.size(), -1);
  std::vector<VertexId> front = result.surfaces[0].projections.front().nodes;
  for (VertexId v : front) ring[v] = 0;
  const VertexTets stars = vertex_to_tets(result.mesh);
  for (int r = 1; !front.empty(); ++r) {
    std::vector<VertexId> next;
    for (VertexId v : front)
      for (TetId t : stars.of(v))
        for (VertexId w : result.mesh.tets[t])
          if (ring[w] < 0) {
            ring[w] = r;
            next.push_back(w);
          }
    front = std::move(next);
  }
  return ring;
}

// A spherical cap in the unit cube at l_r = 1/24, through `last_stage` with `options`' other settings.
InsertionResult inserted_cap(InsertionOptions options, Stage last_stage) {
  const TriangleSurface surface = testing::spherical_cap(16);
  options.resolution = 1.0 / 24;
  options.last_stage = last_stage;
  return insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&surface, 1}, options);
}

// The edges of remeshed tets whose tets do not form one ring (or one fan, on the box) when walked
// through the neighbours: an edge a flip made twice, or a fan split in two.
std::int64_t edges_of_remeshed_tets_off_one_ring(const TetMesh& mesh) {
  std::map<std::pair<VertexId, VertexId>, std::int64_t> tets_holding;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) ++tets_holding[std::minmax(mesh.tets[t][i], mesh.tets[t][j])];
  // Adds to `reached` the tets from t around edge (a, b), crossing first the face opposite `towards`,
  // until the box or a tet reached already.
  auto walk = [&](TetId t, VertexId a, VertexId b, VertexId towards, std::set<TetId>& reached) {
    for (TetId current = t;;) {
      const auto& v = mesh.tets[current];
      const int face = static_cast<int>(std::ranges::find(v, towards) - v.begin());
      const TetId next = mesh.neighbours[current][face];
      if (next == no_tet || !reached.insert(next).second) return;
      // The face crossed holds a, b and the fourth vertex of `current`: `next` goes on across the face
      // opposite that vertex.
      const VertexId crossed = towards;
      for (VertexId w : v)
        if (w != a && w != b && w != crossed) towards = w;
      current = next;
    }
  };
  std::int64_t off = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    if (mesh.bisectable(t)) continue;
    const auto& v = mesh.tets[t];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        std::array<VertexId, 2> rest{};
        for (int k = 0, r = 0; k < 4; ++k)
          if (k != i && k != j) rest[r++] = v[k];
        std::set<TetId> reached{t};
        walk(t, v[i], v[j], rest[0], reached);
        walk(t, v[i], v[j], rest[1], reached);
        off += static_cast<std::int64_t>(reached.size()) != tets_holding[std::minmax(v[i], v[j])];
      }
  }
  return off;
}

// Flips around the inverted tets of a mesh that one sweep leaves badly tangled keep it a valid complex
// (conforming, tagged, every edge of a new tet with one ring of tets around it) and S_M a healed disk
// embedded in P, although in a tangled mesh a flip's cavity can overlap other tets.
TEST(Smoothing, UntanglingFlipsKeepATangledMeshValid) {
  InsertionResult result = inserted_cap({}, Stage::projection);
  std::vector<SurfaceProjection*> projections{&result.surfaces[0].projections.front()};
  const SmoothingStats swept = smooth_mesh(result.mesh, projections, {.max_sweeps = 1, .fallback_sweeps = 0});
  ASSERT_GT(swept.inverted_after, 100);
  const std::vector<TetRegion*> regions{&result.surfaces[0].volumetric};
  const FlipStats flips = flip_inverted_tets(result.mesh, projections, regions, {});
  EXPECT_GT(flips.operations(), 0);
  const auto check = verify_mesh(result.mesh, {.physical = false});
  EXPECT_TRUE(check.ok()) << check.summary();
  EXPECT_EQ(edges_of_remeshed_tets_off_one_ring(result.mesh), 0);
  const SurfaceApproximationCheck interface =
      check_surface_approximation(result.mesh, result.surfaces[0].volumetric, 0);
  EXPECT_TRUE(interface.healed()) << interface.describe();
  EXPECT_EQ(folded_triangles(*projections[0]), 0);
}

// In band mode only nodes within the band's rings of S_M move; the mesh is still untangled.
TEST(Smoothing, BandModeMovesOnlyNodesNearTheSurface) {
  InsertionResult result = inserted_cap({}, Stage::projection);
  const std::vector<Eigen::Vector3d> projected = result.mesh.points;
  const std::vector<int> ring = edge_rings_from_interface(result);

  SmoothingOptions band{.mode = SmoothingMode::band, .band_rings = 2};
  std::vector<SurfaceProjection*> projections{&result.surfaces[0].projections.front()};
  const SmoothingStats stats = smooth_mesh(result.mesh, projections, band);
  EXPECT_TRUE(stats.untangled());
  EXPECT_GT(stats.inverted_before, 0);
  std::int64_t moved_in_band = 0;
  for (VertexId v = 0; v < result.mesh.num_vertices(); ++v) {
    if (ring[v] > 2) ASSERT_EQ(result.mesh.points[v], projected[v]) << "node " << v << " in ring " << ring[v];
    else moved_in_band += result.mesh.points[v] != projected[v];
  }
  EXPECT_GT(moved_in_band, 0);
}

// With drag_rings, the nodes within that many rings of S_M follow it after the projection (and in a band
// no farther than the band): S_M's nodes land where they did without, fewer tets are inverted, box nodes
// stay on the box, nothing beyond the rings moves, and SUS then untangles the mesh as before.
TEST(Smoothing, NodesNearTheInterfaceFollowItWithDragRings) {
  InsertionOptions options;
  const InsertionResult still = inserted_cap(options, Stage::projection);
  const std::vector<int> ring = edge_rings_from_interface(still);
  const std::int64_t inverted_without = still.surfaces[0].projection_stats().inverted_tets;
  ASSERT_GT(inverted_without, 0);
  EXPECT_EQ(still.drag.rings, 0);

  for (const SmoothingMode mode : {SmoothingMode::whole_mesh, SmoothingMode::band}) {
    SCOPED_TRACE(mode == SmoothingMode::whole_mesh ? "whole" : "band");
    options.drag_rings = 4;
    options.smoothing.mode = mode;
    options.smoothing.band_rings = 2;
    const InsertionResult dragged = inserted_cap(options, Stage::projection);
    const int rings = mode == SmoothingMode::whole_mesh ? 4 : 2;
    EXPECT_EQ(dragged.drag.rings, rings);
    EXPECT_LT(dragged.drag.inverted_tets, inverted_without / 2);
    EXPECT_TRUE(verify_mesh(dragged.mesh, {.physical = false}).ok());
    std::int64_t followed = 0;
    for (VertexId v = 0; v < still.mesh.num_vertices(); ++v) {
      if (ring[v] == 0 || ring[v] > rings)
        ASSERT_EQ(dragged.mesh.points[v], still.mesh.points[v]) << "node " << v << " in ring " << ring[v];
      else followed += dragged.mesh.points[v] != still.mesh.points[v];
    }
    EXPECT_EQ(followed, dragged.drag.nodes);
    EXPECT_GT(followed, 0);

    const InsertionResult smoothed = inserted_cap(options, Stage::smoothing);
    EXPECT_TRUE(smoothed.smoothing.untangled());
    EXPECT_TRUE(verify_mesh(smoothed.mesh, {.physical = true}).ok());
  }
}

// On this disk (surface s1 of stress case 87, seed 1) untangling towards the meccano target stalls at one
// inverted tet between two rim nodes for any number of sweeps; the equilateral target untangles it, and
// the smoothing then aims at the meccano target again.
TEST(Smoothing, FallsBackToTheEquilateralTargetWhereTheMeccanoTargetStalls) {
  const TriangleSurface surface = read_surface(std::string(MECCANO_TEST_DATA_DIR) + "/disk_meccano_target_stalls.obj");
  InsertionOptions options;
  options.resolution = 0.025860230418841217;
  options.approximation.side_rule = SideRule::positive_only;
  // Smoothing alone after SUS: every tet keeps its meccano counterpart, which the bound below is about (a
  // crease mend's tets are measured against the equilateral tet).
  options.improve = Improvement::smooth;
  const InsertionResult result = insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&surface, 1}, options);
  EXPECT_TRUE(result.smoothing.untangled());
  EXPECT_EQ(result.smoothing.fallback_sweep, options.smoothing.fallback_sweeps + 1);
  ASSERT_FALSE(result.smoothing.sweeps.empty());
  EXPECT_EQ(result.smoothing.sweeps.back().target, SmoothingTarget::meccano);
  EXPECT_TRUE(verify_mesh(result.mesh, {.physical = true}).ok());
  EXPECT_EQ(folded_triangles(result.surfaces[0].projections.front()), 0);
  // 0.254 before S_M's triangles had a floor on their area in P, 0.245 since (and the equilateral minimum
  // 0.16 -> 0.21, the smallest dihedral angle 5.0 -> 6.4 degrees).
  EXPECT_GE(result.quality_after_smoothing.meccano.min, 0.24);

  options.smoothing.fallback_sweeps = 0;
  options.smoothing.max_sweeps = 40;
  options.finer_retries = 0;
  try {
    insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&surface, 1}, options);
    ADD_FAILURE() << "the meccano target untangles this disk: the test lost its point";
  } catch (const MeshingError& failure) {
    EXPECT_NE(std::string(failure.what()).find("tets are still inverted"), std::string::npos) << failure.what();
  }
}

TEST(Smoothing, UntanglesTowardsTheEquilateralTarget) {
  const TriangleSurface surface = testing::saddle(16);
  const InsertionResult result =
      insert({&surface, 1}, {{0, 0, 0}, {1, 1, 1}}, 1.0 / 16, {.target = SmoothingTarget::equilateral});
  EXPECT_TRUE(result.smoothing.untangled());
  EXPECT_TRUE(verify_mesh(result.mesh, {.physical = true}).ok());
  EXPECT_EQ(folded_triangles(result.surfaces[0].projections.front()), 0);
}

}  // namespace
}  // namespace meccano
