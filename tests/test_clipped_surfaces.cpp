// Surfaces that reach the box boundary (issue 19, deliverable 1): clipped to the box
// (surface/box_clipping.hpp) and inserted through the whole pipeline. The result must be a valid mesh
// whose interface is a disk on S with its rim on S's rim: on the box faces exactly where S meets them,
// with the box's nodes still on their planes, and covering S (its area is S's, exactly for a plane).

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/inspect/mesh_file_measure.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/stages/sequence.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/validation.hpp>

#include <run_command.hpp>
#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace meccano {
namespace {

const Box kUnitBox{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};

// S clipped to the box: exactly one part expected.
TriangleSurface clipped(const TriangleSurface& surface, const Box& box) {
  std::vector<TriangleSurface> parts = clip_to_box(surface, box);
  EXPECT_EQ(parts.size(), 1u);
  return parts.front();
}

InsertionResult insert(const TriangleSurface& surface, const Box& box, double resolution) {
  validate_surfaces({&surface, 1}, box);
  InsertionOptions options;
  options.resolution = resolution;
  return insert_surfaces(make_cube_meccano(box, 0), {&surface, 1}, options);
}

// The surface turned so that its z becomes x (a cyclic permutation of the axes: a rotation, so the
// orientation is kept).
TriangleSurface z_to_x(TriangleSurface surface) {
  for (Eigen::Vector3d& p : surface.points) p = Eigen::Vector3d(p.z(), p.x(), p.y());
  return surface;
}

double area(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<VertexId, 3>>& triangles) {
  double sum = 0.0;
  for (const auto& t : triangles) sum += 0.5 * (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).norm();
  return sum;
}

// Every invariant of a clipped interface, for the only surface of `result`. `area_tolerance`: the share
// of S's area the interface's flat faces may differ by (0 up to round-off for a plane).
void expect_clipped_interface(const InsertionResult& result, const TriangleSurface& surface,
                              double area_tolerance = 1e-9) {
  const TetMesh& mesh = result.mesh;
  ASSERT_TRUE(verify_mesh(mesh, {.physical = true}).ok()) << verify_mesh(mesh, {.physical = true}).summary();
  EXPECT_EQ(count_inverted(mesh), 0);
  ASSERT_TRUE(result.surfaces[0].rim_on_box);

  // Every box node still on its planes, exactly: the box-side faces stay flat and tagged.
  const GridPoint upper = mesh.meccano.upper_corner();
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    for (int axis = 0; axis < 3; ++axis) {
      if (mesh.grid[v][axis] == 0 || mesh.grid[v][axis] == upper[axis]) {
        ASSERT_EQ(mesh.points[v][axis], mesh.meccano.to_physical(mesh.grid[v])[axis]) << "node " << v;
      }
    }

  // A disk: one rim loop (every rim node in two rim edges), Euler characteristic 1.
  const SurfaceInterface interface = surface_interfaces(result).front();
  std::vector<std::array<VertexId, 3>> triangles;
  for (const InterfaceFace& face : interface.faces) triangles.push_back(face.vertices);
  std::map<std::pair<VertexId, VertexId>, int> edges;
  std::vector<VertexId> vertices;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      ++edges[std::minmax(t[k], t[(k + 1) % 3])];
      vertices.push_back(t[k]);
    }
  std::ranges::sort(vertices);
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  EXPECT_EQ(static_cast<std::int64_t>(vertices.size()) - static_cast<std::int64_t>(edges.size()) +
                static_cast<std::int64_t>(triangles.size()),
            1);
  std::map<VertexId, int> rim_degree;
  for (const auto& [edge, uses] : edges) {
    EXPECT_LE(uses, 2);
    if (uses == 1) {
      ++rim_degree[edge.first];
      ++rim_degree[edge.second];
    }
  }

  // On S; rim nodes on S's rim; the rim reaches the box: some rim nodes lie on it.
  const TriangleBVH tree(surface);
  const double tolerance = 1e-12 * mesh.meccano.box.diagonal();
  for (VertexId v : vertices) EXPECT_LE(std::sqrt(tree.closest_point(mesh.points[v]).squared_distance), tolerance);
  int rim_nodes_on_box = 0;
  for (const auto& [v, degree] : rim_degree) {
    EXPECT_EQ(degree, 2) << "rim node " << v << " is pinched";
    EXPECT_LE(testing::distance_to_rim(surface, mesh.points[v]), tolerance) << "rim node " << v;
    rim_nodes_on_box += box_sides(mesh.points[v], mesh.meccano.box) != 0;
  }
  EXPECT_GT(rim_nodes_on_box, 0);
  EXPECT_NEAR(area(mesh.points, triangles), surface_area(surface), area_tolerance * surface_area(surface) + tolerance);

  // Quality of the order the disks of the tests get.
  EXPECT_GT(result.quality_after_smoothing.equilateral.min, 0.1);
  EXPECT_GT(result.quality_after_smoothing.min_dihedral_deg, 5.0);
}

// Planes across the box along each axis: the interface divides the box, its rim runs round four faces.
TEST(ClippedSurface, APlaneAcrossTheBoxAlongEachAxis) {
  const TriangleSurface plane = clipped(
      testing::graph_patch([](double, double) { return 0.5; }, {-0.3, 1.3}, {-0.3, 1.3}, 16, "plane"), kUnitBox);
  for (int turns = 0; turns < 3; ++turns) {
    SCOPED_TRACE(turns);
    TriangleSurface turned = plane;
    for (int k = 0; k < turns; ++k) turned = z_to_x(turned);
    expect_clipped_interface(insert(turned, kUnitBox, 0.08), turned);
  }
}

// An oblique plane through four faces, and one cutting off a corner of the box (three faces, three
// box edges).
TEST(ClippedSurface, ObliquePlanes) {
  const TriangleSurface oblique = clipped(
      testing::graph_patch([](double x, double y) { return 0.3 + 0.35 * x + 0.1 * y; }, {-0.3, 1.3}, {-0.3, 1.3}, 16),
      kUnitBox);
  EXPECT_NEAR(surface_area(oblique), std::sqrt(1.0 + 0.35 * 0.35 + 0.1 * 0.1), 1e-12);
  const InsertionResult result = insert(oblique, kUnitBox, 0.08);
  expect_clipped_interface(result, oblique);
  // The plane divides the box: below it (its negative side) lies the volume of 0.3 + 0.35 x + 0.1 y.
  const auto sides = divided_sides(result, 0);
  ASSERT_TRUE(sides.has_value());
  std::array<double, 2> volume{};
  for (TetId t = 0; t < result.mesh.num_tets(); ++t) {
    const TetPoints p = result.mesh.tet_points(t);
    const double v = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0;
    ASSERT_NE((*sides)[0][t], (*sides)[1][t]);
    volume[(*sides)[1][t]] += std::abs(v);
  }
  EXPECT_NEAR(volume[0], 0.3 + 0.35 / 2 + 0.1 / 2, 1e-12);
  EXPECT_NEAR(volume[1], 1.0 - volume[0], 1e-12);

  const TriangleSurface corner = clipped(
      testing::graph_patch([](double x, double y) { return 0.6 - x - y; }, {-0.3, 0.9}, {-0.3, 0.9}, 16), kUnitBox);
  EXPECT_NEAR(surface_area(corner), std::sqrt(3.0) / 4.0 * 0.72, 1e-12);
  expect_clipped_interface(insert(corner, kUnitBox, 0.06), corner);
}

// A curved sheet across the box, in a box that is not a cube.
TEST(ClippedSurface, AWavySheetAcrossANonCubicBox) {
  const Box box{Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 1.0, 1.0)};
  const TriangleSurface sheet =
      clipped(testing::graph_patch([](double x, double y) { return 0.5 + 0.1 * std::sin(3 * x) * std::cos(2 * y); },
                                   {-0.3, 2.3}, {-0.3, 1.3}, 30, "sheet"),
              box);
  expect_clipped_interface(insert(sheet, box, 0.08), sheet, 0.01);
}

// Faults, near vertical, that reach the box top only, the top and one side (through a box edge), and
// three faces.
TEST(ClippedSurface, FaultsLeavingThroughOneTwoAndThreeFaces) {
  const auto fault = [](std::array<double, 2> y_range, std::array<double, 2> z_range) {
    // x = 0.45 + 0.1 z + 0.03 sin(5 y), over y_range x z_range: a graph over (y, z), turned.
    return z_to_x(testing::graph_patch([](double y, double z) { return 0.45 + 0.1 * z + 0.03 * std::sin(5 * y); },
                                       y_range, z_range, 24, "fault"));
  };
  // graph_patch's (x, y, f) becomes (f, x, y): y_range runs along y, z_range along z.
  for (const auto& [y_range, z_range] : std::vector<std::pair<std::array<double, 2>, std::array<double, 2>>>{
           {{0.2, 0.8}, {0.3, 1.2}}, {{0.3, 1.2}, {0.3, 1.2}}, {{-0.2, 1.2}, {0.3, 1.2}}}) {
    SCOPED_TRACE(y_range[0]);
    const TriangleSurface surface = clipped(fault(y_range, z_range), kUnitBox);
    const InsertionResult result = insert(surface, kUnitBox, 0.07);
    expect_clipped_interface(result, surface, 0.01);
    EXPECT_FALSE(divided_sides(result, 0).has_value()) << "its lower rim runs inside the box";
  }
}

// A fault through the box top, moving. Given clipped at each step, it keeps its triangulation while it
// moves along the top (no vertex crosses the plane), and each step is moved from the previous one: the
// interface stays on S and its rim on the top, and the box nodes on their planes. A step down across a
// row of vertices changes the clipped triangulation, and that step is inserted anew.
TEST(ClippedSurface, AFaultThroughTheTopIsMovedAlongIt) {
  // x = 0.45 + 0.1 z + 0.03 sin(5 y) over y in [0.2, 0.8], z in [0.3, 1.2]: rows of vertices 0.0375 apart
  // in z, one at 1.0125.
  const auto fault = [](const Eigen::Vector3d& by) {
    TriangleSurface surface =
        z_to_x(testing::graph_patch([](double y, double z) { return 0.45 + 0.1 * z + 0.03 * std::sin(5 * y); },
                                    {0.2, 0.8}, {0.3, 1.2}, 24, "fault"));
    for (Eigen::Vector3d& p : surface.points) p += by;
    return clipped(surface, kUnitBox);
  };
  constexpr double resolution = 0.07;
  InsertionOptions options;
  options.resolution = resolution;
  SurfaceSequence sequence(make_cube_meccano(kUnitBox, 0), options);
  for (int step = 0; step < 3; ++step) {
    const TriangleSurface surface = fault({step * resolution / 4, step * resolution / 8, 0.0});
    const SequenceStep& done = sequence.advance({surface});
    SCOPED_TRACE("step " + std::to_string(step) + ": " + done.inserted_because);
    EXPECT_EQ(done.kind, step == 0 ? StepKind::inserted : StepKind::moved);
    expect_clipped_interface(done.result, surface, 0.01);
  }
  const TriangleSurface lowered = fault({0.5 * resolution, 0.25 * resolution, -0.02});
  const SequenceStep& done = sequence.advance({lowered});
  EXPECT_EQ(done.kind, StepKind::inserted);
  EXPECT_NE(done.inserted_because.find("triangulation of fault changed"), std::string::npos) << done.inserted_because;
  expect_clipped_interface(done.result, lowered, 0.01);
}

// Real faults reach the ground: in their box with its top at elevation 0, they are clipped there.
TEST(ClippedSurface, RealFaultsCutByTheGround) {
  for (const char* file : {"CRFA-REHZ-EHSN-East_Huasna_fault-CFM4_1000m.ts",
                           "WTRA-SFFS-ANCP-Malibu_Coast_fault_west_steep_alt2-CFM5_1000m.ts"}) {
    SCOPED_TRACE(file);
    const std::optional<TriangleSurface> fault = testing::read_shared_fault(file);
    if (!fault) GTEST_SKIP() << "the shared faults are not beside the checkout";
    Box box = testing::box_around(*fault);
    ASSERT_GT(box.max.z(), 0.0);
    box.max.z() = 0.0;
    const TriangleSurface surface = clipped(*fault, box);
    expect_clipped_interface(insert(surface, box, testing::largest_extent(*fault) / 30), surface, 0.01);
  }
}

// The mean elevation of the rim vertices in the top tenth of the surface's height (tests/bench/
// clipped_surfaces.py's "mean top").
double mean_top(const TriangleSurface& surface) {
  double low = surface.points[0].z(), high = low;
  for (const Eigen::Vector3d& p : surface.points) {
    low = std::min(low, p.z());
    high = std::max(high, p.z());
  }
  std::set<int> top;
  for (const auto& [a, b] : testing::rim_edges(surface))
    for (const int v : {a, b})
      if (surface.points[v].z() >= high - 0.1 * (high - low)) top.insert(v);
  double sum = 0.0;
  for (const int v : top) sum += surface.points[v].z();
  return sum / static_cast<double>(top.size());
}

// East Huasna with the box top at its mean top: its top edge leaves the box and dips back into it five
// times by up to 220 m, less than V_M's 2 km tets, so S_M runs on along the box top and the insertion
// fails (stages/projection.hpp). With the rim set onto the box within E/200 (293 m) it is valid.
TEST(ClippedSurface, ARealFaultWhoseTopDipsBelowTheBoxTopIsSnappedOntoIt) {
  const std::optional<TriangleSurface> fault =
      testing::read_shared_fault("CRFA-REHZ-EHSN-East_Huasna_fault-CFM4_1000m.ts");
  if (!fault) GTEST_SKIP() << "the shared faults are not beside the checkout";
  Box box = testing::box_around(*fault);
  box.max.z() = mean_top(*fault);
  const double extent = testing::largest_extent(*fault);

  const TriangleSurface dipping = clipped(*fault, box);
  validate_surfaces({&dipping, 1}, box);
  InsertionOptions options;
  options.resolution = extent / 30;
  options.finer_retries = 0;
  EXPECT_THROW(insert_surfaces(make_cube_meccano(box, 0), {&dipping, 1}, options), MeshingError);

  TriangleSurface snapped = *fault;
  const RimSnap snap = snap_rim_to_box(snapped, box, extent / 200);
  EXPECT_GT(snap.vertices, 5);
  EXPECT_LE(snap.largest_move, extent / 200);
  const TriangleSurface surface = clipped(snapped, box);
  expect_clipped_interface(insert(surface, box, extent / 30), surface, 0.01);
}

// A sheet whose edge comes within 0.004 of the box top without reaching it: its S_M meets the box, and the
// finer retry's l_r is set by that gap. The retry's progress line says so and names the snap, before the
// long run it starts (here stopped by the progress callback).
TEST(ClippedSurface, ARetrySetByTheGapToTheBoxNamesTheSnap) {
  const TriangleSurface sheet =
      z_to_x(testing::graph_patch([](double y, double z) { return 0.4 + 0.1 * z + 0.02 * std::sin(4 * y); }, {0.2, 0.8},
                                  {0.3, 0.996}, 12, "sheet"));
  validate_surfaces({&sheet, 1}, kUnitBox);
  struct Stopped {
    std::string line;
  };
  InsertionOptions options;
  options.resolution = 0.1;
  options.progress = [](const std::string& line) {
    if (line.find("retrying") != std::string::npos) throw Stopped{line};
  };
  try {
    insert_surfaces(make_cube_meccano(kUnitBox, 0), {&sheet, 1}, options);
    FAIL() << "no retry";
  } catch (const Stopped& stopped) {
    EXPECT_NE(stopped.line.find("set by its gap of 0.004"), std::string::npos) << stopped.line;
    EXPECT_NE(stopped.line.find("--snap-to-box"), std::string::npos) << stopped.line;
  }
}

// Through the tool: the surface file reaches beyond the box, the CLI clips it, and the written mesh
// passes `check`; `measure` clips the surface to the mesh's box too, so the interface covers all of it.
TEST(ClippedSurface, TheToolClipsChecksAndMeasures) {
  const std::filesystem::path work =
      std::filesystem::temp_directory_path() / ("meccano-clipped-" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  const std::string surface =
      testing::write_obj((work / "sheet.obj").string(),
                         testing::graph_patch([](double x, double y) { return 0.4 + 0.2 * x + 0.05 * std::sin(4 * y); },
                                              {-0.2, 1.2}, {-0.2, 1.2}, 20));
  const std::string mesh = (work / "sheet.msh").string();
  const testing::CommandRun insert =
      testing::run_command(std::string(MECCANO_CLI) + " --box 0,0,0,1,1,1 --resolution 0.08 --quiet --surface " +
                           surface + ":sheet --output " + mesh);
  ASSERT_EQ(insert.status, 0) << insert.output;
  const testing::CommandRun check = testing::run_command(std::string(MECCANO_CLI) + " check " + mesh);
  EXPECT_EQ(check.status, 0) << check.output;
  for (const char* line : {"negative_sheet: ok", "positive_sheet: ok"})
    EXPECT_NE(check.output.find(line), std::string::npos) << check.output;
  TriangleSurface whole = read_surface(surface);
  whole.name = "sheet";
  const MeshMeasure measure = measure_mesh_file(mesh, {&whole, 1});
  ASSERT_NE(measure.find("interface_sheet"), nullptr);
  const SurfaceAccuracy& accuracy = *measure.find("interface_sheet")->accuracy;
  EXPECT_NEAR(accuracy.area_ratio, 1.0, 1e-3);
  EXPECT_LT(accuracy.hausdorff, 0.01);
  EXPECT_LT(accuracy.normal_deviation_max_deg, 5.0);
  std::filesystem::remove_all(work);
}

// Through the tool: a sheet whose top edge zigzags across the box top, 0.015 below it at every other
// vertex, less than the tets at l_r = 0.08 (and at the retries' 0.04 and 0.02). Without --snap-to-box the
// insertion fails and names the option; with --snap-to-box 0.02 the rim runs on the top and `check` passes.
TEST(ClippedSurface, TheToolSnapsARimThatDipsBelowTheTop) {
  const std::filesystem::path work =
      std::filesystem::temp_directory_path() / ("meccano-snapped-" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  TriangleSurface sheet = z_to_x(testing::graph_patch(
      [](double y, double z) { return 0.4 + 0.1 * z + 0.02 * std::sin(4 * y); }, {0.2, 0.8}, {0.3, 1.0}, 12, "sheet"));
  std::vector<int> top;
  for (int v = 0; v < static_cast<int>(sheet.points.size()); ++v)
    if (sheet.points[v].z() == 1.0) top.push_back(v);
  std::ranges::sort(top, {}, [&](int v) { return sheet.points[v].y(); });
  ASSERT_EQ(top.size(), 13u);
  for (std::size_t i = 0; i < top.size(); ++i) sheet.points[top[i]].z() = i % 2 == 0 ? 1.03 : 0.985;
  const std::string surface = testing::write_obj((work / "sheet.obj").string(), sheet);
  const std::string insert = std::string(MECCANO_CLI) + " --box 0,0,0,1,1,1 --resolution 0.08 --surface " + surface +
                             ":sheet --output " + (work / "sheet.msh").string();

  const testing::CommandRun dipping = testing::run_command(insert + " --quiet");
  EXPECT_EQ(dipping.status, 1) << dipping.output;
  EXPECT_NE(dipping.output.find("--snap-to-box"), std::string::npos) << dipping.output;
  EXPECT_FALSE(std::filesystem::exists(work / "sheet.msh"));

  const testing::CommandRun snapped = testing::run_command(insert + " --snap-to-box 0.02");
  ASSERT_EQ(snapped.status, 0) << snapped.output;
  EXPECT_NE(snapped.output.find("6 rim vertices set onto the box (--snap-to-box), moved by up to 0.015"),
            std::string::npos)
      << snapped.output;
  const testing::CommandRun check =
      testing::run_command(std::string(MECCANO_CLI) + " check " + (work / "sheet.msh").string());
  EXPECT_EQ(check.status, 0) << check.output;
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace meccano
