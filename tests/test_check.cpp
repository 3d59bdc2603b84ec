// The MSH volume-mesh reader and the invariant checker (`meccano-immerse check`): the module's output
// passes in every MSH encoding and at the inspection stages, Gmsh's meshes (written by the gmsh tool in
// MSH 2.2/4.1, ASCII/binary) pass, and corrupted meshes fail with the right reason; the reader's errors
// name the file, the place and the defect; the command's exit statuses and report.

#include <meccano/error.hpp>
#include <meccano/inspect/mesh_file_check.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/pipeline.hpp>

#include <run_command.hpp>
#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace meccano {
namespace {

namespace fs = std::filesystem;

using testing::CommandRun;
using testing::run_command;

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// The first tet's line in the $Elements section of an ASCII MSH 2.2 file: "tag 4 ntags tags... nodes".
std::string first_tet_line(const std::string& msh22) {
  std::istringstream in(msh22.substr(msh22.find("$Elements\n")));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    long long tag = 0, type = 0;
    if (fields >> tag >> type && type == 4) return line;
  }
  return {};
}

// The text with the line `old_line` (the first occurrence) given its last two fields swapped or its last
// field replaced.
std::string with_line_edited(std::string text, const std::string& old_line, bool swap_last_two,
                             const std::string& last = {}) {
  std::istringstream in(old_line);
  std::vector<std::string> fields{std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
  if (swap_last_two) std::swap(fields[fields.size() - 1], fields[fields.size() - 2]);
  else fields.back() = last;
  std::string line;
  for (const std::string& f : fields) line += (line.empty() ? "" : " ") + f;
  text.replace(text.find(old_line), old_line.size(), line);
  return text;
}

bool mentions(const CheckResult* check, const std::string& text) {
  return check && std::ranges::any_of(check->problems, [&](const std::string& p) { return p.find(text) != p.npos; });
}

// One run of the whole method on a small patch, shared by the tests (written once per encoding).
class Check : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("meccano-check-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    const TriangleSurface patch = [] {
      TriangleSurface s = testing::paper_like_patch(6);
      s.name = "patch";
      return s;
    }();
    for (const Stage stage : {Stage::volumetric, Stage::smoothing}) {
      InsertionOptions options;
      options.resolution = 0.1;
      options.last_stage = stage;
      const InsertionResult result =
          insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&patch, 1}, options);
      const std::string prefix = stage == Stage::smoothing ? "final" : "volumetric";
      const MeshGroups groups = output_groups(result, stage);
      write_msh41(result.mesh, groups, (dir_ / (prefix + "41.msh")).string());
      write_msh22(result.mesh, groups, (dir_ / (prefix + "22.msh")).string());
    }
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static fs::path path(const std::string& name) { return dir_ / name; }
  static MshMesh final_mesh() { return read_msh_mesh(path("final41.msh").string()); }
  static MshGroup& group(MshMesh& mesh, const std::string& name) {
    const auto found = std::ranges::find(mesh.groups, name, &MshGroup::name);
    if (found == mesh.groups.end()) throw std::runtime_error("no group " + name);
    return *found;
  }

  static inline fs::path dir_;
};

TEST_F(Check, TheModulesOutputPassesInBothVersionsAndAtTheInspectionStage) {
  for (const char* name : {"final41.msh", "final22.msh", "volumetric41.msh", "volumetric22.msh"}) {
    const MeshFileCheck check = check_mesh_file(path(name).string());
    EXPECT_TRUE(check.passed()) << check.text();
    for (const char* run : {"conformity", "orientation", "volume", "box sides"}) EXPECT_TRUE(check.find(run)) << run;
    if (std::string(name).starts_with("final")) {
      EXPECT_TRUE(check.find("interface_patch")) << check.text();
    }
  }
  // MSH 2.2 writes a tet of `domain` and `volumetric_patch` twice: read as one element in two groups.
  const MshMesh v41 = read_msh_mesh(path("volumetric41.msh").string());
  const MshMesh v22 = read_msh_mesh(path("volumetric22.msh").string());
  EXPECT_EQ(v22.tets.size(), v41.tets.size());
  ASSERT_EQ(v22.groups.size(), v41.groups.size());
  for (std::size_t g = 0; g < v41.groups.size(); ++g) {
    EXPECT_EQ(v22.groups[g].name, v41.groups[g].name);
    EXPECT_EQ(v22.groups[g].elements.size(), v41.groups[g].elements.size()) << v41.groups[g].name;
  }
}

// A box with an embedded square, meshed by Gmsh itself: another mesher's files, in every encoding.
TEST_F(Check, GmshMeshesPassInEveryEncoding) {
  write_text(path("box.geo"), R"(lc = 0.3;
Point(1)={0,0,0,lc}; Point(2)={1,0,0,lc}; Point(3)={1,1,0,lc}; Point(4)={0,1,0,lc};
Point(5)={0,0,1,lc}; Point(6)={1,0,1,lc}; Point(7)={1,1,1,lc}; Point(8)={0,1,1,lc};
Line(1)={1,2}; Line(2)={2,3}; Line(3)={3,4}; Line(4)={4,1}; Line(5)={5,6}; Line(6)={6,7}; Line(7)={7,8};
Line(8)={8,5}; Line(9)={1,5}; Line(10)={2,6}; Line(11)={3,7}; Line(12)={4,8};
Curve Loop(1)={-4,-3,-2,-1}; Plane Surface(1)={1}; Curve Loop(2)={5,6,7,8}; Plane Surface(2)={2};
Curve Loop(3)={1,10,-5,-9}; Plane Surface(3)={3}; Curve Loop(4)={3,12,-7,-11}; Plane Surface(4)={4};
Curve Loop(5)={9,-8,-12,4}; Plane Surface(5)={5}; Curve Loop(6)={2,11,-6,-10}; Plane Surface(6)={6};
Surface Loop(1)={1,2,3,4,5,6}; Volume(1)={1};
Point(11)={0.25,0.25,0.5,0.1}; Point(12)={0.75,0.25,0.5,0.1}; Point(13)={0.75,0.75,0.5,0.1};
Point(14)={0.25,0.75,0.5,0.1}; Line(21)={11,12}; Line(22)={12,13}; Line(23)={13,14}; Line(24)={14,11};
Curve Loop(21)={21,22,23,24}; Plane Surface(21)={21}; Surface{21} In Volume{1};
Physical Volume("domain")={1}; Physical Surface("xmin")={5}; Physical Surface("xmax")={6};
Physical Surface("ymin")={3}; Physical Surface("ymax")={4}; Physical Surface("zmin")={1};
Physical Surface("zmax")={2}; Physical Surface("interface_square")={21};
)");
  std::set<std::int64_t> tet_counts;
  for (const std::string format : {"msh41", "msh22"})
    for (const std::string binary : {"", " -bin"}) {
      const fs::path out = path("gmsh_" + format + (binary.empty() ? "" : "_bin") + ".msh");
      const CommandRun gmsh = run_command("gmsh " + path("box.geo").string() + " -3 -v 1 -format " + format + binary +
                                          " -o " + out.string());
      ASSERT_EQ(gmsh.status, 0) << gmsh.output;
      const MeshFileCheck check = check_mesh_file(out.string());
      EXPECT_TRUE(check.passed()) << check.text();
      ASSERT_TRUE(check.find("interface_square")) << check.text();
      EXPECT_NE(check.find("box sides")->summary.find("box-side triangles"), std::string::npos);
      tet_counts.insert(check.tets);
    }
  EXPECT_EQ(tet_counts.size(), 1u) << "the four encodings of one mesh read differently";
}

TEST_F(Check, AFlippedTetFailsOrientationAndVolumeNamingIt) {
  MshMesh mesh = final_mesh();
  std::swap(mesh.tets[5][0], mesh.tets[5][1]);
  const MeshFileCheck check = check_msh_mesh(mesh);
  EXPECT_FALSE(check.passed());
  EXPECT_TRUE(
      mentions(check.find("orientation"), "tet " + std::to_string(mesh.tet_tags[5]) + " is negatively oriented"))
      << check.text();
  EXPECT_FALSE(check.find("volume")->passed);
  EXPECT_TRUE(check.find("conformity")->passed) << "the same tet in the other vertex order: faces still match";
}

TEST_F(Check, ARemovedTetLeavesAHole) {
  MshMesh mesh = final_mesh();
  // A tet with no face on the box: its four faces become unshared faces inside the box.
  const auto& p = mesh.points;
  const auto inner = std::ranges::find_if(mesh.tets, [&](const std::array<int, 4>& t) {
    return std::ranges::all_of(t, [&](int v) { return (p[v].array() > 0.0).all() && (p[v].array() < 1.0).all(); });
  });
  ASSERT_NE(inner, mesh.tets.end());
  const auto index = inner - mesh.tets.begin();
  mesh.tets.erase(inner);
  mesh.tet_tags.erase(mesh.tet_tags.begin() + index);
  const MeshFileCheck check = check_msh_mesh(mesh);
  EXPECT_EQ(check.find("conformity")->problem_count, 4) << check.text();
  EXPECT_TRUE(mentions(check.find("conformity"), "(a hole)")) << check.text();
  EXPECT_TRUE(mentions(check.find("volume"), "differs from the bounding box volume")) << check.text();
  EXPECT_TRUE(check.find("orientation")->passed);
}

TEST_F(Check, ADuplicatedTetSharesItsFacesThreeWays) {
  MshMesh mesh = final_mesh();
  mesh.tets.push_back(mesh.tets[0]);
  mesh.tet_tags.push_back(999999);
  const MeshFileCheck check = check_msh_mesh(mesh);
  EXPECT_TRUE(mentions(check.find("conformity"), "tets (")) << check.text();
  EXPECT_TRUE(mentions(check.find("conformity"), "tet 999999")) << check.text();
}

TEST_F(Check, ABoxSideWithAMissingTriangleNoLongerTilesItsSide) {
  MshMesh mesh = final_mesh();
  group(mesh, "zmax").elements.pop_back();
  const MeshFileCheck check = check_msh_mesh(mesh);
  const CheckResult* sides = check.find("box sides");
  EXPECT_TRUE(mentions(sides, "zmax: its triangles' area")) << check.text();
  EXPECT_TRUE(mentions(sides, "is on the boundary of the mesh but in no box-side group")) << check.text();
  EXPECT_TRUE(check.find("conformity")->passed);
}

TEST_F(Check, InterfaceDefectsAreNamed) {
  const MshMesh original = final_mesh();
  // A hole: an interface triangle none of whose edges is on the rim.
  MshMesh holed = original;
  {
    MshGroup& interface = group(holed, "interface_patch");
    std::map<std::pair<int, int>, int> edge_use;
    for (const int e : interface.elements)
      for (int k = 0; k < 3; ++k) {
        const int a = holed.triangles[e][k], b = holed.triangles[e][(k + 1) % 3];
        ++edge_use[std::minmax(a, b)];
      }
    auto inner = [&](int e) {
      for (int k = 0; k < 3; ++k)
        if (edge_use[std::minmax(holed.triangles[e][k], holed.triangles[e][(k + 1) % 3])] != 2) return false;
      return true;
    };
    // Removing a triangle whose vertices are all away from the rim leaves a second boundary loop.
    std::set<int> rim_vertices;
    for (const auto& [edge, uses] : edge_use)
      if (uses == 1) rim_vertices.insert({edge.first, edge.second});
    const auto hole = std::ranges::find_if(interface.elements, [&](int e) {
      return inner(e) && std::ranges::none_of(holed.triangles[e], [&](int v) { return rim_vertices.count(v) > 0; });
    });
    ASSERT_NE(hole, interface.elements.end());
    interface.elements.erase(hole);
  }
  const MeshFileCheck with_hole = check_msh_mesh(holed);
  EXPECT_TRUE(mentions(with_hole.find("interface_patch"), "2 boundary loops")) << with_hole.text();
  EXPECT_TRUE(mentions(with_hole.find("interface_patch"), "Euler characteristic 0")) << with_hole.text();

  // A second component: an interior face of the mesh far from the interface.
  MshMesh two = original;
  {
    MshGroup& interface = group(two, "interface_patch");
    std::set<int> used;
    for (const int e : interface.elements) used.insert(two.triangles[e].begin(), two.triangles[e].end());
    const auto far = std::ranges::find_if(two.tets, [&](const std::array<int, 4>& t) {
      return std::ranges::none_of(t, [&](int v) {
        return used.count(v) > 0 || two.points[v].z() > 0.99 || two.points[v].z() < 0.01 || two.points[v].x() < 0.01 ||
               two.points[v].x() > 0.99 || two.points[v].y() < 0.01 || two.points[v].y() > 0.99;
      });
    });
    ASSERT_NE(far, two.tets.end());
    two.triangles.push_back({(*far)[1], (*far)[2], (*far)[3]});
    two.triangle_tags.push_back(888888);
    interface.elements.push_back(static_cast<int>(two.triangles.size()) - 1);
  }
  const MeshFileCheck with_two = check_msh_mesh(two);
  EXPECT_TRUE(mentions(with_two.find("interface_patch"), "2 connected components")) << with_two.text();
  EXPECT_TRUE(mentions(with_two.find("interface_patch"), "2 boundary loops")) << with_two.text();

  // A flipped triangle: the orientation is no longer consistent.
  MshMesh flipped = original;
  {
    const int e = group(flipped, "interface_patch").elements[3];
    std::swap(flipped.triangles[e][0], flipped.triangles[e][1]);
  }
  const MeshFileCheck with_flip = check_msh_mesh(flipped);
  EXPECT_TRUE(mentions(with_flip.find("interface_patch"), "inconsistent orientation")) << with_flip.text();

  // A tet with all four nodes on the interface: a tet with an interface face, its fourth node swapped for
  // another interface node.
  MshMesh lying = original;
  {
    const std::array<int, 3> face = lying.triangles[group(lying, "interface_patch").elements[0]];
    const std::array<int, 3> other = lying.triangles[group(lying, "interface_patch").elements[1]];
    const int off = *std::ranges::find_if(other, [&](int v) { return std::ranges::find(face, v) == face.end(); });
    const auto tet = std::ranges::find_if(lying.tets, [&](const std::array<int, 4>& t) {
      return std::ranges::all_of(face, [&](int v) { return std::ranges::find(t, v) != t.end(); });
    });
    ASSERT_NE(tet, lying.tets.end());
    for (int& v : *tet)
      if (std::ranges::find(face, v) == face.end()) v = off;
  }
  const CheckResult* lying_check = check_msh_mesh(lying).find("interface_patch");
  EXPECT_NE(lying_check->summary.find(", 1 tets with all four nodes on it"), std::string::npos) << lying_check->summary;
  EXPECT_EQ(check_msh_mesh(original).find("interface_patch")->summary.find("four nodes"), std::string::npos)
      << "the module's mesh has such a tet";

  // A box-side triangle in the interface: not an interior face.
  MshMesh outside = original;
  group(outside, "interface_patch").elements.push_back(group(outside, "xmin").elements[0]);
  const MeshFileCheck with_outside = check_msh_mesh(outside);
  EXPECT_TRUE(mentions(with_outside.find("interface_patch"), "is a face of 1 tets, not an interior face"))
      << with_outside.text();
}

// The reader's errors name the file, where, and the defect.
TEST_F(Check, ReaderErrorsNameTheFileThePlaceAndTheDefect) {
  const std::string good = file_text(path("final22.msh"));
  const std::string nodes_header = "$Nodes\n";
  const std::size_t nodes_at = good.find(nodes_header) + nodes_header.size();
  const std::string elements_at = "$Elements\n";
  struct Case {
    std::string name, text, message;
  };
  const std::string tet_line = first_tet_line(good);
  ASSERT_FALSE(tet_line.empty());
  const std::vector<Case> cases{
      {"empty.msh", "", "empty file"},
      {"version.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", ":2: unsupported MSH version '3.0'"},
      {"not_msh.msh", "solid x\n", ":1: not a Gmsh MSH file: expected '$MeshFormat', found 'solid'"},
      {"absurd.msh", good.substr(0, nodes_at) + "999999999999\n" + good.substr(good.find('\n', nodes_at) + 1),
       "absurd node count 999999999999: cannot fit in the"},
      {"nan.msh", good.substr(0, nodes_at) + "1\n1 nan 0 0\n$EndNodes\n", "node 1 has a non-finite coordinate"},
      {"undefined.msh", with_line_edited(good, tet_line, false, "99999999"), "node 99999999 is not defined in $Nodes"},
      {"truncated.msh", good.substr(0, good.size() / 2), "unexpected end of file"},
      {"no_tets.msh", good.substr(0, good.find(elements_at)) + "$Elements\n0\n$EndElements\n",
       "no tets (element type 4)"},
      {"bad_end.msh", with_line_edited(good, "$EndPhysicalNames", false, "$EndPhysical"),
       "expected '$EndPhysicalNames', found '$EndPhysical'"},
  };
  for (const Case& c : cases) {
    write_text(path(c.name), c.text);
    try {
      read_msh_mesh(path(c.name).string());
      ADD_FAILURE() << c.name << ": no error";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_EQ(message.rfind(path(c.name).string() + ":", 0), 0u) << message;
      EXPECT_NE(message.find(c.message), std::string::npos) << c.name << ": " << message;
    }
  }
  // Binary data: a truncated file names the byte offset.
  const CommandRun gmsh =
      run_command("gmsh " + path("box.geo").string() + " -3 -v 1 -format msh41 -bin -o " + path("binary.msh").string());
  if (gmsh.status == 0) {
    const std::string binary = file_text(path("binary.msh"));
    write_text(path("binary_truncated.msh"), binary.substr(0, binary.size() * 2 / 3));
    EXPECT_THROW(
        {
          try {
            read_msh_mesh(path("binary_truncated.msh").string());
          } catch (const InputError& error) {
            EXPECT_NE(std::string(error.what()).find(": byte "), std::string::npos) << error.what();
            EXPECT_NE(std::string(error.what()).find("truncated binary data"), std::string::npos) << error.what();
            throw;
          }
        },
        InputError);
  }
}

TEST_F(Check, TheCommandExitsZeroOnAPassingMeshOneOnAFailingOrUnreadableOneTwoOnMisuse) {
  const std::string cli = MECCANO_CLI;
  const CommandRun passing =
      run_command(cli + " check " + path("final41.msh").string() + " --report " + path("report.json").string());
  EXPECT_EQ(passing.status, 0) << passing.output;
  for (const char* line : {"conformity: ok", "orientation: ok", "volume: ok", "box sides: ok", "interface_patch: ok"})
    EXPECT_NE(passing.output.find(line), std::string::npos) << line << "\n" << passing.output;
  const std::string report = file_text(path("report.json"));
  for (const char* key : {"\"passed\": true", "\"name\": \"conformity\"", "\"problem_count\": 0", "\"tets\": "})
    EXPECT_NE(report.find(key), std::string::npos) << key << "\n" << report;

  // A tet of the MSH 2.2 file with two nodes swapped: negatively oriented.
  const std::string good = file_text(path("final22.msh"));
  const std::string text = with_line_edited(good, first_tet_line(good), true);
  write_text(path("flipped.msh"), text);
  const CommandRun failing = run_command(cli + " check " + path("flipped.msh").string());
  EXPECT_EQ(failing.status, 1) << failing.output;
  EXPECT_NE(failing.output.find("orientation: FAILED"), std::string::npos) << failing.output;
  EXPECT_NE(failing.output.find("is negatively oriented"), std::string::npos) << failing.output;
  const CommandRun quiet = run_command(cli + " check --quiet " + path("flipped.msh").string());
  EXPECT_EQ(quiet.status, 1);
  EXPECT_EQ(quiet.output, "");

  const CommandRun missing = run_command(cli + " check " + path("none.msh").string());
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("none.msh: cannot open file"), std::string::npos) << missing.output;
  for (const char* misuse : {" check", " check a.msh b.msh", " check a.msh --frobnicate"}) {
    const CommandRun run = run_command(cli + misuse);
    EXPECT_EQ(run.status, 2) << misuse << "\n" << run.output;
    EXPECT_NE(run.output.find("check"), std::string::npos) << run.output;
  }
}

}  // namespace
}  // namespace meccano
