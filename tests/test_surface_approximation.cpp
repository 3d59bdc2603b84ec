// The healed surface approximation S_M (paper §4.2) on every kind of test surface, several boxes and
// resolutions, and random perturbations: a manifold disk with an axis-parallel rim, none of the
// configurations the healing rules remove, nodes close to S, oriented like S, the mesh conforming and
// V_M still a ball.

#include <meccano/error.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/stages/surface_approximation.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>

namespace meccano {
namespace {

using Case = testing::SurfaceCase;

class SurfaceApproximationOn : public ::testing::TestWithParam<Case> {};

TEST_P(SurfaceApproximationOn, IsAHealedDiskCloseToSAndOrientedLikeIt) {
  const Case& c = GetParam();
  TetMesh mesh = make_cube_meccano(c.box, 0);
  const int count = static_cast<int>(c.surfaces.size());
  std::vector<TetRegion> regions;
  std::vector<TriangleBVH> trees;
  regions.reserve(c.surfaces.size());
  for (const auto& surface : c.surfaces) {
    trees.emplace_back(surface);
    std::vector<TetRegion*> earlier;
    for (auto& r : regions) earlier.push_back(&r);
    VolumetricStats stats;
    regions.push_back(approximate_volume(mesh, trees.back(), {c.resolution}, stats, earlier));
  }
  std::vector<HealingStats> healing(c.surfaces.size());
  for (int s = 0; s < count; ++s) {
    std::vector<TetRegion*> others;
    for (int o = 0; o < count; ++o)
      if (o != s) others.push_back(&regions[o]);
    healing[s] = approximate_surface(mesh, regions[s], c.surfaces[s], trees[s], s, {}, others);
    EXPECT_LE(healing[s].passes, SurfaceApproximationOptions{}.max_healing_passes);
  }

  const auto mesh_check = verify_mesh(mesh);
  ASSERT_TRUE(mesh_check.ok()) << mesh_check.summary();
  for (int s = 0; s < count; ++s) {
    SCOPED_TRACE("surface " + std::to_string(s + 1));
    const SurfaceApproximationCheck check = check_surface_approximation(mesh, regions[s], s);
    EXPECT_TRUE(check.healed()) << check.describe();
    EXPECT_EQ(check.rim_loops, 1);
    EXPECT_EQ(check.euler, 1);
    EXPECT_EQ(check.reflex_rim_corners, healing[s].reflex_corners_left);
    EXPECT_TRUE(check_ball(mesh, regions[s]).is_ball()) << "healing broke V_M";

    // Nodes within V_M's reach of S (growth_band times it where V_M's growth crossed the offset at the
    // reach), and the faces' normals agree with S's nearby (area-weighted cosine).
    const double reach = growth_reach(mesh.meccano, c.resolution);
    const ApproximationFaces faces = approximation_faces(mesh, regions[s], s, healing[s].side);
    ASSERT_EQ(static_cast<std::int64_t>(faces.triangles.size()), check.faces);
    double agreement = 0, area = 0;
    for (const auto& t : faces.triangles) {
      for (VertexId v : t)
        ASSERT_LT(std::sqrt(trees[s].closest_point(mesh.points[v]).squared_distance), growth_band * reach)
            << "S_M node " << v << " is far from S";
      const Eigen::Vector3d area_vector =
          0.5 * (mesh.points[t[1]] - mesh.points[t[0]]).cross(mesh.points[t[2]] - mesh.points[t[0]]);
      const Eigen::Vector3d centroid = (mesh.points[t[0]] + mesh.points[t[1]] + mesh.points[t[2]]) / 3;
      const auto& st = c.surfaces[s].triangles[trees[s].closest_point(centroid).triangle];
      const auto& p = c.surfaces[s].points;
      agreement += area_vector.dot((p[st[1]] - p[st[0]]).cross(p[st[2]] - p[st[0]]).normalized());
      area += area_vector.norm();
    }
    EXPECT_GT(agreement / area, 0.5) << "S_M is not oriented like S";
  }
}

INSTANTIATE_TEST_SUITE_P(AllSurfacesAndBoxes, SurfaceApproximationOn,
                         ::testing::ValuesIn(testing::surface_cases(16, true)),
                         [](const ::testing::TestParamInfo<Case>& param) { return param.param.name; });

// Steps 1 and 2 for one surface in the unit cube's meccano.
struct Healed {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  TetRegion region;
  HealingStats stats;
  SurfaceApproximationCheck check;
};

Healed heal_in_unit_cube(const TriangleSurface& surface, double resolution) {
  Healed healed;
  const TriangleBVH tree(surface);
  VolumetricStats volumetric_stats;
  healed.region = approximate_volume(healed.mesh, tree, {resolution}, volumetric_stats);
  healed.stats = approximate_surface(healed.mesh, healed.region, surface, tree, 0);
  healed.check = check_surface_approximation(healed.mesh, healed.region, 0);
  return healed;
}

TEST(SurfaceApproximation, HealingStatisticsCountTheRules) {
  const Healed healed = heal_in_unit_cube(testing::saddle(24), 1.0 / 32);
  // The saddle needs every kind of repair; the counts must reflect work actually done.
  const HealingStats& stats = healed.stats;
  EXPECT_GT(stats.initial_faces, 0);
  EXPECT_GT(stats.extension_faces, 0);
  EXPECT_GT(stats.tets_with_two_faces, 0);
  EXPECT_GT(stats.triangles_with_two_rim_edges, 0);
  EXPECT_GT(stats.dividing_edges, 0);
  EXPECT_GT(stats.passes, 1);
  EXPECT_EQ(stats.faces, healed.check.faces);
}

// Filling a reflex rim corner made corbels here whose removal brought the corner back: healing cycled
// (fill, remove corbels) until its pass limit. Each corner is now filled once at most.
TEST(SurfaceApproximation, ReflexCornersAreFilledOnceSoHealingEnds) {
  const Healed healed = heal_in_unit_cube(
      read_surface(std::string(MECCANO_TEST_DATA_DIR) + "/disk_fill_corbel_cycle.obj"), 0.031441647624062763);
  EXPECT_GT(healed.stats.reflex_corners_filled, 0);
  EXPECT_TRUE(healed.check.healed()) << healed.check.describe();
  EXPECT_TRUE(healed.check.is_disk()) << healed.check.describe();
}

// A strip narrower than V_M's cubes (0.04 wide, the longest edge of V_M's tets 0.06-0.09 here), tilted so
// that it crosses their layers. Around it nearly every node of V_M lies beyond its rim, and S_M covered
// nothing of it on either side until the rim stopped counting where S is narrow; where S_M then narrows to
// one square, its squares are corbels whose removal would cut it, and they are split instead.
TEST(SurfaceApproximation, AStripNarrowerThanTheCubesIsCoveredAlongItsLength) {
  for (const double resolution : {1.0 / 12, 1.0 / 16}) {
    SCOPED_TRACE("l_r = " + std::to_string(resolution));
    const TriangleSurface strip =
        testing::graph_patch([](double x, double y) { return 0.3 + 0.4 * x + 0.2 * y; }, {0.1, 0.9}, {0.47, 0.51}, 16);
    const Healed healed = heal_in_unit_cube(strip, resolution);
    EXPECT_TRUE(healed.check.healed()) << healed.check.describe();
    EXPECT_TRUE(healed.check.is_disk()) << healed.check.describe();
    double low = 1.0, high = 0.0;  // the extent of S_M's nodes along the strip
    for (const auto& triangle : approximation_faces(healed.mesh, healed.region, 0, healed.stats.side).triangles)
      for (VertexId v : triangle) {
        low = std::min(low, healed.mesh.points[v].x());
        high = std::max(high, healed.mesh.points[v].x());
      }
    EXPECT_LT(low, 0.1 + resolution) << "S_M misses the strip's start";
    EXPECT_GT(high, 0.9 - resolution) << "S_M misses the strip's end";
  }
}

TEST(SurfaceApproximation, CheckDetectsUnhealedConfigurations) {
  // The raw S_M (boundary faces of V_M on one side), before any healing, violates the rules.
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  const TriangleSurface surface = testing::spherical_cap(16);
  const TriangleBVH tree(surface);
  VolumetricStats volumetric_stats;
  TetRegion region = approximate_volume(mesh, tree, {1.0 / 16}, volumetric_stats);
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      const TetId across = mesh.neighbours[t][f];
      if (!region[t] || across == no_tet || region[across]) continue;
      const auto& v = mesh.tets[t];
      bool above = true;
      for (int local : face_vertices[f]) above = above && tree.side(mesh.points[v[local]]) > 0;
      if (above) {
        mesh.face_tags[t][f] = interface_tag(0);
        mesh.face_tags[across][mesh.face_towards(across, t)] = interface_tag(0);
      }
    }
  const SurfaceApproximationCheck raw = check_surface_approximation(mesh, region, 0);
  EXPECT_FALSE(raw.healed()) << raw.describe();
  EXPECT_GT(raw.tets_with_two_faces + raw.triangles_with_two_rim_edges + raw.dividing_edges + raw.oblique_rim_edges, 0);
}

TEST(SurfaceApproximation, EdgesToTheBoxAreSplitWhenTheSurfaceIsCloseToIt) {
  // A plane 0.01 above the floor with tets of 1/4: S_M (on the side away from the floor) gets edges to
  // floor nodes, which healing splits.
  const Healed healed =
      heal_in_unit_cube(testing::graph_patch([](double, double) { return 0.01; }, {0.2, 0.8}, {0.2, 0.8}, 4), 0.25);
  EXPECT_GT(healed.stats.cross_surface_edges, 0);
  EXPECT_TRUE(healed.check.healed()) << healed.check.describe();
  EXPECT_EQ(healed.check.nodes_on_box_or_other_surface, 0);
  EXPECT_TRUE(verify_mesh(healed.mesh).ok());
}

TEST(SurfaceApproximation, SurfaceSqueezedBetweenBoxSidesFailsClearly) {
  // A box 0.02 thick: V_M spans it, so neither side of S has room for S_M.
  const Box thin{{0, 0, 0}, {1, 1, 0.02}};
  const TriangleSurface plane = testing::graph_patch([](double, double) { return 0.01; }, {0.2, 0.8}, {0.2, 0.8}, 4);
  TetMesh mesh = make_cube_meccano(thin, {8, 8, 1}, 0);
  const TriangleBVH tree(plane);
  VolumetricStats volumetric_stats;
  TetRegion region = approximate_volume(mesh, tree, {0.25}, volumetric_stats);
  try {
    approximate_surface(mesh, region, plane, tree, 0);
    FAIL() << "expected a MeshingError";
  } catch (const MeshingError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("too close to the box"), std::string::npos) << message;
    EXPECT_NE(message.find("positive side"), std::string::npos) << "both sides are tried: " << message;
    EXPECT_NE(message.find("negative side"), std::string::npos) << "both sides are tried: " << message;
  }
  EXPECT_TRUE(verify_mesh(mesh).ok());
  EXPECT_EQ(check_surface_approximation(mesh, region, 0).faces, 0) << "a failed attempt leaves no tags behind";
}

}  // namespace
}  // namespace meccano
