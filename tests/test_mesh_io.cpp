// Mesh output read back by independent readers: the Gmsh library for MSH 4.1, MSH 2.2 and Medit, and
// the tests' own XML reader for VTU (support/vtu_reader.hpp). Counts, group names, group contents,
// orientation and qualities must match the mesh written. Also the atomic-write guarantee and the
// rejection of unknown formats and invalid groups.

#include <meccano/error.hpp>
#include <meccano/io/atomic_file.hpp>
#include <meccano/io/mesh_writers.hpp>
#include <meccano/mesh/cube_meccano.hpp>

#include <vtu_reader.hpp>

#include <gmsh.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>

#include <unistd.h>

namespace meccano {
namespace {

namespace fs = std::filesystem;

struct GmshSession {
  GmshSession() {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
  }
  ~GmshSession() { gmsh::finalize(); }
};

fs::path temporary_directory() {
  const fs::path dir = fs::temp_directory_path() / ("meccano-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Eigen vectors start uninitialised: sums start from zero explicitly.
template <class Key>
Eigen::Vector3d& sum_at(std::map<Key, Eigen::Vector3d>& sums, const Key& key) {
  return sums.try_emplace(key, Eigen::Vector3d::Zero()).first->second;
}

double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6;
}

// What Gmsh reads back, per physical group (MSH) or per entity (Medit: one entity per reference,
// named by its tag).
struct ReadBack {
  std::size_t nodes = 0, tets = 0, triangles = 0;  // elements in the file
  std::map<std::string, std::size_t> elements_per_group;
  std::map<std::string, int> dimension_of_group;
  std::map<std::string, Eigen::Vector3d> normal_sum;  // of 2D groups, area-weighted
  std::map<std::string, double> tet_volume;           // of 3D groups
  int negative_tets = 0;
};

ReadBack read_with_gmsh(const fs::path& path, bool by_entity = false) {
  GmshSession session;
  gmsh::open(path.string());
  ReadBack result;
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(node_tags, coords, parametric);
  result.nodes = node_tags.size();
  std::map<std::size_t, Eigen::Vector3d> position;
  for (std::size_t i = 0; i < node_tags.size(); ++i)
    position[node_tags[i]] = {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]};
  auto elements_of_type = [](int type) {
    std::vector<std::size_t> tags, nodes;
    gmsh::model::mesh::getElementsByType(type, tags, nodes);
    return tags.size();
  };
  result.tets = elements_of_type(4);
  result.triangles = elements_of_type(2);

  auto add_entity = [&](const std::string& name, int dim, int entity) {
    result.dimension_of_group[name] = dim;
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> tags, nodes;
    gmsh::model::mesh::getElements(types, tags, nodes, dim, entity);
    for (std::size_t k = 0; k < types.size(); ++k) {
      result.elements_per_group[name] += tags[k].size();
      const auto& n = nodes[k];
      if (types[k] == 2) {
        for (std::size_t e = 0; e < n.size(); e += 3)
          sum_at(result.normal_sum, name) +=
              0.5 * (position[n[e + 1]] - position[n[e]]).cross(position[n[e + 2]] - position[n[e]]);
      } else if (types[k] == 4) {
        for (std::size_t e = 0; e < n.size(); e += 4) {
          const double v = tet_volume(position[n[e]], position[n[e + 1]], position[n[e + 2]], position[n[e + 3]]);
          result.tet_volume[name] += v;
          result.negative_tets += v <= 0;
        }
      }
    }
  };
  if (by_entity) {
    gmsh::vectorpair entities;
    gmsh::model::getEntities(entities);
    for (const auto& [dim, tag] : entities) add_entity(std::to_string(dim) + "/" + std::to_string(tag), dim, tag);
    return result;
  }
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int entity : entities) add_entity(name, dim, entity);
  }
  return result;
}

TetGroup every_nth_tet(const TetMesh& mesh, const std::string& name, int tag, int n) {
  TetGroup group{name, tag, {}};
  for (TetId t = 0; t < mesh.num_tets(); t += n) group.tets.push_back(t);
  return group;
}

// Outward normal times area of each box side of the 2 x 1 x 1 box.
const std::map<std::string, Eigen::Vector3d> bar_side_normals{{"xmin", {-1, 0, 0}}, {"xmax", {1, 0, 0}},
                                                              {"ymin", {0, -2, 0}}, {"ymax", {0, 2, 0}},
                                                              {"zmin", {0, 0, -2}}, {"zmax", {0, 0, 2}}};

std::size_t boundary_face_count(const TetMesh& mesh) {
  std::size_t count = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) count += mesh.neighbours[t][f] == no_tet;
  return count;
}

class MshVersions : public ::testing::TestWithParam<MshVersion> {
 protected:
  // Written through write_mesh, which must pick the version asked for.
  fs::path write(const TetMesh& mesh, const MeshGroups& groups, const std::string& name) const {
    const fs::path path = temporary_directory() / name;
    write_mesh(mesh, groups, path.string(), {.msh_version = GetParam()});
    const std::string header = GetParam() == MshVersion::v41 ? "$MeshFormat\n4.1 0 8\n" : "$MeshFormat\n2.2 0 8\n";
    EXPECT_EQ(file_text(path).rfind(header, 0), 0u) << "not the version asked for";
    return path;
  }
};

TEST_P(MshVersions, ReadBackByGmshWithGroupsCountsAndOutwardNormals) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 5);
  const fs::path path = write(mesh, standard_groups(mesh), "bar.msh");
  const ReadBack back = read_with_gmsh(path);

  EXPECT_EQ(back.nodes, static_cast<std::size_t>(mesh.num_vertices()));
  EXPECT_EQ(back.elements_per_group.at("domain"), static_cast<std::size_t>(mesh.num_tets()));
  EXPECT_EQ(back.dimension_of_group.at("domain"), 3);
  EXPECT_EQ(back.negative_tets, 0);
  EXPECT_NEAR(back.tet_volume.at("domain"), 2.0, 1e-12);
  std::size_t boundary_triangles = 0;
  for (const auto& [name, normal] : bar_side_normals) {
    EXPECT_EQ(back.dimension_of_group.at(name), 2);
    EXPECT_LT((back.normal_sum.at(name) - normal).norm(), 1e-12) << name;
    boundary_triangles += back.elements_per_group.at(name);
  }
  EXPECT_EQ(boundary_triangles, boundary_face_count(mesh));
  EXPECT_EQ(back.triangles, boundary_triangles);
  fs::remove_all(path.parent_path());
}

// MSH 4.1 writes a tet in two groups once; MSH 2.2 once per group. Either way every group reads back
// with exactly its own elements.
TEST_P(MshVersions, OverlappingGroupsReadBackWithTheirOwnElements) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 3);
  MeshGroups groups = standard_groups(mesh);
  const TetGroup half = every_nth_tet(mesh, "volumetric_1", 2, 2);
  groups.volumes.push_back(half);
  FaceGroup corner{"corner", 7, {groups.surfaces[0].faces[0]}};
  groups.surfaces.push_back(corner);
  const fs::path path = write(mesh, groups, "groups.msh");
  const ReadBack back = read_with_gmsh(path);
  EXPECT_EQ(back.elements_per_group.at("domain"), static_cast<std::size_t>(mesh.num_tets()));
  EXPECT_EQ(back.elements_per_group.at("volumetric_1"), half.tets.size());
  EXPECT_EQ(back.elements_per_group.at("xmin"), groups.surfaces[0].faces.size());
  EXPECT_EQ(back.elements_per_group.at("corner"), 1u);
  const std::size_t copies = GetParam() == MshVersion::v22 ? half.tets.size() : 0;
  EXPECT_EQ(back.tets, mesh.num_tets() + copies);
  fs::remove_all(path.parent_path());
}

// Two node fields on a small meccano: node references (negative for none, as the `sequence` command's
// previous_node) and plain integers.
std::array<NodeField, 2> test_node_fields(const TetMesh& mesh) {
  std::array<NodeField, 2> fields{NodeField{"previous_node", {}, true}, NodeField{"count", {}, false}};
  for (VertexId v = 0; v < mesh.num_vertices(); ++v) {
    fields[0].values.push_back(v % 3 == 0 ? -1 : v / 2);
    fields[1].values.push_back(7 * std::int64_t{v} - 5);
  }
  return fields;
}

// MSH writes each node field as a $NodeData section: Gmsh reads it as a view named like the field, node
// references in its node tags (the vertex + 1) and -1 for none, other values as they are.
TEST_P(MshVersions, NodeFieldsReadBackByGmshAsViewsInTheFilesNodeTags) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 2);
  const auto fields = test_node_fields(mesh);
  const fs::path path = temporary_directory() / "fields.msh";
  write_mesh(mesh, standard_groups(mesh), path.string(), {.msh_version = GetParam()}, fields);
  GmshSession session;
  gmsh::open(path.string());
  std::vector<int> views;
  gmsh::view::getTags(views);
  ASSERT_EQ(views.size(), 2u);
  for (std::size_t k = 0; k < views.size(); ++k) {
    std::string name;
    gmsh::option::getString("View[" + std::to_string(gmsh::view::getIndex(views[k])) + "].Name", name);
    EXPECT_EQ(name, fields[k].name);
    std::string type;
    std::vector<std::size_t> tags;
    std::vector<std::vector<double>> data;
    double time = 0;
    int components = 0;
    gmsh::view::getModelData(views[k], 0, type, tags, data, time, components);
    EXPECT_EQ(type, "NodeData");
    ASSERT_EQ(tags.size(), static_cast<std::size_t>(mesh.num_vertices()));
    for (std::size_t i = 0; i < tags.size(); ++i) {
      const std::int64_t value = fields[k].values[tags[i] - 1];
      const std::int64_t expected = !fields[k].node_references ? value : value < 0 ? -1 : value + 1;
      ASSERT_EQ(data[i].at(0), static_cast<double>(expected)) << fields[k].name << " at node tag " << tags[i];
    }
  }
  fs::remove_all(path.parent_path());
}

INSTANTIATE_TEST_SUITE_P(MeshIo, MshVersions, ::testing::Values(MshVersion::v41, MshVersion::v22),
                         [](const auto& version) { return version.param == MshVersion::v41 ? "msh41" : "msh22"; });

// A tet's reference is its first 3D group, a face's its 2D group (once per group).
TEST(MeshIo, MeditIsReadBackByGmshWithAReferencePerGroup) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 3);
  MeshGroups groups = standard_groups(mesh);
  const TetGroup inner = every_nth_tet(mesh, "inner", 2, 3);
  groups.volumes.insert(groups.volumes.begin(), inner);  // ref 2; the other tets keep domain's, 1
  FaceGroup corner{"corner", 7, {groups.surfaces[0].faces[0], groups.surfaces[0].faces[1]}};
  groups.surfaces.push_back(corner);  // ref 7, faces also in xmin
  const fs::path path = temporary_directory() / "bar.mesh";
  write_medit(mesh, groups, path.string());

  const ReadBack back = read_with_gmsh(path, true);
  EXPECT_EQ(back.nodes, static_cast<std::size_t>(mesh.num_vertices()));
  EXPECT_EQ(back.tets, static_cast<std::size_t>(mesh.num_tets()));
  EXPECT_EQ(back.triangles, boundary_face_count(mesh) + 2);
  EXPECT_EQ(back.elements_per_group.at("3/2"), inner.tets.size());
  EXPECT_EQ(back.elements_per_group.at("3/1"), mesh.num_tets() - inner.tets.size());
  EXPECT_EQ(back.negative_tets, 0);
  EXPECT_NEAR(back.tet_volume.at("3/1") + back.tet_volume.at("3/2"), 2.0, 1e-12);
  for (int side = 0; side < 6; ++side) {  // xmin .. zmax are refs 1 .. 6
    const std::string name = box_side_name(static_cast<BoxSide>(side));
    EXPECT_LT((back.normal_sum.at("2/" + std::to_string(side + 1)) - bar_side_normals.at(name)).norm(), 1e-12) << name;
  }
  EXPECT_EQ(back.elements_per_group.at("2/7"), 2u);

  const std::string text = file_text(path);
  EXPECT_EQ(text.rfind("MeshVersionFormatted 2\nDimension 3\n", 0), 0u);
  for (const char* line : {"\n# Tetrahedra ref 2 inner\n", "\n# Tetrahedra ref 1 domain\n",
                           "\n# Triangles ref 1 xmin\n", "\n# Triangles ref 6 zmax\n", "\n# Triangles ref 7 corner\n"})
    EXPECT_NE(text.find(line), std::string::npos) << line;
  fs::remove_all(path.parent_path());
}

// 12 (3V)^(2/3) / (sum of squared edge lengths), computed here from the file's own points.
double equilateral_mean_ratio(const std::array<Eigen::Vector3d, 4>& p) {
  double squared_edges = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) squared_edges += (p[i] - p[j]).squaredNorm();
  return 12 * std::cbrt(std::pow(3 * tet_volume(p[0], p[1], p[2], p[3]), 2)) / squared_edges;
}

TEST(MeshIo, VtuIsReadBackWithCellsGroupsAndQualities) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 3);
  // Moving one interior vertex lowers the meccano quality of exactly the tets around it.
  const Eigen::Vector3d centre(1, 0.5, 0.5);
  VertexId moved = 0;
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    if ((mesh.points[v] - centre).norm() < (mesh.points[moved] - centre).norm()) moved = v;
  ASSERT_LT((mesh.points[moved] - centre).norm(), 1e-12);
  mesh.points[moved] += Eigen::Vector3d(0.05, -0.03, 0.02);
  std::size_t tets_around_moved = 0;
  for (const auto& tet : mesh.tets) tets_around_moved += std::find(tet.begin(), tet.end(), moved) != tet.end();

  MeshGroups groups = standard_groups(mesh);
  const TetGroup half = every_nth_tet(mesh, "volumetric_1", 2, 2);
  groups.volumes.push_back(half);
  const fs::path path = temporary_directory() / "bar.vtu";
  write_vtu(mesh, groups, path.string());
  const testing::VtuFile vtu = testing::read_vtu(path.string());

  // Tags per dimension, as in MSH (domain 1, volumetric_1 2; xmin .. zmax 1 .. 6), named in the field
  // data as (tag, dimension); the cell type tells the dimension.
  std::map<std::pair<int, int>, std::size_t> expected_cells_of_group{{{3, 1}, mesh.tets.size()},
                                                                     {{3, 2}, half.tets.size()}};
  std::map<std::string, std::vector<double>> field{{"domain", {1, 3}}, {"volumetric_1", {2, 3}}};
  for (const FaceGroup& side : groups.surfaces) {
    expected_cells_of_group[{2, side.tag}] = side.faces.size();
    field[side.name] = {double(side.tag), 2};
  }
  EXPECT_EQ(vtu.field, field);
  const std::size_t cells = mesh.tets.size() + half.tets.size() + boundary_face_count(mesh);
  ASSERT_EQ(vtu.points, mesh.num_vertices());
  ASSERT_EQ(vtu.cells, static_cast<std::int64_t>(cells));
  const auto& points = vtu.arrays.at("Points");
  const auto& connectivity = vtu.arrays.at("connectivity");
  const auto& offsets = vtu.arrays.at("offsets");
  const auto& types = vtu.arrays.at("types");
  const auto& group = vtu.arrays.at("group");
  const auto& meccano_quality = vtu.arrays.at("quality_meccano");
  const auto& equilateral_quality = vtu.arrays.at("quality_equilateral");
  ASSERT_EQ(points.size(), 3 * static_cast<std::size_t>(mesh.num_vertices()));
  for (const auto* array : {&offsets, &types, &group, &meccano_quality, &equilateral_quality})
    ASSERT_EQ(array->size(), cells);
  ASSERT_EQ(offsets.back(), static_cast<double>(connectivity.size()));

  auto point = [&](double node) {
    const auto i = static_cast<std::size_t>(node);
    return Eigen::Vector3d(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
  };
  std::map<std::pair<int, int>, std::size_t> cells_of_group;  // (dimension, tag)
  std::map<int, Eigen::Vector3d> normal_sum;
  double domain_volume = 0;
  std::size_t lowered = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    const auto begin = static_cast<std::size_t>(c == 0 ? 0 : offsets[c - 1]);
    const auto size = static_cast<std::size_t>(offsets[c]) - begin;
    const int tag = static_cast<int>(group[c]);
    ++cells_of_group[{types[c] == 10 ? 3 : 2, tag}];
    if (types[c] == 10) {
      ASSERT_EQ(size, 4u);
      const std::array<Eigen::Vector3d, 4> p{point(connectivity[begin]), point(connectivity[begin + 1]),
                                             point(connectivity[begin + 2]), point(connectivity[begin + 3])};
      const double volume = tet_volume(p[0], p[1], p[2], p[3]);
      EXPECT_GT(volume, 0) << "cell " << c;
      if (tag == 1) domain_volume += volume;
      EXPECT_NEAR(equilateral_quality[c], equilateral_mean_ratio(p), 1e-12) << "cell " << c;
      for (const double q : {meccano_quality[c], equilateral_quality[c]}) {
        EXPECT_GT(q, 0) << "cell " << c;
        EXPECT_LE(q, 1 + 1e-12) << "cell " << c;
      }
      lowered += tag == 1 && meccano_quality[c] < 1 - 1e-9;
    } else {
      ASSERT_EQ(types[c], 5) << "cell " << c;
      ASSERT_EQ(size, 3u);
      sum_at(normal_sum, tag) += 0.5 * (point(connectivity[begin + 1]) - point(connectivity[begin]))
                                           .cross(point(connectivity[begin + 2]) - point(connectivity[begin]));
      EXPECT_EQ(meccano_quality[c], 1.0);
      EXPECT_EQ(equilateral_quality[c], 1.0);
    }
  }
  EXPECT_EQ(cells_of_group, expected_cells_of_group);
  EXPECT_NEAR(domain_volume, 2.0, 1e-12);
  EXPECT_EQ(lowered, tets_around_moved);
  for (const auto& [name, normal] : bar_side_normals)
    EXPECT_LT((normal_sum[static_cast<int>(field.at(name)[0])] - normal).norm(), 1e-12) << name;
  fs::remove_all(path.parent_path());
}

// VTU writes each node field as PointData, node references as 0-based point indices; Medit holds no node
// data and refuses fields; a field of the wrong size is refused before anything is written.
TEST(MeshIo, NodeFieldsAreVtuPointDataAndMeditRefusesThem) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 2);
  const auto fields = test_node_fields(mesh);
  const fs::path dir = temporary_directory();
  write_mesh(mesh, standard_groups(mesh), (dir / "fields.vtu").string(), {}, fields);
  const testing::VtuFile vtu = testing::read_vtu((dir / "fields.vtu").string());
  for (const NodeField& field : fields) {
    const std::vector<double>& read = vtu.arrays.at(field.name);
    ASSERT_EQ(read.size(), field.values.size());
    for (std::size_t v = 0; v < read.size(); ++v) {
      const std::int64_t value = field.values[v];
      ASSERT_EQ(read[v], static_cast<double>(field.node_references && value < 0 ? -1 : value)) << field.name;
    }
  }
  fs::remove(dir / "fields.vtu");
  EXPECT_THROW(write_mesh(mesh, standard_groups(mesh), (dir / "fields.mesh").string(), {}, fields), InputError);
  NodeField short_field{"short", {1, 2, 3}, false};
  EXPECT_THROW(write_mesh(mesh, standard_groups(mesh), (dir / "short.msh").string(), {}, {&short_field, 1}),
               std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(MeshIo, TheFormatFollowsTheExtension) {
  EXPECT_EQ(mesh_format_of("out/a.msh"), MeshFormat::msh);
  EXPECT_EQ(mesh_format_of("a.vtu"), MeshFormat::vtu);
  EXPECT_EQ(mesh_format_of("a.b.mesh"), MeshFormat::medit);
  for (const char* name : {"a.vtk", "a.msh.gz", "mesh", "a.MSH", ".msh"}) EXPECT_FALSE(mesh_format_of(name)) << name;

  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  const fs::path dir = temporary_directory();
  const fs::path path = dir / "cube.vtk";
  try {
    write_mesh(mesh, standard_groups(mesh), path.string());
    ADD_FAILURE() << "no error for .vtk";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find(".msh, .vtu and .mesh"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

using Writer = std::function<void(const TetMesh&, const MeshGroups&, const std::string&)>;
const std::map<std::string, Writer> writers{
    {"msh41", [](const TetMesh& m, const MeshGroups& g, const std::string& p) { write_msh41(m, g, p); }},
    {"msh22", [](const TetMesh& m, const MeshGroups& g, const std::string& p) { write_msh22(m, g, p); }},
    {"vtu", [](const TetMesh& m, const MeshGroups& g, const std::string& p) { write_vtu(m, g, p); }},
    {"medit", write_medit}};

TEST(MeshIo, InvalidGroupsAreRejectedBeforeAnythingIsWritten) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  MeshGroups missing_tet = standard_groups(mesh);
  missing_tet.volumes.push_back({"stray", 2, {mesh.num_tets()}});
  MeshGroups missing_face = standard_groups(mesh);
  missing_face.surfaces.push_back({"bad_face", 7, {{0, 4}}});
  MeshGroups quoted = standard_groups(mesh);
  quoted.surfaces[0].name = "x\"min";
  MeshGroups repeated_tag = standard_groups(mesh);
  repeated_tag.surfaces.push_back({"interface_again", 6, {{0, 0}}});
  MeshGroups zero_tag = standard_groups(mesh);
  zero_tag.volumes[0].tag = 0;
  const fs::path dir = temporary_directory();
  for (const auto& [format, write] : writers)
    for (const auto& [groups, message] :
         {std::pair{missing_tet, "mesh group stray: tet 6 does not exist"},
          std::pair{missing_face, "mesh group bad_face: tet 0 has no local face 4"},
          std::pair{quoted, "names may not hold"},
          std::pair{repeated_tag, "interface_again: tag 6 is already the tag of another 2D"},
          std::pair{zero_tag, "mesh group domain: tag 0 is not positive"}}) {
      try {
        write(mesh, groups, (dir / "out").string());
        ADD_FAILURE() << format << ": no error for " << message;
      } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find(message), std::string::npos) << format << ": " << error.what();
      }
    }
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(MeshIo, FailedWriteLeavesNoFile) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  for (const auto& [format, write] : writers) {
    EXPECT_THROW(write(mesh, standard_groups(mesh), "/nonexistent-dir/out"), InputError) << format;
    EXPECT_FALSE(fs::exists("/nonexistent-dir/out"));
  }
  const fs::path dir = temporary_directory();
  const fs::path path = dir / "failing.msh";
  // A writer that fails half-way must not leave the target or a temporary behind.
  EXPECT_THROW(write_file_atomically(
                   path.string(),
                   [](std::ostream& out) {
    out << "partial content";
    throw std::runtime_error("simulated failure");
                   }),
               std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

// Writing is by rename, which would replace a device node: /dev/null must stay a device.
TEST(MeshIo, RefusesToReplaceAFileThatIsNotRegular) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  try {
    write_msh41(mesh, standard_groups(mesh), "/dev/null");
    ADD_FAILURE() << "wrote over /dev/null";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("/dev/null: not a regular file"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

}  // namespace
}  // namespace meccano
