// The meccano-immerse command line: exit statuses, messages, outputs read back by the Gmsh library (MSH,
// Medit) and the tests' VTU reader, and bad input that must fail with its own message and leave no file
// behind.

#include <meccano/geometry/geometry.hpp>
#include <meccano/io/surface_readers.hpp>

#include <run_command.hpp>
#include <scratch_directory.hpp>
#include <test_surfaces.hpp>
#include <vtu_reader.hpp>

#include <gmsh.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace meccano {
namespace {

namespace fs = std::filesystem;

using CliRun = testing::CommandRun;

CliRun run_cli(const std::string& arguments) {
  return testing::run_command(std::string(MECCANO_CLI) + " " + arguments);
}

class CliTest : public testing::ScratchDirectoryTest {
 protected:
  CliTest() : ScratchDirectoryTest("meccano-cli") {}

  std::string write_obj(const std::string& name, const TriangleSurface& surface) const {
    return testing::write_obj(path(name), surface);
  }

  // " --step FILE:fault" for each of `count` steps of the test patch raised by a quarter of l_r = 1/16
  // per step, written as NAME_k.obj.
  std::string patch_steps(const std::string& name, int count) const {
    std::string steps;
    for (int k = 0; k < count; ++k) {
      TriangleSurface patch = testing::paper_like_patch(10);
      for (Eigen::Vector3d& p : patch.points) p.z() += k * 0.0625 / 4;
      steps += " --step " + write_obj(name + "_" + std::to_string(k) + ".obj", patch) + ":fault";
    }
    return steps;
  }

  // The surfaces as one GOCAD TSurf object, a TFACE each, followed by `extra` lines. No coordinate
  // system: the unit cube is not in metres.
  std::string write_tsurf(const std::string& name, const std::vector<TriangleSurface>& surfaces,
                          const std::string& extra = "") const {
    std::ofstream out(path(name));
    out.precision(17);
    out << "GOCAD TSurf 1\nHEADER {\nname:" << name << "\n}\n";
    std::size_t first_id = 1;
    for (const auto& surface : surfaces) {
      out << "TFACE\n";
      for (std::size_t v = 0; v < surface.points.size(); ++v)
        out << "VRTX " << first_id + v << ' ' << surface.points[v].transpose() << '\n';
      for (const auto& t : surface.triangles)
        out << "TRGL " << first_id + t[0] << ' ' << first_id + t[1] << ' ' << first_id + t[2] << '\n';
      first_id += surface.points.size();
    }
    out << extra << "END\n";
    return path(name);
  }

  // The stacked pair of test surfaces as lower.obj and upper.obj.
  std::array<std::string, 2> write_stacked_pair() const {
    const auto pair = testing::stacked_pair(8);
    return {write_obj("lower.obj", pair[0]), write_obj("upper.obj", pair[1])};
  }

  bool only_inputs_in_directory(std::size_t inputs) const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator())) == inputs;
  }
};

std::map<std::string, std::size_t> group_sizes(const std::string& file) {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(file);
  std::map<std::string, std::size_t> sizes;
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int entity : entities) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> tags, nodes;
      gmsh::model::mesh::getElements(types, tags, nodes, dim, entity);
      for (const auto& t : tags) sizes[name] += t.size();
    }
  }
  gmsh::finalize();
  return sizes;
}

TEST_F(CliTest, HelpExitsZeroWithExamples) {
  const CliRun run = run_cli("--help");
  EXPECT_EQ(run.status, 0);
  EXPECT_NE(run.output.find("--box X0,Y0,Z0,X1,Y1,Z1"), std::string::npos);
  EXPECT_NE(run.output.find("Examples:"), std::string::npos);
  for (const char* text :
       {"--msh-version V", ".vtu", ".mesh", "--output fault.vtu", ".ts GOCAD TSurf", "ZPOSITIVE", "--weld-tolerance D",
        "--split-parts", "the tets far from the surfaces", "1.26·h·2^(-K/3)", "A solver's accuracy away from"})
    EXPECT_NE(run.output.find(text), std::string::npos) << text;
}

TEST_F(CliTest, UsageErrorsExitTwoWithAMessage) {
  const std::map<std::string, std::string> cases{
      {"--level 2 --output " + path("a.msh"), "--box is required"},
      {"--box 0,0,0,1,1,1", "--output is required"},
      {"--box 0,0,0,1,1 --output " + path("a.msh"), "takes 6 comma-separated numbers"},
      {"--box 0,0,0,1,x,1 --output " + path("a.msh"), "is not a finite number"},
      {"--box 1,1,1,0,0,0 --output " + path("a.msh"), "--box: on axis x the minimum 1 must be below the maximum 0"},
      {"--box 0,0,0,1,0,1 --output " + path("a.msh"), "--box: on axis y the minimum 0 must be below the maximum 0"},
      {"--box -1e308,0,0,1e308,1,1 --output " + path("a.msh"), "below the maximum 1e+308 by a finite extent"},
      {"--box 0,0,0,1,1,1 --cells 2,0,2 --output " + path("a.msh"), "--cells takes three integers from 1 to 1024"},
      {"--box 0,0,0,1,1,1 --cells 2000,1,1 --output " + path("a.msh"), "--cells takes three integers from 1 to 1024"},
      {"--box 0,0,0,1,1,1 --cells 1e10,1,1 --output " + path("a.msh"), "--cells takes three integers from 1 to 1024"},
      {"--box 0,0,0,1,1,1 --level -1 --output " + path("a.msh"), "--level must be between"},
      {"--box 0,0,0,1,1,1 --frobnicate --output " + path("a.msh"), "unknown option"},
      {"--box 0,0,0,1,1,1 --output " + path("a.vtk"), "unknown format; the extensions are .msh"},
      {"--box 0,0,0,1,1,1 --output " + path("a.msh") + " --output " + path("a.vtk"), "a.vtk: unknown format"},
      {"--box 0,0,0,1,1,1 --msh-version 3 --output " + path("a.msh"), "the versions are 4.1 and 2.2"},
      {"--box 0,0,0,1,1,1 --output " + path("a.msh") + " --msh-version 2.2 --output " + path("a.vtu"),
       "--msh-version applies to the .msh outputs after it, and none follows"},
      {"--box 0,0,0,1,1,1 --surface s.obj --stage volumetric --output " + path("a.msh"),
       "--surface needs --resolution"},
      {"--box 0,0,0,1,1,1 --resolution 0.1 --output " + path("a.msh"), "need at least one --surface"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0 --stage volumetric --output " + path("a.msh"),
       "--resolution must be positive"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --stage refinement --output " + path("a.msh"),
       "the stages available are"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --smoothing sideways --output " + path("a.msh"),
       "the modes are whole and band"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --target cube --output " + path("a.msh"),
       "the targets are meccano and equilateral"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --improve harder --output " + path("a.msh"),
       "--improve harder: the modes are topology, smooth and none"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --improve-threshold 0 --output " + path("a.msh"),
       "--improve-threshold must be above 0 and at most 1"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --improve-first-threshold 2 --output " + path("a.msh"),
       "--improve-first-threshold must be at least 0 and at most 1"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --improve-angles 15 --output " + path("a.msh"),
       "--improve-angles takes 2 comma-separated numbers"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --improve-angles 75,150 --output " + path("a.msh"),
       "--improve-angles takes MIN,MAX in degrees with 0 <= MIN < 70.5 < MAX <= 180"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --side up --output " + path("a.msh"),
       "the rules are positive, negative, positive-only and negative-only"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --threads 0 --output " + path("a.msh"),
       "--threads must be at least 1"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --fallback-sweeps -1 --output " + path("a.msh"),
       "--fallback-sweeps must not be negative"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --drag-rings -1 --output " + path("a.msh"),
       "--drag-rings must not be negative"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --finer-retries -2 --output " + path("a.msh"),
       "--finer-retries must not be negative"},
      {"--box 0,0,0,1,1,1 --histograms h.csv --output " + path("a.msh"), "need at least one --surface"},
      {"--box 0,0,0,1,1,1 --surface s.ts --resolution 0.1 --weld-tolerance -1 --output " + path("a.msh"),
       "--weld-tolerance must not be negative"},
      {"--box 0,0,0,1,1,1 --surface s.ts --resolution 0.1 --weld-tolerance x --output " + path("a.msh"),
       "--weld-tolerance: 'x' is not a finite number"},
      {"--box 0,0,0,1,1,1 --split-parts --output " + path("a.msh"),
       "--split-parts and --snap-to-box need at least one --surface"},
      {"--box 0,0,0,1,1,1 --snap-to-box 10 --output " + path("a.msh"), "--snap-to-box need at least one --surface"},
      {"--box 0,0,0,1,1,1 --snap-to-box -1 --surface s.obj --resolution 0.1 --output " + path("a.msh"),
       "--snap-to-box must not be negative"},
      {"--box 0,0,0,1,1,1 --surface s.obj --resolution 0.1 --stage projection --histograms h.csv --output " +
           path("a.msh"),
       "needs --stage smoothing"},
  };
  for (const auto& [arguments, message] : cases) {
    const CliRun run = run_cli(arguments);
    EXPECT_EQ(run.status, 2) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << arguments << "\n" << run.output;
  }
  EXPECT_TRUE(only_inputs_in_directory(0));
}

TEST_F(CliTest, WritesTheMeccanoMeshWithBoxGroups) {
  const CliRun run = run_cli("--box 0,0,0,2,1,1 --level 4 --quiet --output " + path("bar.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(run.output.empty()) << "--quiet printed: " << run.output;
  const auto sizes = group_sizes(path("bar.msh"));
  EXPECT_EQ(sizes.at("domain"), 2u * 6 * 16);
  for (const char* side : {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}) EXPECT_GT(sizes.at(side), 0u) << side;
}

TEST_F(CliTest, ProgressReportsEachStageWithCounts) {
  const std::string surface = write_obj("patch.obj", testing::paper_like_patch(8));
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + surface +
                             ":patch --resolution 0.1 --stage volumetric --output " + path("vm.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("surface patch:"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("volumetric patch:"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("wrote"), std::string::npos) << run.output;
}

// SUS can run for minutes after the projection's line: every sweep says how far it got, and --quiet
// silences these lines with the others.
TEST_F(CliTest, EverySmoothingSweepHasAProgressLine) {
  const std::string surface = write_obj("patch.obj", testing::paper_like_patch(8));
  const std::string arguments =
      "--box 0,0,0,1,1,1 --surface " + surface + " --resolution 0.1 --output " + path("mesh.msh");
  const CliRun run = run_cli(arguments);
  ASSERT_EQ(run.status, 0) << run.output;
  // The stage's line counts the sweeps: "smoothing: ... inverted tets before, M after N sweeps (...".
  const std::size_t summary = run.output.find("smoothing: ");
  ASSERT_NE(summary, std::string::npos) << run.output;
  const int sweeps = std::stoi(run.output.substr(run.output.find(" after ", summary) + 7));
  ASSERT_GT(sweeps, 0) << run.output;
  for (int sweep = 1; sweep <= sweeps; ++sweep)
    EXPECT_NE(run.output.find("smoothing sweep " + std::to_string(sweep) + ": "), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("smoothing sweep " + std::to_string(sweeps + 1) + ": "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(" tets inverted, quality min "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("improvement: "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(" rounds of flips: "), std::string::npos) << "topology is the default\n" << run.output;
  EXPECT_NE(run.output.find("improvement shape pass 1: "), std::string::npos) << "angle floors are the default\n"
                                                                              << run.output;

  const CliRun quiet = run_cli(arguments + " --quiet");
  ASSERT_EQ(quiet.status, 0) << quiet.output;
  EXPECT_TRUE(quiet.output.empty()) << "--quiet printed: " << quiet.output;
}

// --improve-angles sets the shape passes' floors; 0,180 turns them off.
TEST_F(CliTest, ImproveAnglesSetsTheShapePassesFloors) {
  const std::string surface = write_obj("patch.obj", testing::paper_like_patch(8));
  auto shape_passes = [&](const std::string& angles) {
    const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + surface + " --resolution 0.1 --improve smooth " +
                               angles + " --quiet --output " + path("mesh.msh") + " --report " + path("r.json"));
    EXPECT_EQ(run.status, 0) << run.output;
    std::ifstream file(path("r.json"));
    const std::string report((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    const std::size_t at = report.find("\"shape_passes\": ");
    return at == std::string::npos ? -1 : std::stoi(report.substr(at + 16));
  };
  EXPECT_EQ(shape_passes("--improve-angles 0,180"), 0);
  EXPECT_GT(shape_passes("--improve-angles 20,140"), 0);
}

TEST_F(CliTest, VolumetricStageWritesOneGroupPerSurface) {
  const auto [lower, upper] = write_stacked_pair();
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + lower + " --surface " + upper +
                             ":top --resolution 0.08 --stage volumetric --quiet --output " + path("vm.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  const auto sizes = group_sizes(path("vm.msh"));
  ASSERT_TRUE(sizes.count("volumetric_1")) << "the first surface is named by its position";
  ASSERT_TRUE(sizes.count("volumetric_top"));
  EXPECT_GT(sizes.at("volumetric_1"), 0u);
  EXPECT_GT(sizes.at("volumetric_top"), 0u);
  EXPECT_LT(sizes.at("volumetric_1"), sizes.at("domain"));
}

TEST_F(CliTest, ApproximationStageWritesOneInterfaceGroupPerSurface) {
  const auto [lower, upper] = write_stacked_pair();
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + lower + ":bottom --surface " + upper +
                             ":top --resolution 0.06 --stage approximation --output " + path("sm.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("approximation bottom: side"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("approximation top: side"), std::string::npos) << run.output;
  const auto sizes = group_sizes(path("sm.msh"));
  for (const char* name : {"interface_bottom", "interface_top", "volumetric_bottom", "volumetric_top", "domain"})
    EXPECT_GT(sizes.count(name) ? sizes.at(name) : 0u, 0u) << name;
}

TEST_F(CliTest, TheSideRuleChoosesWhereSMIsBuilt) {
  const std::string surface = write_obj("patch.obj", testing::paper_like_patch(8));
  for (const auto& [rule, side] : {std::pair{"negative-only", "side -"}, std::pair{"positive", "side +"}}) {
    const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + surface + ":patch --resolution 0.1 --side " + rule +
                               " --stage approximation --output " + path("sm.msh"));
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find(std::string("approximation patch: ") + side), std::string::npos) << rule << run.output;
  }
}

TEST_F(CliTest, ProjectionStageWritesTheInterfaceOnTheSurface) {
  const TriangleSurface patch = testing::paper_like_patch(12);
  const std::string file = write_obj("patch.obj", patch);
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + file + " --resolution 0.07 --stage projection --output " +
                             path("projected.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("projection 1:"), std::string::npos) << run.output;
  // Every node of the interface group, read back by Gmsh, lies on the surface.
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(path("projected.msh"));
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 2);
  std::size_t checked = 0;
  const TriangleBVH tree(patch);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    if (name != "interface_1") continue;
    std::vector<std::size_t> nodes;
    std::vector<double> coords;
    gmsh::model::mesh::getNodesForPhysicalGroup(dim, tag, nodes, coords);
    for (std::size_t i = 0; i < nodes.size(); ++i, ++checked) {
      const Eigen::Vector3d x(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
      EXPECT_LT(std::sqrt(tree.closest_point(x).squared_distance), 1e-12);
    }
  }
  gmsh::finalize();
  EXPECT_GT(checked, 0u) << "no interface_1 group";
}

// The whole method: an untangled mesh (every tet read back by Gmsh has positive volume), the report with
// the keys scripts rely on, and the histograms.
TEST_F(CliTest, FullPipelineWritesAnUntangledMeshAReportAndHistograms) {
  const std::string file = write_obj("patch.obj", testing::paper_like_patch(12));
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + file + ":fault --resolution 0.07 --threads 2 --output " +
                             path("mesh.msh") + " --report " + path("report.json") + " --histograms " + path("q.csv"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("smoothing:"), std::string::npos) << run.output;

  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(path("mesh.msh"));
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(node_tags, coords, parametric);
  std::map<std::size_t, Eigen::Vector3d> nodes;
  for (std::size_t i = 0; i < node_tags.size(); ++i)
    nodes[node_tags[i]] = {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]};
  std::vector<std::size_t> element_tags, tets;
  gmsh::model::mesh::getElementsByType(4, element_tags, tets);
  gmsh::finalize();
  ASSERT_FALSE(tets.empty());
  for (std::size_t t = 0; t < tets.size(); t += 4) {
    const Eigen::Vector3d& a = nodes.at(tets[t]);
    ASSERT_GT((nodes.at(tets[t + 1]) - a).dot((nodes.at(tets[t + 2]) - a).cross(nodes.at(tets[t + 3]) - a)), 0.0)
        << "tet " << t / 4 << " is inverted";
  }
  const auto sizes = group_sizes(path("mesh.msh"));
  EXPECT_GT(sizes.count("interface_fault") ? sizes.at("interface_fault") : 0u, 0u);
  EXPECT_EQ(sizes.count("volumetric_fault"), 0u) << "V_M is for the inspection stages only";

  std::ifstream report_file(path("report.json"));
  const std::string report((std::istreambuf_iterator<char>(report_file)), std::istreambuf_iterator<char>());
  for (const char* key : {"\"tets\"",
                          "\"nodes\"",
                          "\"inverted\": 0",
                          "\"before_smoothing\"",
                          "\"after_smoothing\"",
                          "\"meccano\"",
                          "\"equilateral\"",
                          "\"min\"",
                          "\"mean\"",
                          "\"std\"",
                          "\"min_dihedral_deg\"",
                          "\"seconds\"",
                          "\"smoothing\"",
                          "\"total\"",
                          "\"improvement\"",
                          "\"tets_below_threshold_before\"",
                          "\"min_equilateral_quality_after\"",
                          "\"shape_passes\"",
                          "\"tets_outside_floors_before\"",
                          "\"tets_outside_floors_after\"",
                          "\"operations\"",
                          "\"flips_2_3\"",
                          "\"flips_3_2\"",
                          "\"flips_4_4\"",
                          "\"edge_removals\"",
                          "\"surface_edge_flips\"",
                          "\"cap_flips\"",
                          "\"remeshed_tets\""})
    EXPECT_NE(report.find(key), std::string::npos) << key << " missing from\n" << report;
  std::ifstream histogram_file(path("q.csv"));
  std::string header;
  std::getline(histogram_file, header);
  EXPECT_EQ(header, "bin_low,bin_high,before_smoothing_meccano,before_smoothing_equilateral,after_smoothing_meccano,"
                    "after_smoothing_equilateral");
}

// The report says what the improvement aimed at: the thresholds given (the ladder's first stage and the
// last) and the dihedral floors, inside its "improvement" object. The first threshold is close to the last:
// the ladder runs only when a tet is below it, and SUS leaves this coarse mesh above 0.3.
TEST_F(CliTest, ReportRecordsTheImprovementsThresholdsAndFloors) {
  const std::string file = write_obj("patch.obj", testing::paper_like_patch(12));
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + file + " --resolution 0.07 --threads 2 --quiet " +
                             "--improve-threshold 0.42 --improve-first-threshold 0.41 --output " + path("mesh.msh") +
                             " --report " + path("report.json"));
  ASSERT_EQ(run.status, 0) << run.output;
  std::ifstream report_file(path("report.json"));
  const std::string report((std::istreambuf_iterator<char>(report_file)), std::istreambuf_iterator<char>());
  const std::size_t improvement = report.find("\"improvement\": {");
  ASSERT_NE(improvement, std::string::npos) << report;
  const std::string stage = report.substr(improvement, report.find('}', improvement) - improvement);
  for (const char* entry : {"\"threshold\": 0.42,", "\"first_threshold\": 0.41,", "\"min_dihedral_deg\": 15,",
                            "\"max_dihedral_deg\": 150,"})
    EXPECT_NE(stage.find(entry), std::string::npos) << entry << " missing from\n" << stage;
}

// The node tags and coordinates of an MSH file, and its views' data by view name and node tag.
struct MshNodes {
  std::map<std::size_t, Eigen::Vector3d> points;
  std::map<std::string, std::map<std::size_t, double>> views;
};

MshNodes read_nodes_and_views(const std::string& file) {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(file);
  MshNodes read;
  std::vector<std::size_t> tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(tags, coords, parametric);
  for (std::size_t i = 0; i < tags.size(); ++i)
    read.points[tags[i]] = {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]};
  std::vector<int> views;
  gmsh::view::getTags(views);
  for (const int view : views) {
    std::string name, type;
    gmsh::option::getString("View[" + std::to_string(gmsh::view::getIndex(view)) + "].Name", name);
    std::vector<std::size_t> nodes;
    std::vector<std::vector<double>> data;
    double time = 0;
    int components = 0;
    gmsh::view::getModelData(view, 0, type, nodes, data, time, components);
    for (std::size_t i = 0; i < nodes.size(); ++i) read.views[name][nodes[i]] = data[i].at(0);
  }
  gmsh::finalize();
  return read;
}

// --retry-after-quality-loss is accepted and changes nothing for steps that move without a loss.
TEST_F(CliTest, SequenceTakesTheRetryAfterQualityLossFlag) {
  const CliRun run = run_cli("sequence --box 0,0,0,1,1,1 --level 3 --resolution 0.0625" + patch_steps("retry", 2) +
                             " --retry-after-quality-loss --output " + path("retry_{step}.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("step 1: moved"), std::string::npos) << run.output;
}

// A patch raised by a quarter of l_r per step: one file per step, every step checked, and each node's
// previous_node a node of the previous step's file at the same position; the report counts them.
TEST_F(CliTest, SequenceWritesEveryStepWithItsPreviousNodesAndAReport) {
  const std::string steps = patch_steps("patch", 3);
  const CliRun run =
      run_cli("sequence --box 0,0,0,1,1,1 --level 3 --resolution 0.0625" + steps + " --output " +
              path("fault_{step}.msh") + " --output " + path("fault_{step}.vtu") + " --report " + path("steps.json"));
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* line : {"step 0: inserted", "step 1: moved", "step 2: moved"})
    EXPECT_NE(run.output.find(line), std::string::npos) << line << "\n" << run.output;
  std::ifstream report_file(path("steps.json"));
  const std::string report((std::istreambuf_iterator<char>(report_file)), std::istreambuf_iterator<char>());
  for (const char* key : {"\"steps\"", "\"step\": 2", "\"mode\": \"moved\"", "\"seconds\"", "\"tets\"", "\"nodes\"",
                          "\"nodes_unchanged\"", "\"quality\"", "\"min_dihedral_deg\"", "\"insertion\""})
    EXPECT_NE(report.find(key), std::string::npos) << key << " missing from\n" << report;

  MshNodes previous;
  for (int k = 0; k < 3; ++k) {
    const std::string file = path("fault_" + std::to_string(k) + ".msh");
    EXPECT_EQ(run_cli("check " + file + " --quiet").status, 0) << file;
    EXPECT_TRUE(fs::exists(path("fault_" + std::to_string(k) + ".vtu")));
    const MshNodes step = read_nodes_and_views(file);
    ASSERT_EQ(step.views.count("previous_node"), 1u);
    std::size_t unchanged = 0;
    for (const auto& [tag, previous_tag] : step.views.at("previous_node")) {
      if (previous_tag < 0) continue;
      ASSERT_GT(k, 0) << "step 0 has no previous step";
      ++unchanged;
      ASSERT_EQ(previous.points.at(static_cast<std::size_t>(previous_tag)), step.points.at(tag)) << "node " << tag;
    }
    const std::string counted = "\"nodes_unchanged\": " + std::to_string(unchanged);
    EXPECT_NE(report.find(counted), std::string::npos) << "step " << k << ": " << counted;
    previous = step;
  }
}

// A growing inclusion (closed) and a fault through the box top (clipped by the tool at each step) moving
// along the top: both are moved, not inserted anew, and every step's file passes check.
TEST_F(CliTest, SequenceMovesAClosedSurfaceAndOneClippedByTheBox) {
  constexpr double resolution = 0.0625;
  std::string steps;
  for (int k = 0; k < 3; ++k) {
    const double radius = 0.2 + k * 0.003;  // its area grows by less than --max-area-change's 10 %
    const TriangleSurface inclusion = testing::ellipsoid({0.3, 0.5, 0.45}, {radius, radius, radius}, 8);
    TriangleSurface fault = testing::graph_patch([](double, double z) { return 0.72 + 0.05 * z; },
                                                 {0.2 + k * resolution / 4, 0.8 + k * resolution / 4}, {0.3, 1.2}, 12);
    for (Eigen::Vector3d& p : fault.points) p = Eigen::Vector3d(p.z(), p.x(), p.y());  // (y, z, x) -> (x, y, z)
    steps += " --step " + write_obj("inclusion_" + std::to_string(k) + ".obj", inclusion) + ":inclusion," +
             write_obj("fault_" + std::to_string(k) + ".obj", fault) + ":fault";
  }
  const CliRun run = run_cli("sequence --box 0,0,0,1,1,1 --level 3 --resolution " + std::to_string(resolution) + steps +
                             " --output " + path("both_{step}.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* line : {"step 0: inserted", "step 1: moved", "step 2: moved"})
    EXPECT_NE(run.output.find(line), std::string::npos) << line << "\n" << run.output;
  for (int k = 0; k < 3; ++k) {
    const CliRun check = run_cli("check " + path("both_" + std::to_string(k) + ".msh"));
    EXPECT_EQ(check.status, 0) << check.output;
    for (const char* group : {"interface_inclusion: ok", "inside_inclusion: ok", "interface_fault: ok"})
      EXPECT_NE(check.output.find(group), std::string::npos) << group << "\n" << check.output;
  }
}

TEST_F(CliTest, SequenceRefusesWhatItCannotDoAndWritesNothing) {
  const std::string patch = write_obj("patch.obj", testing::paper_like_patch(10));
  const std::string start = "sequence --box 0,0,0,1,1,1 --level 3 --resolution 0.0625 ";
  const std::map<std::string, std::string> usage{
      {start + "--output " + path("a.msh"), "sequence needs at least one --step"},
      {start + "--step " + patch + " --output " + path("a.msh"), "must hold {step}"},
      {start + "--step " + patch + " --output " + path("a_{step}.mesh"), "a Medit file holds no node data"},
      {start + "--step " + patch + ":a --step " + patch + ":b --output " + path("a_{step}.msh"),
       "every step names the same surfaces in the same order"},
      {start + "--step " + patch + ", --output " + path("a_{step}.msh"), "an empty surface between commas"},
      {start + "--step " + patch + " --stage volumetric --output " + path("a_{step}.msh"), "--stage and --histograms"},
      {start + "--step " + patch + " --max-move -0.5 --output " + path("a_{step}.msh"),
       "--max-move must not be negative"},
      {start + "--step " + patch + " --max-quality-loss x --output " + path("a_{step}.msh"),
       "--max-quality-loss: 'x' is not a finite number"},
      {start + "--step " + patch + " --max-area-change -0.1 --output " + path("a_{step}.msh"),
       "--max-area-change must not be negative"},
  };
  for (const auto& [arguments, message] : usage) {
    const CliRun run = run_cli(arguments);
    EXPECT_EQ(run.status, 2) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << arguments << "\n" << run.output;
  }
  // A bad file in a later step fails the run before any meshing, naming the step; nothing is written.
  const CliRun missing =
      run_cli(start + "--step " + patch + " --step " + path("none.obj") + " --output " + path("a_{step}.msh"));
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_NE(missing.output.find("step 1: "), std::string::npos) << missing.output;
  EXPECT_EQ(missing.output.find("meccano: 48 tets, "), std::string::npos) << "meshed before reading every step";
  EXPECT_TRUE(only_inputs_in_directory(1));
}

// An insertion that fails after its retries (one sweep cannot untangle the projected patch, on either
// side, at l_r and at l_r / 2) lists each attempt on one line, with its l_r and side rule, and says once
// what the failure means and what may mend it.
TEST_F(CliTest, AFailureAfterRetriesListsEachAttemptOnOneLine) {
  const std::string surface = write_obj("patch.obj", testing::paper_like_patch(8));
  // --improve smooth: no untangling flips, which would untangle some attempts.
  const CliRun run =
      run_cli("--box 0,0,0,1,1,1 --surface " + surface + " --resolution 0.1 --max-sweeps 1 " +
              "--fallback-sweeps 0 --finer-retries 1 --improve smooth --quiet --output " + path("mesh.msh"));
  EXPECT_EQ(run.status, 1) << run.output;
  std::vector<std::string> lines;
  std::istringstream text(run.output);
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 6u) << run.output;
  EXPECT_EQ(lines[0], "meccano-immerse: error: the insertion failed (4 attempts):");
  const std::array<const char*, 4> settings{"l_r = 0.1, side positive", "l_r = 0.1, side negative-only",
                                            "l_r = 0.05, side positive", "l_r = 0.05, side negative-only"};
  for (std::size_t k = 0; k < settings.size(); ++k) {
    const std::string& line = lines[k + 1];
    EXPECT_TRUE(line.starts_with("  attempt " + std::to_string(k + 1) + " (" + settings[k] + "): ")) << line;
    EXPECT_TRUE(line.ends_with(" tets are still inverted after 1 sweeps")) << line;
  }
  EXPECT_EQ(lines[5], "smoothing could not untangle the mesh; more finer retries (--finer-retries, "
                      "InsertionOptions::finer_retries; 1 here) may succeed");

  // A flat patch below it that projection leaves untangled: only the first patch changes sides and is
  // retried finer, and the settings name each surface's.
  const std::string flat =
      write_obj("flat.obj", testing::graph_patch([](double, double) { return 0.2; }, {0.3, 0.7}, {0.3, 0.7}, 4));
  const CliRun two =
      run_cli("--box 0,0,0,1,1,1 --surface " + surface + ":patch --surface " + flat +
              ":flat --resolution 0.1 --max-sweeps 1 --fallback-sweeps 0 --finer-retries 1 --improve smooth " +
              "--quiet --output " + path("mesh.msh"));
  EXPECT_EQ(two.status, 1) << two.output;
  for (const char* line : {"\n  attempt 1 (l_r = 0.1, side positive): ",
                           "\n  attempt 2 (l_r = 0.1, side patch negative-only, flat positive): ",
                           "\n  attempt 3 (l_r = patch 0.05, flat 0.1, side positive): ",
                           "\n  attempt 4 (l_r = patch 0.05, flat 0.1, side patch negative-only, flat positive): "})
    EXPECT_NE(two.output.find(line), std::string::npos) << line << "\n" << two.output;
  EXPECT_TRUE(only_inputs_in_directory(2));
}

TEST_F(CliTest, BadSurfacesFailWithTheirOwnMessageAndWriteNothing) {
  const TriangleSurface patch = testing::paper_like_patch(6);
  // A surface that crosses the box is clipped to it; one wholly outside has nothing to insert, and one
  // whose rim touches the box at a point cannot be followed there.
  TriangleSurface outside = patch;
  for (Eigen::Vector3d& p : outside.points) p.z() += 1.5;
  TriangleSurface on_boundary = patch;
  on_boundary.points[0].x() = 0.0;
  TriangleSurface flipped = patch;
  std::swap(flipped.triangles[3][0], flipped.triangles[3][1]);
  const std::map<std::string, std::pair<TriangleSurface, std::string>> cases{
      {"outside.obj", {outside, "no part of the surface lies inside the box"}},
      {"boundary.obj", {on_boundary, "on the box boundary"}},
      {"flipped.obj", {flipped, "orientation"}},
  };
  for (const auto& [name, surface_and_message] : cases) {
    const std::string file = write_obj(name, surface_and_message.first);
    const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + file +
                               " --resolution 0.1 --stage volumetric --output " + path("out.msh"));
    EXPECT_EQ(run.status, 1) << name << "\n" << run.output;
    EXPECT_NE(run.output.find(name), std::string::npos) << "the message names the file\n" << run.output;
    EXPECT_NE(run.output.find(surface_and_message.second), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(path("out.msh")));
  }
  // The tilted plane crosses the patch.
  const std::string file = write_obj("patch.obj", patch);
  const std::string crossing = write_obj("plane.obj", testing::tilted_plane(6));
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --surface " + file + " --surface " + crossing +
                             " --resolution 0.1 "
                             "--stage volumetric --output " +
                             path("out.msh"));
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_NE(run.output.find("intersect"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(path("out.msh")));
  const CliRun missing = run_cli("--box 0,0,0,1,1,1 --surface " + path("none.obj") +
                                 " --resolution 0.1 --stage volumetric "
                                 "--output " +
                                 path("out.msh"));
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("none.obj"), std::string::npos) << missing.output;
  EXPECT_TRUE(only_inputs_in_directory(5));
}

// A real fault (UTM metres) in a box 10 % of its largest extent larger on every side, at l_r = that
// extent / 20.
TEST_F(CliTest, TsurfFaultAtTheVolumetricStage) {
  const fs::path fault = fs::path(MECCANO_FAULTS_DIR) / "PNRA-CRSF-YUHA-Shell_Beds_fault-CFM5_1000m.ts";
  if (!fs::exists(fault)) GTEST_SKIP() << "no fault data at " << fault << " (shared/data/faults beside the checkout)";
  const TriangleSurface surface = read_surface(fault.string());
  Eigen::Vector3d lo = surface.points[0], hi = surface.points[0];
  for (const auto& p : surface.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = (hi - lo).maxCoeff();
  lo.array() -= 0.1 * extent;
  hi.array() += 0.1 * extent;
  std::ostringstream box;
  box.precision(17);
  box << lo.x() << ',' << lo.y() << ',' << lo.z() << ',' << hi.x() << ',' << hi.y() << ',' << hi.z();
  const CliRun run = run_cli("--box " + box.str() + " --surface " + fault.string() + ":shell_beds --resolution " +
                             std::to_string(extent / 20) + " --stage volumetric --output " + path("fault.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("surface shell_beds: " + fault.string() + ", 317 triangles, 182 points\n"),
            std::string::npos)
      << run.output;
  const auto sizes = group_sizes(path("fault.msh"));
  ASSERT_TRUE(sizes.count("volumetric_shell_beds")) << run.output;
  EXPECT_GT(sizes.at("volumetric_shell_beds"), 0u);
  EXPECT_LT(sizes.at("volumetric_shell_beds"), sizes.at("domain"));
}

// One TSurf file holding both surfaces of the stacked pair, in two TFACEs that share no edge.
TEST_F(CliTest, SplitPartsInsertsEachPartOfATsurfAsItsOwnSurface) {
  const std::string file = write_tsurf("pair.ts", testing::stacked_pair(8));
  const std::string arguments = "--box 0,0,0,1,1,1 --surface " + file + ":pair --resolution 0.1 --stage approximation ";
  const CliRun refused = run_cli(arguments + "--output " + path("sm.msh"));
  EXPECT_EQ(refused.status, 1) << refused.output;
  for (const char* text : {"pair.ts: 2 parts", "part 1, 128 triangles in TFACE 1 (line 5) of object 'pair.ts'",
                           "part 2, 128 triangles in TFACE 2 (line 215) of object 'pair.ts'", "--split-parts"})
    EXPECT_NE(refused.output.find(text), std::string::npos) << text << "\n" << refused.output;
  EXPECT_FALSE(fs::exists(path("sm.msh")));

  const CliRun run = run_cli(arguments + "--split-parts --output " + path("sm.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* text : {"surface pair: ", "pair.ts, 2 parts\n", "surface pair_1: part 1 of ",
                           "surface pair_2: part 2 of ", "approximation pair_1: side", "approximation pair_2: side"})
    EXPECT_NE(run.output.find(text), std::string::npos) << text << "\n" << run.output;
  const auto sizes = group_sizes(path("sm.msh"));
  for (const char* name : {"interface_pair_1", "interface_pair_2"})
    EXPECT_GT(sizes.count(name) ? sizes.at(name) : 0u, 0u) << name;
  EXPECT_EQ(sizes.count("interface_pair"), 0u);
}

// A vertex 1e-7 from another (the default TSurf weld of an unknown unit: 1e-6 of the diagonal) in a
// copy of the first triangle, and a triangle with a repeated vertex: the progress line counts them,
// and the surface is valid once they are dropped. --weld-tolerance 0 keeps the copy, which the
// validation refuses.
TEST_F(CliTest, TsurfWeldingIsCountedInTheProgressLine) {
  const TriangleSurface patch = testing::paper_like_patch(6);
  const Eigen::Vector3d near =
      patch.points[static_cast<std::size_t>(patch.triangles[0][0])] + Eigen::Vector3d(1e-7, 0, 0);
  std::ostringstream extra;
  extra.precision(17);
  extra << "VRTX 1000 " << near.transpose() << "\nTRGL 1000 " << patch.triangles[0][1] + 1 << ' '
        << patch.triangles[0][2] + 1 << "\nTRGL 1 1 2\n";
  const std::string file = write_tsurf("patch.ts", {patch}, extra.str());
  const std::string arguments = "--box 0,0,0,1,1,1 --surface " + file + ":patch --resolution 0.1 --stage volumetric ";
  const CliRun run = run_cli(arguments + "--output " + path("vm.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find(", 72 triangles, 49 points, 1 vertex welded, 1 degenerate triangle dropped, 1 duplicate "
                            "triangle dropped\n"),
            std::string::npos)
      << run.output;
  const CliRun unwelded = run_cli(arguments + "--weld-tolerance 0 --output " + path("vm.msh"));
  EXPECT_EQ(unwelded.status, 1) << unwelded.output;
  EXPECT_NE(unwelded.output.find(", 73 triangles, 50 points, 1 degenerate triangle dropped\n"), std::string::npos)
      << unwelded.output;
  EXPECT_NE(unwelded.output.find("patch.ts: non-manifold edge"), std::string::npos) << unwelded.output;
}

std::string file_text(const std::string& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Triangles per Medit reference, as Gmsh reads them (one entity per reference).
std::map<int, std::size_t> medit_triangles_per_reference(const std::string& file) {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(file);
  std::map<int, std::size_t> counts;
  gmsh::vectorpair surfaces;
  gmsh::model::getEntities(surfaces, 2);
  for (const auto& [dim, tag] : surfaces) {
    std::vector<std::size_t> elements, nodes;
    gmsh::model::mesh::getElementsByType(2, elements, nodes, tag);
    counts[tag] = elements.size();
  }
  gmsh::finalize();
  return counts;
}

// Every format from one run of the whole method: the same groups with the same counts in each.
TEST_F(CliTest, WritesEveryFormatInOneRunWithBothInterfaces) {
  const auto [lower, upper] = write_stacked_pair();
  const CliRun run =
      run_cli("--box 0,0,0,1,1,1 --surface " + lower + ":bottom --surface " + upper +
              ":top --resolution 0.1 --quiet --output " + path("new.msh") + " --msh-version 2.2" + " --output " +
              path("old.msh") + " --output " + path("mesh.vtu") + " --output " + path("mesh.mesh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(file_text(path("new.msh")).rfind("$MeshFormat\n4.1 0 8\n", 0), 0u);
  EXPECT_EQ(file_text(path("old.msh")).rfind("$MeshFormat\n2.2 0 8\n", 0), 0u);
  const auto sizes = group_sizes(path("new.msh"));
  EXPECT_EQ(group_sizes(path("old.msh")), sizes);
  for (const char* name : {"interface_bottom", "interface_top"})
    ASSERT_GT(sizes.count(name) ? sizes.at(name) : 0u, 0u) << name;

  const testing::VtuFile vtu = testing::read_vtu(path("mesh.vtu"));
  std::map<std::pair<int, int>, std::size_t> cells_of_group;  // (tag, dimension): tags are per dimension
  const auto& types = vtu.arrays.at("types");
  for (std::size_t c = 0; c < types.size(); ++c)
    ++cells_of_group[{static_cast<int>(vtu.arrays.at("group")[c]), types[c] == 10 ? 3 : 2}];
  ASSERT_EQ(vtu.field.size(), sizes.size());
  for (const auto& [name, tag_and_dimension] : vtu.field)
    EXPECT_EQ((cells_of_group[{static_cast<int>(tag_and_dimension.at(0)), static_cast<int>(tag_and_dimension.at(1))}]),
              sizes.at(name))
        << name;

  // Box sides are references 1..6, the interfaces 7 and 8, in the order of the surfaces.
  const std::string medit = file_text(path("mesh.mesh"));
  EXPECT_NE(medit.find("\n# Triangles ref 7 interface_bottom\n"), std::string::npos) << medit.substr(0, 400);
  EXPECT_NE(medit.find("\n# Triangles ref 8 interface_top\n"), std::string::npos) << medit.substr(0, 400);
  const auto triangles = medit_triangles_per_reference(path("mesh.mesh"));
  EXPECT_EQ(triangles.at(7), sizes.at("interface_bottom"));
  EXPECT_EQ(triangles.at(8), sizes.at("interface_top"));
  EXPECT_EQ(triangles.at(1), sizes.at("xmin"));
}

// A run whose writes fail past 40 blocks of 512 bytes, as on a full disk: a failure that no check before
// the run can foresee. At level 6 the .msh and .mesh files take about 10 KB, the .vtu file 39 KB.
// SIGXFSZ ignored: write() fails instead.
CliRun run_cli_on_a_small_disk(const std::string& arguments) {
  return testing::run_command("trap '' XFSZ; ulimit -f 40; exec " + std::string(MECCANO_CLI) + " " + arguments);
}

TEST_F(CliTest, AFailedWriteRemovesTheFilesTheRunWrote) {
  const CliRun run = run_cli_on_a_small_disk("--box 0,0,0,1,1,1 --level 6 --output " + path("a.msh") + " --output " +
                                             path("a.mesh") + " --output " + path("a.vtu"));
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_NE(run.output.find("cannot write " + path("a.vtu") + ": File too large"), std::string::npos) << run.output;
  EXPECT_TRUE(only_inputs_in_directory(0));
}

TEST_F(CliTest, AFailedWriteLeavesAFileThatWasThereAsItWas) {
  const std::string earlier = path("a.msh");
  std::ofstream(earlier) << "an earlier result\n";
  const CliRun run =
      run_cli_on_a_small_disk("--box 0,0,0,1,1,1 --level 6 --output " + earlier + " --output " + path("a.vtu"));
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_NE(run.output.find("cannot write " + path("a.vtu") + ": File too large"), std::string::npos) << run.output;
  std::ifstream in(earlier);
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(content, "an earlier result\n");
  EXPECT_TRUE(only_inputs_in_directory(1));
}

TEST_F(CliTest, UnwritableOutputFailsWithStatusOne) {
  const CliRun run = run_cli("--box 0,0,0,1,1,1 --level 1 --output /nonexistent-dir/out.msh");
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_NE(run.output.find("cannot write /nonexistent-dir/out.msh"), std::string::npos) << run.output;
}

// --drag-rings N: the nodes near S_M follow it before SUS, which the progress and the report say; without
// it the report has no "drag".
TEST_F(CliTest, DragRingsAreReportedWhenAsked) {
  const std::string file = write_obj("patch.obj", testing::paper_like_patch(12));
  const std::string meshing = "--box 0,0,0,1,1,1 --surface " + file + " --resolution 0.07 --output " + path("mesh.msh");
  const CliRun dragged = run_cli(meshing + " --drag-rings 3 --report " + path("dragged.json"));
  ASSERT_EQ(dragged.status, 0) << dragged.output;
  EXPECT_NE(dragged.output.find(" rings of the interfaces follow them; "), std::string::npos) << dragged.output;
  std::ifstream dragged_file(path("dragged.json"));
  const std::string report((std::istreambuf_iterator<char>(dragged_file)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("\"drag\": {\n    \"rings\": 3,\n    \"nodes\": "), std::string::npos) << report;

  const CliRun still = run_cli(meshing + " --quiet --report " + path("still.json"));
  ASSERT_EQ(still.status, 0) << still.output;
  std::ifstream still_file(path("still.json"));
  const std::string plain((std::istreambuf_iterator<char>(still_file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(plain.find("\"drag\""), std::string::npos) << plain;
}

// Every path a run writes is checked before any work: one that cannot be written fails at once, naming
// it, before the first progress line, and nothing is written.
TEST_F(CliTest, UnwritablePathsFailBeforeMeshing) {
  const std::string surface = write_obj("patch.obj", testing::paper_like_patch(8));
  ASSERT_EQ(run_cli("--box 0,0,0,1,1,1 --quiet --output " + path("cube.msh")).status, 0);
  fs::create_directory(path("taken.msh"));
  const std::string meshing = "--box 0,0,0,1,1,1 --surface " + surface + " --resolution 0.1 --output " + path("ok.msh");
  const std::map<std::string, std::string> cases{
      {meshing + " --output /nonexistent-dir/out.vtu",
       "cannot write /nonexistent-dir/out.vtu: there is no directory /nonexistent-dir"},
      {meshing + " --report /nonexistent-dir/r.json", "cannot write /nonexistent-dir/r.json: there is no directory"},
      {meshing + " --histograms /nonexistent-dir/h.csv", "cannot write /nonexistent-dir/h.csv: there is no directory"},
      {meshing + " --output " + path("taken.msh"), "cannot write " + path("taken.msh") + ": it is a directory"},
      {"check " + path("cube.msh") + " --report /nonexistent-dir/c.json",
       "cannot write /nonexistent-dir/c.json: there is no directory"},
  };
  for (const auto& [arguments, message] : cases) {
    const CliRun run = run_cli(arguments);
    EXPECT_EQ(run.status, 1) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << arguments << "\n" << run.output;
    for (const char* work : {"meccano:", "surface 1:", "conformity:"})
      EXPECT_EQ(run.output.find(work), std::string::npos) << "work began before the check\n" << run.output;
  }
  EXPECT_TRUE(only_inputs_in_directory(3));
}

}  // namespace
}  // namespace meccano
