// MSH 4.1 output read back by an independent reader (the Gmsh library): counts, group names,
// group contents and orientation must match the mesh written. Also the atomic-write guarantee.

#include <meccano/atomic_file.hpp>
#include <meccano/cube_meccano.hpp>
#include <meccano/error.hpp>
#include <meccano/mesh_io.hpp>

#include <gmsh.h>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <filesystem>
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

struct ReadBack {
  std::size_t nodes = 0;
  std::map<std::string, std::size_t> elements_per_group;
  std::map<std::string, int> dimension_of_group;
  std::map<std::string, Eigen::Vector3d> normal_sum;  // of 2D groups, area-weighted
  double tet_volume = 0;
  int negative_tets = 0;
};

ReadBack read_with_gmsh(const fs::path& path) {
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

  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    result.dimension_of_group[name] = dim;
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int entity : entities) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> element_tags, element_nodes;
      gmsh::model::mesh::getElements(types, element_tags, element_nodes, dim, entity);
      for (std::size_t k = 0; k < types.size(); ++k) {
        result.elements_per_group[name] += element_tags[k].size();
        const auto& n = element_nodes[k];
        if (types[k] == 2) {
          for (std::size_t e = 0; e < n.size(); e += 3)
            result.normal_sum[name] += 0.5 * (position[n[e + 1]] - position[n[e]]).cross(position[n[e + 2]] - position[n[e]]);
        } else if (types[k] == 4 && name == "domain") {
          for (std::size_t e = 0; e < n.size(); e += 4) {
            const Eigen::Vector3d a = position[n[e]];
            const double v = (position[n[e + 1]] - a).dot((position[n[e + 2]] - a).cross(position[n[e + 3]] - a)) / 6;
            result.tet_volume += v;
            result.negative_tets += v <= 0;
          }
        }
      }
    }
  }
  return result;
}

TEST(MeshIo, Msh41IsReadBackByGmshWithGroupsCountsAndOutwardNormals) {
  const Box box{{0, 0, 0}, {2, 1, 1}};
  const TetMesh mesh = make_cube_meccano(box, 5);
  const fs::path path = temporary_directory() / "bar.msh";
  write_msh41(mesh, standard_groups(mesh), path.string());
  const ReadBack back = read_with_gmsh(path);

  EXPECT_EQ(back.nodes, static_cast<std::size_t>(mesh.num_vertices()));
  EXPECT_EQ(back.elements_per_group.at("domain"), static_cast<std::size_t>(mesh.num_tets()));
  EXPECT_EQ(back.dimension_of_group.at("domain"), 3);
  EXPECT_EQ(back.negative_tets, 0);
  EXPECT_NEAR(back.tet_volume, 2.0, 1e-12);
  const std::map<std::string, Eigen::Vector3d> expected_normal{
      {"xmin", {-1, 0, 0}}, {"xmax", {1, 0, 0}}, {"ymin", {0, -2, 0}},
      {"ymax", {0, 2, 0}},  {"zmin", {0, 0, -2}}, {"zmax", {0, 0, 2}}};
  std::size_t boundary_triangles = 0;
  for (const auto& [name, normal] : expected_normal) {
    EXPECT_EQ(back.dimension_of_group.at(name), 2);
    EXPECT_LT((back.normal_sum.at(name) - normal).norm(), 1e-12) << name;
    boundary_triangles += back.elements_per_group.at(name);
  }
  std::size_t expected_boundary = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) expected_boundary += mesh.neighbours[t][f] == no_tet;
  EXPECT_EQ(boundary_triangles, expected_boundary);
  fs::remove_all(path.parent_path());
}

TEST(MeshIo, OverlappingVolumeGroupsAreWrittenOnceAndReadBackAsGroups) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 3);
  MeshGroups groups = standard_groups(mesh);
  TetGroup half{"volumetric_1", {}};
  for (TetId t = 0; t < mesh.num_tets(); t += 2) half.tets.push_back(t);
  groups.volumes.push_back(half);
  const fs::path path = temporary_directory() / "groups.msh";
  write_msh41(mesh, groups, path.string());
  const ReadBack back = read_with_gmsh(path);
  EXPECT_EQ(back.elements_per_group.at("domain"), static_cast<std::size_t>(mesh.num_tets()));
  EXPECT_EQ(back.elements_per_group.at("volumetric_1"), half.tets.size());
  fs::remove_all(path.parent_path());
}

TEST(MeshIo, FailedWriteLeavesNoFile) {
  const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  EXPECT_THROW(write_msh41(mesh, standard_groups(mesh), "/nonexistent-dir/out.msh"), InputError);
  EXPECT_FALSE(fs::exists("/nonexistent-dir/out.msh"));
  const fs::path dir = temporary_directory();
  const fs::path path = dir / "failing.msh";
  // A writer that fails half-way must not leave the target or a temporary behind.
  EXPECT_THROW(write_file_atomically(path.string(),
                                     [](std::ostream& out) {
                                       out << "partial content";
                                       throw std::runtime_error("simulated failure");
                                     }),
               std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace meccano
