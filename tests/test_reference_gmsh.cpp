// reference-gmsh (reference/reference_gmsh.cpp): the Gmsh reference mesh, read back with the Gmsh library.
// Checked: orientation and volume of the tets, the interface is the input surface as given and made of
// interior faces, the box sides tile the boundary, the report agrees with the mesh, the size field refines
// near the surface, and the error paths.

#include <meccano/geometry/geometry.hpp>
#include <meccano/inspect/mesh_file_check.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/quality.hpp>

#include <run_command.hpp>
#include <scratch_directory.hpp>
#include <test_surfaces.hpp>

#include <gmsh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace meccano {
namespace {

namespace fs = std::filesystem;

using ToolRun = testing::CommandRun;

ToolRun run_reference_gmsh(const std::string& arguments) {
  return testing::run_command(std::string(MECCANO_REFERENCE_GMSH) + " " + arguments);
}

using Face = std::array<std::size_t, 3>;  // node tags

Face sorted(Face face) {
  std::sort(face.begin(), face.end());
  return face;
}

// The same oriented triangle, rotated so that its smallest vertex comes first.
std::array<int, 3> smallest_first(std::array<int, 3> triangle) {
  std::rotate(triangle.begin(), std::min_element(triangle.begin(), triangle.end()), triangle.end());
  return triangle;
}

// What a MSH file holds, by node tag: the tets of `domain` and the triangles of every 2D group.
struct MshContents {
  std::vector<Eigen::Vector3d> point_of_tag;
  std::vector<std::array<std::size_t, 4>> tets;
  std::map<std::string, std::vector<Face>> triangles_of_group;

  TetPoints points(const std::array<std::size_t, 4>& tet) const {
    return {point_of_tag[tet[0]], point_of_tag[tet[1]], point_of_tag[tet[2]], point_of_tag[tet[3]]};
  }
  double area(const Face& face) const {
    const auto& a = point_of_tag[face[0]];
    return 0.5 * (point_of_tag[face[1]] - a).cross(point_of_tag[face[2]] - a).norm();
  }
  // How many tets have each face.
  std::map<Face, int> tets_of_face() const {
    std::map<Face, int> count;
    for (const auto& t : tets)
      for (int opposite = 0; opposite < 4; ++opposite) {
        Face face{};
        for (int i = 0, k = 0; i < 4; ++i)
          if (i != opposite) face[k++] = t[i];
        ++count[sorted(face)];
      }
    return count;
  }
};

MshContents read_msh(const std::string& path) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(path);
  MshContents contents;
  std::vector<std::size_t> node_tags;
  std::vector<double> coordinates, parametric;
  gmsh::model::mesh::getNodes(node_tags, coordinates, parametric);
  contents.point_of_tag.resize(node_tags.empty() ? 0 : *std::max_element(node_tags.begin(), node_tags.end()) + 1);
  for (std::size_t i = 0; i < node_tags.size(); ++i)
    contents.point_of_tag[node_tags[i]] = {coordinates[3 * i], coordinates[3 * i + 1], coordinates[3 * i + 2]};
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int entity : entities) {
      std::vector<std::size_t> element_tags, element_nodes;
      gmsh::model::mesh::getElementsByType(dim == 3 ? 4 : 2, element_tags, element_nodes, entity);
      if (dim == 3 && name == "domain") {
        for (std::size_t e = 0; e < element_tags.size(); ++e)
          contents.tets.push_back(
              {element_nodes[4 * e], element_nodes[4 * e + 1], element_nodes[4 * e + 2], element_nodes[4 * e + 3]});
      } else if (dim == 2) {
        auto& triangles = contents.triangles_of_group[name];
        for (std::size_t e = 0; e < element_tags.size(); ++e)
          triangles.push_back({element_nodes[3 * e], element_nodes[3 * e + 1], element_nodes[3 * e + 2]});
      }
    }
  }
  gmsh::finalize();
  return contents;
}

// The number after the first `"key": ` in the text (enough for the report's few nested objects).
double number_after(const std::string& text, const std::string& key) {
  const auto at = text.find("\"" + key + "\": ");
  if (at == std::string::npos) return std::nan("");
  return std::stod(text.substr(at + key.size() + 4));
}

// A temporary directory per test, for the runs that check options and failures.
class ReferenceGmshCliTest : public testing::ScratchDirectoryTest {
 protected:
  ReferenceGmshCliTest() : ScratchDirectoryTest("meccano-reference-gmsh") {}

  // The surface as the OBJ file `name`.obj in the directory; returns its path.
  std::string write_obj(const TriangleSurface& surface, const std::string& name) const {
    return testing::write_obj(path(name + ".obj"), surface);
  }
};

// One run on the cube example at --size 0.1, shared by the tests that inspect its output.
class ReferenceGmshCubeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("meccano-reference-gmsh-cube-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    surface_file_ = std::string(MECCANO_MESHES_DIR) + "/cube_example.obj";
    run_ = run_reference_gmsh("--box 0 0 0 1 1 1 --surface " + surface_file_ + ":patch --size 0.1 --quiet --output " +
                              path("cube.msh") + " --report " + path("cube.json"));
    if (run_.status == 0) mesh_ = read_msh(path("cube.msh"));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  void SetUp() override { ASSERT_EQ(run_.status, 0) << run_.output; }

  static std::string path(const std::string& name) { return (dir_ / name).string(); }

  static inline fs::path dir_;
  static inline std::string surface_file_;
  static inline ToolRun run_;
  static inline MshContents mesh_;
};

TEST_F(ReferenceGmshCubeTest, WritesTheGroupsOfMeccanoImmerse) {
  EXPECT_TRUE(run_.output.empty()) << "--quiet printed: " << run_.output;
  std::set<std::string> names;
  for (const auto& [name, triangles] : mesh_.triangles_of_group) names.insert(name);
  EXPECT_EQ(names, (std::set<std::string>{"xmin", "xmax", "ymin", "ymax", "zmin", "zmax", "interface_patch"}));
  EXPECT_GT(mesh_.tets.size(), 1000u) << "no `domain` tets";
}

TEST_F(ReferenceGmshCubeTest, EveryTetIsPositiveAndTheVolumesSumToTheBox) {
  double total = 0.0;
  for (const auto& tet : mesh_.tets) {
    const TetPoints p = mesh_.points(tet);
    const double volume = signed_volume(p[0], p[1], p[2], p[3]);
    ASSERT_GT(volume, 1e-15) << "tet " << tet[0] << ' ' << tet[1] << ' ' << tet[2] << ' ' << tet[3];
    total += volume;
  }
  EXPECT_NEAR(total, 1.0, 1e-9);
}

TEST_F(ReferenceGmshCubeTest, InterfaceIsTheSurfaceAsGivenOnInteriorFaces) {
  const TriangleSurface surface = read_surface(surface_file_);
  const auto& interface = mesh_.triangles_of_group.at("interface_patch");
  const TriangleBVH tree(surface);
  // Each output node is an input vertex (S is kept as is), found by brute force: a few thousand points.
  const auto input_vertex = [&](std::size_t node) {
    const Eigen::Vector3d& x = mesh_.point_of_tag[node];
    int nearest = 0;
    for (int v = 1; v < static_cast<int>(surface.points.size()); ++v)
      if ((surface.points[v] - x).squaredNorm() < (surface.points[nearest] - x).squaredNorm()) nearest = v;
    EXPECT_LE((surface.points[nearest] - x).norm(), 1e-9) << "node " << node << " is not an input vertex";
    return nearest;
  };
  std::set<std::array<int, 3>> input_triangles;
  for (const auto& triangle : surface.triangles) input_triangles.insert(smallest_first(triangle));
  std::set<std::array<int, 3>> matched;
  const auto tets_of_face = mesh_.tets_of_face();
  for (const Face& face : interface) {
    for (std::size_t node : face)
      ASSERT_LE(std::sqrt(tree.closest_point(mesh_.point_of_tag[node]).squared_distance), 1e-9) << "node " << node;
    const auto corners = smallest_first({input_vertex(face[0]), input_vertex(face[1]), input_vertex(face[2])});
    EXPECT_TRUE(input_triangles.count(corners))
        << "an interface triangle is not an input triangle in the input's orientation";
    matched.insert(corners);
    const auto found = tets_of_face.find(sorted(face));
    ASSERT_NE(found, tets_of_face.end()) << "an interface triangle is not a face of any tet";
    EXPECT_EQ(found->second, 2) << "an interface face is interior: shared by exactly two tets";
  }
  EXPECT_EQ(interface.size(), surface.triangles.size());
  EXPECT_EQ(matched.size(), surface.triangles.size()) << "every input triangle appears once";
}

TEST_F(ReferenceGmshCubeTest, BoxSidesTileTheBoundary) {
  const auto tets_of_face = mesh_.tets_of_face();
  std::size_t side_triangles = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int at_max = 0; at_max < 2; ++at_max) {
      const std::string name = std::string(1, "xyz"[axis]) + (at_max ? "max" : "min");
      double area = 0.0;
      for (const Face& face : mesh_.triangles_of_group.at(name)) {
        for (std::size_t node : face) ASSERT_NEAR(mesh_.point_of_tag[node][axis], at_max, 1e-12) << name;
        const Eigen::Vector3d normal = (mesh_.point_of_tag[face[1]] - mesh_.point_of_tag[face[0]])
                                           .cross(mesh_.point_of_tag[face[2]] - mesh_.point_of_tag[face[0]]);
        EXPECT_GT(at_max ? normal[axis] : -normal[axis], 0.0) << name << ": normals point out of the box, as meccano's";
        const auto found = tets_of_face.find(sorted(face));
        ASSERT_NE(found, tets_of_face.end()) << name << ": a triangle is not a face of any tet";
        EXPECT_EQ(found->second, 1) << name << ": a side face belongs to one tet";
        area += mesh_.area(face);
      }
      EXPECT_NEAR(area, 1.0, 1e-9) << name;
      side_triangles += mesh_.triangles_of_group.at(name).size();
    }
  const auto boundary_faces = static_cast<std::size_t>(
      std::count_if(tets_of_face.begin(), tets_of_face.end(), [](const auto& entry) { return entry.second == 1; }));
  EXPECT_EQ(side_triangles, boundary_faces) << "the sides hold every boundary face, each once";
}

TEST_F(ReferenceGmshCubeTest, ReportAgreesWithTheMesh) {
  std::ifstream in(path("cube.json"));
  ASSERT_TRUE(in) << "no report";
  std::stringstream text;
  text << in.rdbuf();
  const std::string report = text.str();
  EXPECT_EQ(number_after(report, "tets"), static_cast<double>(mesh_.tets.size()));
  EXPECT_EQ(number_after(report, "patch"), 4608.0) << "interface triangles";
  EXPECT_GT(number_after(report, "meshing"), 0.0);
  EXPECT_GE(number_after(report, "total"), number_after(report, "meshing"));
  // Quality by the same functions, from the file read back.
  double min_ratio = 1.0, min_dihedral = 180.0;
  for (const auto& tet : mesh_.tets) {
    const TetPoints p = mesh_.points(tet);
    min_ratio = std::min(min_ratio, mean_ratio_equilateral(p));
    for (double angle : dihedral_angles_deg(p)) min_dihedral = std::min(min_dihedral, angle);
  }
  EXPECT_EQ(number_after(report, "inverted"), 0.0);
  EXPECT_NEAR(number_after(report.substr(report.find("\"equilateral\"")), "min"), min_ratio, 1e-12);
  EXPECT_NEAR(number_after(report, "min_dihedral_deg"), min_dihedral, 1e-9);
  EXPECT_GT(min_ratio, 0.2) << "HXT keeps slivers away from the kept surface (peers.md: eta_min about 0.4)";
}

TEST_F(ReferenceGmshCliTest, TwoSurfacesWithTheCommaBoxAndDelaunay) {
  const auto pair = testing::stacked_pair(4);
  std::vector<std::string> files;
  for (const auto& surface : pair) files.push_back(write_obj(surface, surface.name + std::to_string(files.size())));
  const ToolRun run =
      run_reference_gmsh("--box 0,0,0,1,1,1 --surface " + files[0] + " --surface " + files[1] +
                         ":top --size 0.25 --algorithm delaunay --threads 2 --output " + path("pair.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("Delaunay"), std::string::npos) << "progress names the algorithm\n" << run.output;
  const MshContents pair_mesh = read_msh(path("pair.msh"));
  ASSERT_TRUE(pair_mesh.triangles_of_group.count("interface_1")) << "the first surface is named by its position";
  ASSERT_TRUE(pair_mesh.triangles_of_group.count("interface_top"));
  EXPECT_EQ(pair_mesh.triangles_of_group.at("interface_1").size(), pair[0].triangles.size());
  EXPECT_EQ(pair_mesh.triangles_of_group.at("interface_top").size(), pair[1].triangles.size());
}

// A closed surface bounds a volume of its own: the mesh fills the box, inside and out, and passes the
// module's file check with its closed interface and inside group. (HXT in Gmsh 4.8.4 leaves holes next
// to an inclusion on some meshes, which the tool refuses; Delaunay does not.)
TEST_F(ReferenceGmshCliTest, AClosedSurfaceBoundsItsInside) {
  const std::string sphere = write_obj(testing::sphere(8), "sphere");
  const ToolRun run = run_reference_gmsh("--box 0 0 0 1 1 1 --surface " + sphere +
                                         ":ball --size 0.2 --algorithm delaunay --quiet --output " + path("ball.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  const MeshFileCheck check = check_mesh_file(path("ball.msh"));
  EXPECT_TRUE(check.passed()) << check.text();
  ASSERT_NE(check.find("inside_ball"), nullptr);
  EXPECT_EQ(read_msh(path("ball.msh")).triangles_of_group.at("interface_ball").size(),
            testing::sphere(8).triangles.size());
}

// The mean edge length of the tets whose centroid lies between `from` and `to` away from the surface.
double mean_edge_of_tets_between(const MshContents& mesh, const TriangleBVH& surface, double from, double to) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const auto& tet : mesh.tets) {
    const TetPoints p = mesh.points(tet);
    const double distance = std::sqrt(surface.closest_point((p[0] + p[1] + p[2] + p[3]) / 4.0).squared_distance);
    if (distance <= from || distance >= to) continue;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) sum += (p[a] - p[b]).norm() / 6.0;
    ++count;
  }
  EXPECT_GT(count, 100u) << "too few tets between " << from << " and " << to;
  return sum / static_cast<double>(count);
}

// The kept triangles (mean edge 0.044) already make the tets next to S small; the field (0.045 at S,
// growing to --size 0.4 over a distance of 1) must also keep the tets further out smaller. Measured with
// HXT: their mean edge 0.24 without the field, 0.14 with it.
TEST_F(ReferenceGmshCliTest, SizeFieldMakesTheTetsNearTheSurfaceSmaller) {
  const TriangleSurface patch = testing::paper_like_patch(16);
  const std::string base = "--box 0 0 0 1 1 1 --surface " + write_obj(patch, "patch") + " --size 0.4 --quiet";
  const ToolRun plain = run_reference_gmsh(base + " --output " + path("plain.msh") + " --report " + path("plain.json"));
  ASSERT_EQ(plain.status, 0) << plain.output;
  const ToolRun graded = run_reference_gmsh(base + " --size-near-surface 0.045 --size-distance 1 --output " +
                                            path("graded.msh") + " --report " + path("graded.json"));
  ASSERT_EQ(graded.status, 0) << graded.output;

  const TriangleBVH tree(patch);
  const double without_field = mean_edge_of_tets_between(read_msh(path("plain.msh")), tree, 0.1, 0.3);
  const double with_field = mean_edge_of_tets_between(read_msh(path("graded.msh")), tree, 0.1, 0.3);
  EXPECT_LT(with_field, 0.75 * without_field)
      << "tets 0.1 to 0.3 away from S: mean edge " << with_field << " with the field, " << without_field << " without";

  const auto report = [&](const std::string& name) {
    std::ifstream in(path(name));
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  EXPECT_EQ(number_after(report("graded.json"), "size_near_surface"), 0.045);
  EXPECT_EQ(number_after(report("graded.json"), "size_distance"), 1.0);
  EXPECT_NE(report("plain.json").find("\"size_near_surface\": null"), std::string::npos) << report("plain.json");
}

TEST_F(ReferenceGmshCliTest, MissingSurfaceExitsOneAndWritesNothing) {
  const ToolRun run = run_reference_gmsh("--box 0 0 0 1 1 1 --surface " + path("none.obj") + " --size 0.1 --output " +
                                         path("missing.msh") + " --report " + path("missing.json"));
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_NE(run.output.find("none.obj"), std::string::npos) << "the message names the file\n" << run.output;
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().string().find("missing"), std::string::npos) << "left behind: " << entry.path();
}

TEST_F(ReferenceGmshCliTest, UsageErrorsExitTwoWithAMessage) {
  const std::string rest = " --output " + path("usage.msh");
  const std::map<std::string, std::string> cases{
      {"--surface a.obj --size 0.1" + rest, "--box is required"},
      {"--box 0 0 0 1 1 --surface a.obj --size 0.1" + rest, "--box takes 6 numbers"},
      {"--box 0 0 0 1 1 1 --size 0.1" + rest, "--surface is required"},
      {"--box 0 0 0 1 1 1 --surface a.obj --size 0" + rest, "--size must be positive"},
      {"--box 0 0 0 1 1 1 --surface a.obj --size 0.1 --algorithm frontal" + rest, "the algorithms available are"},
      {"--box 0 0 0 1 1 1 --surface a.obj --size 0.1 --size-near-surface 0.05" + rest, "go together"},
      {"--box 0 0 0 1 1 1 --surface a.obj --size 0.1 --size-distance 0.3" + rest, "go together"},
      {"--box 0 0 0 1 1 1 --surface a.obj --size 0.1 --size-near-surface 0.2 --size-distance 0.3" + rest,
       "must not exceed --size"},
      {"--box 0 0 0 1 1 1 --surface a.obj --size 0.1 --size-near-surface 0.05 --size-distance 0" + rest,
       "--size-distance must be positive"},
      {"--box 0 0 0 1 1 1 --surface a.obj --surface b.obj:1 --size 0.1" + rest, "two surfaces are named 1"},
      {"--box 0 0 0 1 1 1 --surface a.obj --size 0.1 --output " + path("usage.vtk"), "only .msh output"},
  };
  for (const auto& [arguments, message] : cases) {
    const ToolRun run = run_reference_gmsh(arguments);
    EXPECT_EQ(run.status, 2) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << arguments << "\n" << run.output;
  }
  EXPECT_FALSE(fs::exists(path("usage.msh")));
}

}  // namespace
}  // namespace meccano
