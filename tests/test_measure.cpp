// The measurements of any MSH mesh (`meccano-immerse measure`, inspect/mesh_file_measure.hpp): on the module's own mesh
// they agree with the insertion's report and with the method's guarantees (nodes on S, faces oriented like
// S); on hand-made meshes whose answers are known exactly (a square patch against a shifted, flipped or
// larger square; a regular tet beside an inverted one) they give those answers; the command's report is
// the library's, and its errors name the files.

#include <meccano/error.hpp>
#include <meccano/inspect/mesh_file_measure.hpp>
#include <meccano/io/mesh_writers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/pipeline.hpp>

#include <run_command.hpp>
#include <scratch_directory.hpp>
#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include <unistd.h>

namespace meccano {
namespace {

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The square [lo, hi]^2 at height z as two triangles, normal towards +z.
TriangleSurface square(double lo, double hi, double z, const std::string& name) {
  TriangleSurface s;
  s.name = name;
  s.points = {{lo, lo, z}, {hi, lo, z}, {hi, hi, z}, {lo, hi, z}};
  s.triangles = {{0, 1, 2}, {0, 2, 3}};
  return s;
}

// The module's mesh of a curved patch, made once: l_r = 0.1 in the unit cube.
class ModuleMesh : public ::testing::Test {
 protected:
  static constexpr double resolution = 0.1;

  static void SetUpTestSuite() {
    patch_ = new TriangleSurface(testing::paper_like_patch(6));
    patch_->name = "patch";
    InsertionOptions options;
    options.resolution = resolution;
    result_ = new InsertionResult(insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {patch_, 1}, options));
    file_ =
        (std::filesystem::temp_directory_path() / ("meccano-measure-" + std::to_string(::getpid()) + ".msh")).string();
    write_msh41(result_->mesh, output_groups(*result_), file_);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove(file_);
    delete result_;
    delete patch_;
  }

  static inline TriangleSurface* patch_ = nullptr;
  static inline InsertionResult* result_ = nullptr;
  static inline std::string file_;
};

TEST_F(ModuleMesh, QualityIsTheInsertionReportsAfterSmoothing) {
  const MeshMeasure measure = measure_mesh_file(file_);
  const QualitySummary& report = result_->quality_after_smoothing;
  EXPECT_EQ(measure.source, file_);
  EXPECT_EQ(measure.nodes, result_->mesh.num_vertices());
  EXPECT_EQ(measure.tets, result_->mesh.num_tets());
  EXPECT_EQ(measure.inverted, 0);
  EXPECT_EQ(measure.equilateral.min, report.equilateral.min);  // the same tets, coordinates written exactly
  EXPECT_NEAR(measure.equilateral.mean, report.equilateral.mean, 1e-12);
  EXPECT_NEAR(measure.equilateral.std, report.equilateral.std, 1e-12);
  EXPECT_EQ(measure.min_dihedral_deg, report.min_dihedral_deg);
  EXPECT_EQ(measure.max_dihedral_deg, report.max_dihedral_deg);
  // The histogram's first bins hold the tets below 0.1, 0.2 (20 bins of 0.05).
  const auto& bins = report.equilateral_histogram.counts;
  ASSERT_EQ(bins.size(), 20u);
  EXPECT_EQ(measure.below[0], bins[0] + bins[1]);
  EXPECT_EQ(measure.below[1], bins[0] + bins[1] + bins[2] + bins[3]);
  ASSERT_EQ(measure.interfaces.size(), 1u);
  EXPECT_EQ(measure.interfaces[0].name, "interface_patch");
  EXPECT_FALSE(measure.interfaces[0].accuracy) << "no surface given";
}

TEST_F(ModuleMesh, InterfaceLiesOnTheSurfaceAndIsOrientedLikeIt) {
  const MeshMeasure measure = measure_mesh_file(file_, {patch_, 1});
  const InterfaceMeasure* interface = measure.find("interface_patch");
  ASSERT_TRUE(interface && interface->accuracy) << measure.text();
  const std::vector<SurfaceInterface> faces = surface_interfaces(*result_);
  EXPECT_EQ(interface->faces, static_cast<std::int64_t>(faces[0].faces.size()));
  const SurfaceAccuracy& a = *interface->accuracy;
  EXPECT_LT(a.node_distance_max, 1e-12);  // every S_M node was moved onto S
  EXPECT_LE(a.node_distance_mean, a.node_distance_max);
  // S_M's faces are flat chords of the curved S: apart from it, by much less than l_r.
  EXPECT_GT(a.hausdorff, 0.0);
  EXPECT_LT(a.hausdorff, resolution);
  EXPECT_EQ(a.flipped_faces, 0);
  EXPECT_GT(a.normal_deviation_max_deg, 0.0);
  EXPECT_LT(a.normal_deviation_max_deg, 30.0);
  EXPECT_LE(a.normal_deviation_mean_deg, a.normal_deviation_max_deg);
  EXPECT_NEAR(a.area_ratio, 1.0, 0.02);
}

// A mesh of the unit cube (4 cells a side, 3 bisection levels: edges of 1/8) whose group interface_square
// is the square [0.25, 0.75]^2 at z = 0.5, made of the faces of the tets below it (normals +z) or above
// (-z); with a hole, without the faces inside [0.375, 0.625]^2.
class SquarePatch : public testing::ScratchDirectoryTest {
 protected:
  SquarePatch() : ScratchDirectoryTest("meccano-measure") {}

  std::string write_square_mesh(const std::string& name, bool upward, bool hole = false) const {
    const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {4, 4, 4}, 3);
    MeshGroups groups = standard_groups(mesh);
    FaceGroup& patch = groups.surfaces.emplace_back(FaceGroup{"interface_square", interface_tag(0), {}});
    for (TetId t = 0; t < mesh.num_tets(); ++t)
      for (int f = 0; f < 4; ++f) {
        bool on_square = true, in_hole = hole;
        for (const VertexId v : mesh.outward_face(t, f)) {
          const Eigen::Vector3d& p = mesh.points[v];
          const auto within = [&p](double lo, double hi) {
            return p.x() >= lo && p.x() <= hi && p.y() >= lo && p.y() <= hi;
          };
          on_square = on_square && p.z() == 0.5 && within(0.25, 0.75);
          in_hole = in_hole && within(0.375, 0.625);
        }
        const bool below = mesh.points[mesh.tets[t][f]].z() < 0.5;  // the vertex opposite the face
        if (on_square && !in_hole && below == upward) patch.faces.push_back({t, f});
      }
    write_msh41(mesh, groups, path(name));
    return path(name);
  }
};

TEST_F(SquarePatch, ShiftedSquareIsAtItsShiftEverywhere) {
  const TriangleSurface shifted = square(0.25, 0.75, 0.51, "square");
  const MeshMeasure measure = measure_mesh_file(write_square_mesh("up.msh", true), {&shifted, 1});
  ASSERT_EQ(measure.interfaces.size(), 1u);
  const InterfaceMeasure& interface = measure.interfaces[0];
  EXPECT_EQ(interface.faces, 32);  // 2 x 2 cells, 4 x 4 squares of 2 triangles at level 3
  EXPECT_NEAR(interface.area, 0.25, 1e-15);
  ASSERT_TRUE(interface.accuracy);
  const SurfaceAccuracy& a = *interface.accuracy;
  EXPECT_NEAR(a.node_distance_max, 0.01, 1e-15);
  EXPECT_NEAR(a.node_distance_mean, 0.01, 1e-15);
  EXPECT_NEAR(a.hausdorff, 0.01, 1e-15);
  EXPECT_EQ(a.normal_deviation_max_deg, 0.0);
  EXPECT_EQ(a.normal_deviation_mean_deg, 0.0);
  EXPECT_EQ(a.flipped_faces, 0);
  EXPECT_NEAR(a.area_ratio, 1.0, 1e-14);
  EXPECT_EQ(measure.inverted, 0);
}

TEST_F(SquarePatch, FlippedFacesAreCountedApartFromTheAngle) {
  const TriangleSurface shifted = square(0.25, 0.75, 0.51, "square");
  const MeshMeasure measure = measure_mesh_file(write_square_mesh("down.msh", false), {&shifted, 1});
  ASSERT_TRUE(measure.interfaces.at(0).accuracy);
  const SurfaceAccuracy& a = *measure.interfaces[0].accuracy;
  EXPECT_EQ(a.flipped_faces, measure.interfaces[0].faces);
  EXPECT_EQ(a.normal_deviation_max_deg, 0.0);
  EXPECT_NEAR(a.hausdorff, 0.01, 1e-15);
}

// S larger than the interface: only the distance from S's side sees it, at S's corners.
TEST_F(SquarePatch, HausdorffDistanceIsTwoSided) {
  const TriangleSurface larger = square(0.2, 0.8, 0.5, "square");
  const MeshMeasure measure = measure_mesh_file(write_square_mesh("up.msh", true), {&larger, 1});
  const SurfaceAccuracy& a = *measure.interfaces.at(0).accuracy;
  EXPECT_EQ(a.node_distance_max, 0.0);
  EXPECT_NEAR(a.hausdorff, 0.05 * std::numbers::sqrt2, 1e-15);
  EXPECT_NEAR(a.area_ratio, 0.25 / 0.36, 1e-14);
}

// The interface with a hole of half-width 1/8 against the whole square: the point of S farthest from the
// interface is the hole's centre, no vertex of either side, but a sample (the midpoint of S's diagonal).
TEST_F(SquarePatch, HausdorffDistanceSamplesInsideTheTriangles) {
  const TriangleSurface whole = square(0.25, 0.75, 0.5, "square");
  const MeshMeasure measure = measure_mesh_file(write_square_mesh("ring.msh", true, true), {&whole, 1});
  const InterfaceMeasure& interface = measure.interfaces.at(0);
  EXPECT_EQ(interface.faces, 24);
  EXPECT_EQ(interface.accuracy->node_distance_max, 0.0);
  EXPECT_EQ(interface.accuracy->hausdorff, 0.125);
  EXPECT_EQ(interface.accuracy->area_ratio, 0.75);
}

TEST_F(SquarePatch, SurfaceWithoutItsGroupIsAnErrorNamingBoth) {
  const std::string mesh = write_square_mesh("up.msh", true);
  TriangleSurface other = square(0.25, 0.75, 0.51, "fault");
  other.source = "fault.obj";
  try {
    measure_mesh_file(mesh, {&other, 1});
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    const std::string message = error.what();
    for (const std::string& part :
         {mesh, std::string("fault.obj"), std::string("interface_fault"), std::string("interface_square")})
      EXPECT_NE(message.find(part), std::string::npos) << message;
  }
  const std::vector<TriangleSurface> twice{square(0.25, 0.75, 0.51, "square"), square(0.2, 0.8, 0.5, "square")};
  EXPECT_THROW(measure_mesh_file(mesh, twice), InputError);
}

// A regular tet (eta 1, every dihedral angle acos(1/3)) beside the unit corner tet written inverted.
TEST_F(SquarePatch, InvertedTetIsCountedAsQualityZero) {
  std::ofstream(path("inverted.msh")) << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                         "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$EndNodes\n"
                                         "$Elements\n2\n1 4 2 1 1 1 3 2 4\n2 4 2 1 1 2 3 4 5\n$EndElements\n";
  const MeshMeasure measure = measure_mesh_file(path("inverted.msh"));
  EXPECT_EQ(measure.tets, 2);
  EXPECT_EQ(measure.inverted, 1);
  EXPECT_EQ(measure.equilateral.min, 0.0);
  EXPECT_NEAR(measure.equilateral.mean, 0.5, 1e-15);
  EXPECT_NEAR(measure.equilateral.std, 0.5, 1e-15);
  EXPECT_EQ(measure.below, (std::array<std::int64_t, 3>{1, 1, 1}));
  const double regular = std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(measure.min_dihedral_deg, regular, 1e-12);
  EXPECT_NEAR(measure.max_dihedral_deg, regular, 1e-12);
  EXPECT_TRUE(measure.interfaces.empty());
}

using testing::run_command;

TEST_F(SquarePatch, CommandWritesTheLibrarysReport) {
  const std::string mesh = write_square_mesh("up.msh", true);
  TriangleSurface shifted = square(0.25, 0.75, 0.51, "square");
  testing::write_obj(path("square.obj"), shifted);
  const std::string measure = std::string(MECCANO_CLI) + " measure " + mesh;
  const auto run = run_command(measure + " --surface " + path("square.obj") + ":square --report " + path("m.json"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("interface_square: 32 faces"), std::string::npos) << run.output;
  shifted.source = path("square.obj");
  const std::string report = file_text(path("m.json"));
  EXPECT_EQ(report, measure_mesh_file(mesh, {&shifted, 1}).json());
  for (const char* key :
       {"\"file\"", "\"nodes\"", "\"tets\"", "\"inverted\": 0", "\"below_0.1\"", "\"below_0.3\"",
        "\"min_dihedral_deg\"", "\"interfaces\"", "\"name\": \"interface_square\"", "\"surface\"", "\"node_distance\"",
        "\"hausdorff\"", "\"normal_deviation_deg\"", "\"flipped_faces\": 0", "\"area_ratio\""})
    EXPECT_NE(report.find(key), std::string::npos) << key << " missing from\n" << report;
  EXPECT_EQ(run_command(measure + " --quiet").output, "");
}

TEST_F(SquarePatch, CommandErrorsNameTheFiles) {
  const std::string mesh = write_square_mesh("up.msh", true);
  testing::write_obj(path("square.obj"), square(0.25, 0.75, 0.51, "square"));
  const std::string measure = std::string(MECCANO_CLI) + " measure ";
  // Without :NAME the surface is named by its position, as in the meshing command.
  const auto unnamed = run_command(measure + mesh + " --surface " + path("square.obj") + " --report " + path("x.json"));
  EXPECT_EQ(unnamed.status, 1);
  for (const std::string& part : {mesh, path("square.obj"), std::string("interface_1")})
    EXPECT_NE(unnamed.output.find(part), std::string::npos) << unnamed.output;
  EXPECT_FALSE(std::filesystem::exists(path("x.json")));
  const auto no_mesh = run_command(measure + path("none.msh"));
  EXPECT_EQ(no_mesh.status, 1);
  EXPECT_NE(no_mesh.output.find("none.msh"), std::string::npos) << no_mesh.output;
  const auto no_surface = run_command(measure + mesh + " --surface " + path("none.obj"));
  EXPECT_EQ(no_surface.status, 1);
  EXPECT_NE(no_surface.output.find("none.obj"), std::string::npos) << no_surface.output;
  EXPECT_EQ(run_command(measure).status, 2);
  EXPECT_EQ(run_command(measure + mesh + " --tolerance 1").status, 2);
  EXPECT_EQ(run_command(measure + mesh + " --surface").status, 2);
  EXPECT_EQ(run_command(std::string(MECCANO_CLI) + " check " + mesh + " --surface " + path("square.obj")).status, 2);
}

}  // namespace
}  // namespace meccano
