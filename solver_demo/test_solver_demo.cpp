// The demo solver: the manufactured solution's formulas against finite differences, the mesh reader
// against the module's own meshes and against broken files, and the two programs end to end: errors
// that shrink with h, the flux balance on another surface, and MPI runs equal to serial ones.

#include "cube_example.hpp"
#include "interface_mesh.hpp"

#include <meccano/cube_meccano.hpp>
#include <meccano/error.hpp>
#include <meccano/mesh_io.hpp>
#include <meccano/pipeline.hpp>
#include <meccano/surface.hpp>

#include <run_command.hpp>
#include <scratch_directory.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <unistd.h>

namespace solver_demo {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

// ---------------------------------------------------------------------------------------------------
// The manufactured solution

// Random points of the box, away from S by more than `gap` in z.
std::vector<Vector3d> points_off_surface(int count, double gap) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(0.05, 0.95);
  std::vector<Vector3d> points;
  while (static_cast<int>(points.size()) < count) {
    const Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    if (std::abs(p.z() - cube_example_height(p.x(), p.y())) > gap) points.push_back(p);
  }
  return points;
}

TEST(ManufacturedSolution, GradientIsTheDerivativeOfTheValue) {
  const double step = 1e-6;
  for (const Vector3d& p : points_off_surface(200, 1e-3)) {
    const Vector3d gradient = manufactured_solution(p).gradient;
    for (int k = 0; k < 3; ++k) {
      const Vector3d e = step * Vector3d::Unit(k);
      const double difference =
          (manufactured_solution(p + e).value - manufactured_solution(p - e).value) / (2.0 * step);
      EXPECT_NEAR(gradient[k], difference, 1e-6 * (1.0 + std::abs(difference))) << "at " << p.transpose();
    }
  }
}

TEST(ManufacturedSolution, RightHandSideIsMinusTheLaplacian) {
  const double step = 1e-4;
  for (const Vector3d& p : points_off_surface(200, 1e-2)) {
    double laplacian = 0.0;
    for (int k = 0; k < 3; ++k) {
      const Vector3d e = step * Vector3d::Unit(k);
      laplacian += (manufactured_solution(p + e).value - 2.0 * manufactured_solution(p).value +
                    manufactured_solution(p - e).value) / (step * step);
    }
    EXPECT_NEAR(manufactured_right_hand_side(p), -laplacian, 1e-4 * (1.0 + std::abs(laplacian))) << "at " << p.transpose();
  }
}

// g_S = ∂u/∂n from below − ∂u/∂n from above, by one-sided differences of u along S's normal; u itself
// is continuous across S.
TEST(ManufacturedSolution, InterfaceSourceIsTheJumpOfTheNormalDerivative) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(0.21, 0.79);
  const double step = 1e-6;
  double largest = 0.0;
  for (int i = 0; i < 200; ++i) {
    const double x = coordinate(random), y = coordinate(random);
    const Vector3d p(x, y, cube_example_height(x, y)), n = cube_example_normal(x, y);
    const double u = manufactured_solution(p).value;
    const double below = (u - manufactured_solution(p - step * n).value) / step;
    const double above = (manufactured_solution(p + step * n).value - u) / step;
    EXPECT_NEAR(manufactured_interface_source(p), below - above, 1e-4) << "at " << p.transpose();
    EXPECT_NEAR(manufactured_solution(p - 1e-9 * n).value, manufactured_solution(p + 1e-9 * n).value, 1e-8);
    largest = std::max(largest, below - above);
  }
  EXPECT_GT(largest, 1.0);  // the kink is there to be resolved
}

// Across the side walls of the column over S's rim the kink term vanishes with two derivatives, so u,
// ∇u and f are continuous there, and there is no flux jump beyond the rim.
TEST(ManufacturedSolution, KinkFadesOutAtTheRim) {
  const double step = 1e-9;
  for (const double t : {0.25, 0.5, 0.75})
    for (const double z : {0.1, 0.47, 0.9}) {
      const double y = 0.2 + 0.6 * t;
      for (const double wall : {0.2, 0.8}) {
        const Vector3d inside(wall + (wall < 0.5 ? step : -step), y, z), outside(wall + (wall < 0.5 ? -step : step), y, z);
        EXPECT_NEAR(manufactured_solution(inside).value, manufactured_solution(outside).value, 1e-8);
        EXPECT_LT((manufactured_solution(inside).gradient - manufactured_solution(outside).gradient).norm(), 1e-7);
        EXPECT_NEAR(manufactured_right_hand_side(inside), manufactured_right_hand_side(outside), 1e-6);
      }
    }
  EXPECT_EQ(manufactured_interface_source({0.2, 0.5, cube_example_height(0.2, 0.5)}), 0.0);
  EXPECT_EQ(manufactured_interface_source({0.1, 0.5, 0.5}), 0.0);
}

TEST(CubeExample, TriangulationIsTheExampleFile) {
  const meccano::TriangleSurface file = meccano::read_surface(std::string(MECCANO_MESHES_DIR) + "/cube_example.obj");
  const meccano::TriangleSurface made = triangulate_cube_example(48);
  ASSERT_EQ(made.points.size(), file.points.size());
  ASSERT_EQ(made.triangles, file.triangles);
  for (std::size_t i = 0; i < made.points.size(); ++i) EXPECT_LT((made.points[i] - file.points[i]).norm(), 1e-12);
  for (const auto& t : made.triangles) {
    const Vector3d normal = (made.points[t[1]] - made.points[t[0]]).cross(made.points[t[2]] - made.points[t[0]]);
    EXPECT_GT(normal.z(), 0.0);
  }
}

// ---------------------------------------------------------------------------------------------------
// Meshes

meccano::InsertionResult insert(const meccano::TriangleSurface& surface, int level, double resolution) {
  meccano::InsertionOptions options;
  options.resolution = resolution;
  return meccano::insert_surfaces(meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, level), std::vector{surface}, options);
}

meccano::TriangleSurface spherical_cap() {
  meccano::TriangleSurface cap = meccano::read_surface(std::string(MECCANO_MESHES_DIR) + "/spherical_cap.obj");
  cap.name = "cap";
  return cap;
}

// Elements by their corners' coordinates, whatever the vertex numbering.
template <std::size_t n>
std::set<std::array<std::array<double, 3>, n>> by_position(const InterfaceMesh& mesh,
                                                           const std::vector<std::array<unsigned int, n>>& elements) {
  std::set<std::array<std::array<double, 3>, n>> result;
  for (const auto& element : elements) {
    std::array<std::array<double, 3>, n> corners;
    for (std::size_t i = 0; i < n; ++i) corners[i] = mesh.points[element[i]];
    std::sort(corners.begin(), corners.end());
    result.insert(corners);
  }
  return result;
}

bool positively_oriented(const InterfaceMesh& mesh) {
  return std::all_of(mesh.tets.begin(), mesh.tets.end(), [&](const auto& t) {
    const auto p = [&](int i) { return Vector3d(mesh.points[t[i]].data()); };
    return (p(1) - p(0)).dot((p(2) - p(0)).cross(p(3) - p(0))) > 0.0;
  });
}

class DemoFiles : public meccano::testing::ScratchDirectoryTest {
 protected:
  DemoFiles() : ScratchDirectoryTest("solver-demo") {}
};

using InterfaceMeshTest = DemoFiles;

// The module's mesh, in process and through its MSH 4.1 and 2.2 files, is the same mesh.
TEST_F(InterfaceMeshTest, FilesHoldTheModulesMesh) {
  const meccano::InsertionResult result = insert(triangulate_cube_example(24), 9, 0.1);
  const InterfaceMesh direct = interface_mesh_from_insertion(result);
  EXPECT_EQ(direct.interface_name, "patch");
  EXPECT_EQ(direct.tets.size(), static_cast<std::size_t>(result.mesh.num_tets()));
  ASSERT_FALSE(direct.interface.empty());
  meccano::write_msh41(result.mesh, meccano::output_groups(result), path("mesh41.msh"));
  meccano::write_msh22(result.mesh, meccano::output_groups(result), path("mesh22.msh"));
  for (const std::string name : {"mesh41.msh", "mesh22.msh"}) {
    const InterfaceMesh read = read_interface_mesh(path(name));
    EXPECT_EQ(read.interface_name, "patch") << name;
    EXPECT_EQ(read.points.size(), direct.points.size()) << name;
    EXPECT_EQ(read.tets.size(), direct.tets.size()) << name;
    EXPECT_EQ(by_position(read, read.tets), by_position(direct, direct.tets)) << name;
    EXPECT_EQ(by_position(read, read.interface), by_position(direct, direct.interface)) << name;
    EXPECT_TRUE(positively_oriented(read)) << name;
  }
  EXPECT_TRUE(positively_oriented(direct));
}

TEST_F(InterfaceMeshTest, CubeExampleSurfaceIsRecognised) {
  const InterfaceMesh patch = interface_mesh_from_insertion(insert(triangulate_cube_example(24), 9, 0.1));
  const SurfaceMatch match = match_cube_example_surface(patch);
  EXPECT_TRUE(match.matches());
  EXPECT_LT(match.max_deviation, 0.25 * match.tolerance);  // nodes on a fine triangulation of S
  const InterfaceMesh cap = interface_mesh_from_insertion(insert(spherical_cap(), 9, 0.1));
  EXPECT_FALSE(match_cube_example_surface(cap).matches());
  const NormalError normals = cube_example_normal_error(patch);
  EXPECT_EQ(normals.per_triangle_deg.size(), patch.interface.size());
  EXPECT_GT(normals.max_deg, 0.0);
  EXPECT_LT(normals.mean_deg, normals.max_deg);
  EXPECT_LT(normals.max_deg, 20.0);
}

void expect_input_error(const std::function<void()>& read, const std::vector<std::string>& parts) {
  try {
    read();
    ADD_FAILURE() << "no error";
  } catch (const meccano::InputError& error) {
    for (const std::string& part : parts) EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
  }
}

TEST_F(InterfaceMeshTest, BadFilesAreRefusedWithTheirDefect) {
  const meccano::InsertionResult result = insert(triangulate_cube_example(24), 9, 0.1);
  meccano::MeshGroups groups = meccano::output_groups(result);
  meccano::write_msh41(result.mesh, groups, path("good.msh"));
  expect_input_error([&] { read_interface_mesh(path("missing.msh")); }, {"missing.msh", "no such file"});
  expect_input_error([&] { read_interface_mesh(path("good.msh"), "fault"); },
                     {"good.msh", "interface_fault", "interface_patch"});

  // A second interface group: the name must be given; a box side as interface: not interior faces.
  meccano::FaceGroup side = *std::find_if(groups.surfaces.begin(), groups.surfaces.end(),
                                          [](const auto& g) { return g.name == "zmin"; });
  side.name = "interface_floor";
  groups.surfaces.push_back(side);
  meccano::write_msh41(result.mesh, groups, path("two.msh"));
  expect_input_error([&] { read_interface_mesh(path("two.msh")); }, {"two.msh", "2 2D physical groups", "--interface"});
  EXPECT_EQ(read_interface_mesh(path("two.msh"), "patch").interface.size(),
            interface_mesh_from_insertion(result).interface.size());
  expect_input_error([&] { read_interface_mesh(path("two.msh"), "floor"); },
                     {"two.msh", "interface_floor", "boundary of the mesh"});

  // Not a mesh at all.
  std::ofstream(path("text.msh")) << "$MeshFormat\nnot a mesh\n";
  expect_input_error([&] { read_interface_mesh(path("text.msh")); }, {"text.msh"});
}

// ---------------------------------------------------------------------------------------------------
// The programs

using Execution = meccano::testing::CommandRun;
using meccano::testing::run_command;

// The number that `prefix` (a regular expression) first comes before in `text`.
double number_after_pattern(const std::string& text, const std::string& prefix) {
  std::smatch match;
  if (!std::regex_search(text, match, std::regex(prefix + "([-+0-9.eE]+)"))) {
    ADD_FAILURE() << "no '" << prefix << "' in:\n" << text;
    return std::nan("");
  }
  return std::stod(match[match.size() - 1]);
}

// The number after `label` at the start of a line of poisson_interface's output.
double value_after(const std::string& output, const std::string& label) {
  return number_after_pattern(output, "(^|\n)" + label + " +");
}

// The value of the first member `key` in a JSON text.
double json_number(const std::string& json, const std::string& key) { return number_after_pattern(json, "\"" + key + "\": "); }

std::vector<std::vector<double>> read_csv(const std::string& file, std::string& header) {
  std::ifstream in(file);
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::stringstream fields(line);
    std::vector<double>& row = rows.emplace_back();
    for (std::string field; std::getline(fields, field, ',');) row.push_back(std::stod(field));
  }
  return rows;
}

using Programs = DemoFiles;

// Two small levels of the study: errors below bounds set from the measured values with some room,
// and shrinking by about the optimal factors for P1 (h halves: L2 by 4, H1 by 2).
TEST_F(Programs, StudyErrorsShrinkWithH) {
  const Execution study = run_command(std::string(SOLVER_DEMO_STUDY) + " --levels 2 --degree 1 --csv " + path("study.csv"));
  ASSERT_EQ(study.status, 0) << study.output;
  std::string header;
  const auto rows = read_csv(path("study.csv"), header);
  EXPECT_EQ(header, "h,tets,dofs,l2_error,h1_error,normal_error_deg,seconds");
  ASSERT_EQ(rows.size(), 2u);
  const std::vector<double>& coarse = rows[0];
  const std::vector<double>& fine = rows[1];
  ASSERT_EQ(coarse.size(), 7u);
  EXPECT_LT(coarse[3], 0.02);  // measured 0.0114
  EXPECT_LT(coarse[4], 0.6);   // measured 0.381
  EXPECT_LT(fine[0], 0.6 * coarse[0]);
  EXPECT_GT(fine[1], 4 * coarse[1]);
  EXPECT_GT(coarse[3] / fine[3], 2.8);  // measured 3.16
  EXPECT_GT(coarse[4] / fine[4], 1.6);  // measured 1.77
  EXPECT_LT(fine[5], coarse[5]);
}

// On the spherical cap (not the cube example's surface) the unit source problem is solved: what S puts
// in leaves through the box sides, to discretisation accuracy (measured: 2.0e-2 with P1, 4.0e-3 with P2;
// on the next level 3.7e-3 and 5.1e-4).
TEST_F(Programs, FluxBalancesOnTheSphericalCap) {
  const meccano::InsertionResult result = insert(spherical_cap(), 12, 0.05);
  meccano::write_msh41(result.mesh, meccano::output_groups(result), path("cap.msh"));
  const double area = interface_area(interface_mesh_from_insertion(result));
  std::vector<double> balance;
  for (const char* degree : {"1", "2"}) {
    const Execution solve = run_command(std::string(SOLVER_DEMO_POISSON) + " --mesh " + path("cap.msh") + " --degree " + degree +
                          " --vtu " + path("cap"));
    ASSERT_EQ(solve.status, 0) << solve.output;
    EXPECT_NE(solve.output.find("not the cube example's"), std::string::npos) << solve.output;
    EXPECT_EQ(solve.output.find("L2 error"), std::string::npos);
    EXPECT_NEAR(value_after(solve.output, "source"), area, 1e-12 * area);  // ∫_S 1
    balance.push_back(value_after(solve.output, "balance     relative difference"));
    EXPECT_GT(value_after(solve.output, "norms       L2"), 0.0);
  }
  EXPECT_LT(balance[0], 0.04);
  EXPECT_LT(balance[1], 0.01);
  EXPECT_LT(balance[1], 0.5 * balance[0]);
  EXPECT_TRUE(fs::exists(path("cap.vtu")));
  EXPECT_TRUE(fs::exists(path("cap_interface.vtu")));
}

// The same mesh on one and on two MPI ranks: the same errors to the solver's tolerance.
TEST_F(Programs, TwoRanksGiveTheSerialErrors) {
  const meccano::InsertionResult result = insert(triangulate_cube_example(24), 12, 0.1);
  meccano::write_msh41(result.mesh, meccano::output_groups(result), path("patch.msh"));
  const std::string solve = std::string(SOLVER_DEMO_POISSON) + " --mesh " + path("patch.msh") + " --degree 2";
  const Execution serial = run_command(solve);
  // Open MPI refuses to run as root (as CI does) unless told; harmless for other users.
  const Execution parallel =
      run_command("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " + std::string(SOLVER_DEMO_MPIEXEC) +
                  " -n 2 --oversubscribe " + solve + " --vtu " + path("mpi"));
  ASSERT_EQ(serial.status, 0) << serial.output;
  ASSERT_EQ(parallel.status, 0) << parallel.output;
  EXPECT_NE(serial.output.find("the manufactured solution"), std::string::npos) << serial.output;
  for (const char* label : {"L2 error", "H1 error", "source", "outflow"}) {
    const double one = value_after(serial.output, label), two = value_after(parallel.output, label);
    EXPECT_NEAR(one, two, 1e-9 * std::abs(one)) << label;
  }
  EXPECT_TRUE(fs::exists(path("mpi.pvtu")));
  EXPECT_TRUE(fs::exists(path("mpi.1.vtu")));
}

// --report holds the numbers the text prints, at full precision (the text has 12 digits).
TEST_F(Programs, ReportHoldsThePrintedNumbers) {
  const meccano::InsertionResult result = insert(triangulate_cube_example(24), 9, 0.1);
  meccano::write_msh41(result.mesh, meccano::output_groups(result), path("patch.msh"));
  const Execution solve =
      run_command(std::string(SOLVER_DEMO_POISSON) + " --mesh " + path("patch.msh") + " --report " + path("run.json"));
  ASSERT_EQ(solve.status, 0) << solve.output;
  std::ifstream file(path("run.json"));
  const std::string report((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  for (const char* part : {"\"manufactured\": true", "\"interface\": \"interface_patch\"", "\"degree\": 1", "\"ranks\": 1",
                           "\"errors\"", "\"flux\"", "\"seconds\""})
    ASSERT_NE(report.find(part), std::string::npos) << part << " missing from\n" << report;
  std::smatch dofs;
  ASSERT_TRUE(std::regex_search(solve.output, dofs, std::regex("P1, ([0-9]+) dofs"))) << solve.output;
  EXPECT_EQ(json_number(report, "dofs"), std::stod(dofs[1]));
  EXPECT_EQ(json_number(report, "cells"), static_cast<double>(result.mesh.num_tets()));
  const std::string errors = report.substr(report.find("\"errors\""));
  const std::string flux = report.substr(report.find("\"flux\""));
  for (const auto& [json, key, label] : {std::tuple{errors, "l2", "L2 error"}, std::tuple{errors, "h1", "H1 error"},
                                         std::tuple{flux, "source", "source"}, std::tuple{flux, "outflow", "outflow"}}) {
    const double printed = value_after(solve.output, label);
    EXPECT_NEAR(json_number(json, key), printed, 1e-11 * std::abs(printed)) << key;
  }
  const std::string seconds = report.substr(report.find("\"seconds\""));
  EXPECT_GE(json_number(seconds, "total"),
            json_number(seconds, "setup") + json_number(seconds, "assembly") + json_number(seconds, "solve"));
}

TEST_F(Programs, BadInputAndUsage) {
  const meccano::InsertionResult result = insert(triangulate_cube_example(24), 9, 0.1);
  meccano::write_msh41(result.mesh, meccano::output_groups(result), path("patch.msh"));
  const std::string poisson = SOLVER_DEMO_POISSON;
  const Execution missing_group = run_command(poisson + " --mesh " + path("patch.msh") + " --interface fault");
  EXPECT_EQ(missing_group.status, 1);
  EXPECT_NE(missing_group.output.find("interface_fault"), std::string::npos) << missing_group.output;
  EXPECT_EQ(run_command(poisson + " --mesh " + path("patch.msh") + " --degree 3").status, 2);
  EXPECT_EQ(run_command(poisson).status, 2);
  EXPECT_EQ(run_command(std::string(SOLVER_DEMO_STUDY) + " --levels 0 --degree 1 --csv x.csv").status, 2);
  EXPECT_EQ(run_command(poisson + " --help").status, 0);
  const Execution unwritable = run_command(std::string(SOLVER_DEMO_STUDY) + " --levels 1 --degree 1 --csv " + path("none/x.csv"));
  EXPECT_EQ(unwritable.status, 1);
  EXPECT_NE(unwritable.output.find("none/x.csv"), std::string::npos) << unwritable.output;
}

}  // namespace
}  // namespace solver_demo
