// The fast subset of the real-surface set (issue 17; the whole set, at four resolutions and against Gmsh,
// is tests/bench/bench_faults.sh): shared SCEC faults read as they are (GOCAD TSurf, UTM metres) and the
// synthetic surfaces of tests/data/hard_surfaces that reproduce what makes them hard, each in the box of
// the benchmarks (its bounding box grown by a tenth of its largest extent E) at l_r = E / divisor.
//
// Every result must be a valid mesh (conforming, positively oriented, the box's volume, no sliver) whose interface
// lies on S and is oriented like it, reached at the l_r asked without retries, with the tet count within
// 30 % of estimate_tets and the interface normals within the targets: area-weighted mean <= 1
// degree at E/50 (1.5 at E/30). The max <= 15 degrees is not met on every fault (doc/benchmarks.md); here the max is
// held below the value measured on each case when this test was written, rounded up by a few degrees,
// so that a change that brings back the chords across creases fails.

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/inspect/mesh_file_measure.hpp>
#include <meccano/io/mesh_writers.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/pipeline.hpp>

#include <scratch_directory.hpp>
#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <ostream>
#include <string>

namespace meccano {
namespace {

struct RealCase {
  std::string name;  // test name
  std::string file;  // a shared fault (file name in ../shared/data/faults) or a path
  bool shared;       // whether `file` is a shared fault
  double divisor;    // l_r = E / divisor
  double max_normal_deviation_deg;
};

// No sliver: with the improvement's ladder of thresholds (the default since 2026-12-06) every case measured
// 13.9-16.3 degrees, at most 151.9 degrees and an equilateral mean ratio of 0.377-0.403; the bounds leave
// room for another path (a change of rounding moves single runs by a degree or two). With the flips at
// the old threshold 0.35 the cases measured 9.8-15.7 and up to 162 degrees; with smoothing alone Malibu
// Coast at E/30 ended at 6.8 and 166 degrees, and once at 0.1 degrees (SUS's δ > 0 on valid stars
// flattened the objective of tets far below their target's size).
constexpr double minimum_dihedral_deg = 12.0;
constexpr double maximum_dihedral_deg = 155.0;
constexpr double minimum_mean_ratio = 0.35;

void PrintTo(const RealCase& c, std::ostream* os) { *os << c.name; }

std::string hard_surface(const std::string& name) {
  return std::string(MECCANO_TEST_DATA_DIR) + "/hard_surfaces/" + name;
}

class RealSurface : public testing::ScratchDirectoryTest, public ::testing::WithParamInterface<RealCase> {
 protected:
  RealSurface() : ScratchDirectoryTest("meccano-real") {}
};

TEST_P(RealSurface, IsInsertedValidFaithfulAndAsEstimated) {
  const RealCase& c = GetParam();
  const std::string file = c.shared ? testing::shared_fault(c.file) : c.file;
  if (file.empty()) GTEST_SKIP() << "no shared fault data beside the checkout";
  TriangleSurface surface = read_surface(file);
  surface.name = "fault";
  const double extent = testing::largest_extent(surface);
  InsertionOptions options;
  options.resolution = extent / c.divisor;
  const InsertionResult result =
      insert_surfaces(make_cube_meccano(testing::box_around(surface), 0), {&surface, 1}, options);

  const MeshInvariantReport check = verify_mesh(result.mesh);
  ASSERT_TRUE(check.ok()) << check.summary();
  const QualitySummary quality = summarize_quality(result.mesh);
  EXPECT_GE(quality.min_dihedral_deg, minimum_dihedral_deg) << "a sliver the improvement did not lift";
  EXPECT_LE(quality.max_dihedral_deg, maximum_dihedral_deg) << "a cap the improvement did not open";
  EXPECT_GE(quality.equilateral.min, minimum_mean_ratio) << "a tet the improvement did not lift";
  EXPECT_TRUE(result.finer_retries.empty()) << result.finer_retries.front();
  EXPECT_TRUE(result.side_retry.empty()) << result.side_retry;
  EXPECT_EQ(result.smoothing.fallback_sweep, 0) << "the meccano target stalled";
  const double tets = static_cast<double>(result.mesh.num_tets());
  EXPECT_NEAR(static_cast<double>(result.estimated_tets) / tets, 1.0, 0.3) << result.estimated_tets << " for " << tets;

  const std::string msh = path("fault.msh");
  write_msh41(result.mesh, output_groups(result), msh);
  const MeshMeasure measure = measure_mesh_file(msh, {&surface, 1});
  EXPECT_EQ(measure.inverted, 0);
  const SurfaceAccuracy& a = *measure.find("interface_fault")->accuracy;
  EXPECT_LT(a.node_distance_max, 1e-9 * extent) << "an S_M node off S";
  EXPECT_EQ(a.flipped_faces, 0);
  EXPECT_LT(a.hausdorff, 0.25 * options.resolution);
  // The 1 degree is for l_r = E/50; a coarser interface follows S's bends less closely.
  EXPECT_LE(a.normal_deviation_mean_deg, c.divisor >= 50 ? 1.0 : 1.5);
  EXPECT_LE(a.normal_deviation_max_deg, c.max_normal_deviation_deg);
}

INSTANTIATE_TEST_SUITE_P(
    FastSubset, RealSurface,
    ::testing::Values(
        RealCase{"East_Huasna_E50", "CRFA-REHZ-EHSN-East_Huasna_fault-CFM4_1000m.ts", true, 50, 20},
        RealCase{"Pipes_Canyon_E30", "MJVA-HSLZ-SBMT-Pipes_Canyon_fault_north_extension-CFM5_1000m.ts", true, 30, 25},
        RealCase{"Malibu_Coast_E30", "WTRA-SFFS-ANCP-Malibu_Coast_fault_west_steep_alt2-CFM5_1000m.ts", true, 30, 18},
        RealCase{"creased_E30", hard_surface("creased.obj"), false, 30, 25},
        RealCase{"low_dip_E30", hard_surface("low_dip.obj"), false, 30, 6},
        // Two rim nodes slid together during smoothing (47 m to 0.4 m apart at l_r = 236 m), the tet
        // between them and two free nodes stayed inverted, and the side retry ran (30 s instead of 10)
        // until rim nodes kept a floor on their gaps along the rim (smoothing.cpp, rim_gap_floor).
        RealCase{"low_dip_E100", hard_surface("low_dip.obj"), false, 100, 10},
        RealCase{"thin_long_E30", hard_surface("thin_long.obj"), false, 30, 3},
        RealCase{"vertical_E30", hard_surface("vertical.obj"), false, 30, 3}),
    [](const ::testing::TestParamInfo<RealCase>& test) { return test.param.name; });

// A fault whose east end is a tail 1.2-1.5 km deep, narrower than V_M's cubes at E/30 (the longest edge of
// their tets 1.7 km), as Western Santa Cruz Island's is. Around the tail nearly every node of V_M lay
// beyond the rim and got no side, so S_M left the tail out on both sides, and the retry at l_r / 2 made
// three times the tets. Once the rim stopped counting where S is narrow (surface/narrow_rim.hpp), S_M
// covered the tail on the positive side, but the squares of a neck one square wide were corbels: removing
// them cut the tail off, and the component clean-up dropped it (the other side was tried). Such corbels
// are now split, not removed, and the positive side's S_M reaches within 0.7 l_r of the tail's end.
TEST(ThinTail, ATailNarrowerThanTheCubesIsInsertedAtTheResolutionAsked) {
  TriangleSurface surface = read_surface(hard_surface("thin_tail.obj"));
  surface.name = "tail";
  const double extent = testing::largest_extent(surface);
  InsertionOptions options;
  options.resolution = extent / 30;
  const InsertionResult result =
      insert_surfaces(make_cube_meccano(testing::box_around(surface), 0), {&surface, 1}, options);
  EXPECT_TRUE(result.finer_retries.empty()) << result.finer_retries.front();
  EXPECT_TRUE(result.side_retry.empty()) << result.side_retry;
  EXPECT_EQ(result.surfaces[0].healing_stats.side, +1);
  EXPECT_TRUE(verify_mesh(result.mesh).ok());
  EXPECT_LE(result.surfaces[0].projections.front().stats.rim_gap, options.resolution);
}

// A fault tapering to a 10 degree tip: near the tip it is narrower than V_M's cubes at every l_r. Its sides
// there no longer keep V_M's nodes from a side, while the tip's own vertex, with no rim point across it,
// still does: at E/30 S_M covers the tip without growing past it, and the insertion needs no retry.
// (Before, S_M on the positive side stopped 4-5 l_r short of the tip and the other side was tried.) At
// E/100 the positive side still stops 4 l_r short of the tip: the rim gap finds it before any smoothing,
// and the other side is inserted at the l_r asked.
TEST(SharpTip, ATipNarrowerThanTheCubesIsCoveredAtTheResolutionAsked) {
  TriangleSurface surface = read_surface(hard_surface("sharp_tip.obj"));
  surface.name = "tip";
  const double extent = testing::largest_extent(surface);
  const TetMesh mesh = make_cube_meccano(testing::box_around(surface), 0);
  for (double divisor : {30.0, 100.0}) {
    SCOPED_TRACE("E/" + std::to_string(static_cast<int>(divisor)));
    InsertionOptions options;
    options.resolution = extent / divisor;
    const InsertionResult result = insert_surfaces(mesh, {&surface, 1}, options);
    EXPECT_TRUE(result.finer_retries.empty()) << result.finer_retries.front();
    if (divisor == 30.0) {
      EXPECT_TRUE(result.side_retry.empty()) << result.side_retry;
    } else {
      EXPECT_NE(result.side_retry.find("tip: S_M leaves part of S uncovered"), std::string::npos) << result.side_retry;
      EXPECT_EQ(result.side_retry.find("sweeps"), std::string::npos) << "smoothing ran first: " << result.side_retry;
    }
    EXPECT_TRUE(verify_mesh(result.mesh).ok());
    EXPECT_LE(result.surfaces[0].projections.front().stats.rim_gap, max_rim_gap_in_resolutions * options.resolution);
  }
}

// Western Santa Cruz Island at E/30, E/50 and E/70. At E/50 and E/70, before S_M's triangles had a floor
// on their area in P, two of its rim nodes slid onto one point during smoothing, the tets between them
// stayed flat on both sides of S, and the retry at l_r / 2 made three times the tets. At E/30 its east end,
// a tongue 1.3 km deep, is narrower than V_M's cubes: before its rim stopped keeping V_M's nodes from a
// side there (surface/narrow_rim.hpp), S_M on either side stopped 9-13 km short of its tip, and the retry
// at l_r / 2 made 3.5 times the tets. Now each is inserted as asked.
TEST(WesternSantaCruzIsland, IsInsertedAtE30E50AndE70WithoutRetries) {
  const std::optional<TriangleSurface> fault =
      testing::read_shared_fault("WTRA-SFFS-SRSM-Western_Santa_Cruz_Island_fault_trim-CFM5_1000m.ts");
  if (!fault) GTEST_SKIP() << "no shared fault data beside the checkout";
  const TriangleSurface& surface = *fault;
  const double extent = testing::largest_extent(surface);
  for (double divisor : {30.0, 50.0, 70.0}) {
    SCOPED_TRACE("E/" + std::to_string(static_cast<int>(divisor)));
    InsertionOptions options;
    options.resolution = extent / divisor;
    const InsertionResult result =
        insert_surfaces(make_cube_meccano(testing::box_around(surface), 0), {&surface, 1}, options);
    EXPECT_TRUE(result.finer_retries.empty()) << result.finer_retries.front();
    EXPECT_TRUE(result.side_retry.empty()) << result.side_retry;
    EXPECT_TRUE(verify_mesh(result.mesh).ok());
    const double tets = static_cast<double>(result.mesh.num_tets());
    EXPECT_NEAR(static_cast<double>(result.estimated_tets) / tets, 1.0, 0.3)
        << result.estimated_tets << " for " << tets;
  }
}

// A surface trimmed along its triangles (a fault model cut to a region) has a sawtooth rim: a rim edge
// whose triangle sticks out joins two rim vertices of the rest. Before such chords were split, S's own
// parameterization failed for want of corners at every l_r, and so did the insertion.
TEST(TrimmedRim, ASawtoothRimIsInsertedAtTheResolutionAsked) {
  const TriangleSurface surface = testing::sawtooth_patch(10);
  InsertionOptions options;
  options.resolution = 1.0 / 16;
  const InsertionResult result = insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&surface, 1}, options);
  EXPECT_TRUE(result.finer_retries.empty()) << result.finer_retries.front();
  const MeshInvariantReport check = verify_mesh(result.mesh);
  EXPECT_TRUE(check.ok()) << check.summary();
  const TriangleBVH tree(surface);
  for (const VertexId v : result.surfaces[0].projections.front().nodes)
    EXPECT_LT(tree.closest_point(result.mesh.points[v]).squared_distance, 1e-18) << "S_M node " << v << " off S";
}

}  // namespace
}  // namespace meccano
