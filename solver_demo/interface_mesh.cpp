#include "interface_mesh.hpp"

#include <meccano/atomic_file.hpp>
#include <meccano/error.hpp>

#include <gmsh.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <unordered_map>

namespace solver_demo {
namespace {

using Triple = std::array<unsigned int, 3>;

Eigen::Vector3d point(const InterfaceMesh& mesh, unsigned int v) { return Eigen::Vector3d(mesh.points[v].data()); }

Triple sorted(Triple t) {
  std::sort(t.begin(), t.end());
  return t;
}

// One Gmsh session per read: the library keeps a global model.
class GmshSession {
 public:
  GmshSession() {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

std::string last_gmsh_error() {
  std::string error;
  gmsh::logger::getLastError(error);
  return error;
}

// The elements of one entity (or of every entity of dimension `dim` when entity < 0), all of Gmsh
// element type `type` (4 = linear tet, 2 = linear triangle); anything else is an error.
struct Elements {
  std::vector<std::size_t> tags;
  std::vector<std::size_t> nodes;  // `nodes_per_element` node tags per element
};

Elements elements_of_type(const std::string& what, int dim, int entity, int type, const std::string& path) {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> tags, nodes;
  gmsh::model::mesh::getElements(types, tags, nodes, dim, entity);
  Elements result;
  for (std::size_t k = 0; k < types.size(); ++k) {
    if (tags[k].empty()) continue;
    if (types[k] != type) {
      std::string name;
      int element_dim = 0, order = 0, node_count = 0, primary = 0;
      std::vector<double> local;
      gmsh::model::mesh::getElementProperties(types[k], name, element_dim, order, node_count, local, primary);
      throw meccano::InputError(path + ": element " + std::to_string(tags[k].front()) + " of " + what + " is a " + name +
                                "; the solver takes linear " + (type == 4 ? "tetrahedra" : "triangles") + " only");
    }
    result.tags.insert(result.tags.end(), tags[k].begin(), tags[k].end());
    result.nodes.insert(result.nodes.end(), nodes[k].begin(), nodes[k].end());
  }
  return result;
}

// The 2D physical group interface_NAME, NAME given or the only one in the file.
std::pair<int, std::string> interface_group(const std::string& interface_name, const std::string& path) {
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 2);
  std::vector<std::pair<int, std::string>> interfaces;
  std::string all_names;
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    all_names += (all_names.empty() ? "" : ", ") + (name.empty() ? "(unnamed " + std::to_string(tag) + ")" : name);
    if (name.rfind("interface_", 0) == 0) interfaces.emplace_back(tag, name.substr(10));
  }
  if (all_names.empty()) all_names = "none";
  for (const auto& candidate : interfaces)
    if (candidate.second == interface_name) return candidate;
  if (!interface_name.empty())
    throw meccano::InputError(path + ": no 2D physical group named interface_" + interface_name +
                              " (its 2D groups: " + all_names + ")");
  if (interfaces.size() != 1)
    throw meccano::InputError(path + ": " + (interfaces.empty() ? "no" : std::to_string(interfaces.size())) +
                              " 2D physical groups named interface_NAME (its 2D groups: " + all_names +
                              "); name the one to use with --interface");
  return interfaces.front();
}

double signed_volume_times_six(const std::array<Eigen::Vector3d, 4>& p) {
  return (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]));
}

// Every face of every tet with its tet, sorted so that the tets sharing a face are adjacent.
struct FaceOfTet {
  Triple key;
  std::size_t tet;
  bool operator<(const FaceOfTet& other) const { return key < other.key; }
};

// Flags the elements whose vertex set an earlier element has already: MSH 2.2 writes an element once
// per physical group it belongs to, so a tet in `domain` and `volumetric_NAME` comes twice.
template <std::size_t n>
std::vector<bool> repeated_elements(const std::vector<std::array<unsigned int, n>>& elements) {
  std::vector<std::pair<std::array<unsigned int, n>, std::size_t>> keys;
  keys.reserve(elements.size());
  for (std::size_t e = 0; e < elements.size(); ++e) {
    keys.emplace_back(elements[e], e);
    std::sort(keys.back().first.begin(), keys.back().first.end());
  }
  std::sort(keys.begin(), keys.end());
  std::vector<bool> repeated(elements.size(), false);
  for (std::size_t k = 1; k < keys.size(); ++k)
    if (keys[k].first == keys[k - 1].first) repeated[keys[k].second] = true;
  return repeated;
}

std::vector<FaceOfTet> sorted_faces(const InterfaceMesh& mesh) {
  std::vector<FaceOfTet> faces;
  faces.reserve(4 * mesh.tets.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      const auto& v = mesh.tets[t];
      faces.push_back({sorted({v[(f + 1) % 4], v[(f + 2) % 4], v[(f + 3) % 4]}), t});
    }
  std::sort(faces.begin(), faces.end());
  return faces;
}

}  // namespace

InterfaceMesh interface_mesh_from_insertion(const meccano::InsertionResult& result, int surface_index) {
  const std::string& name = result.surfaces.at(surface_index).name;
  const auto interfaces = meccano::surface_interfaces(result);
  const auto found = std::find_if(interfaces.begin(), interfaces.end(), [&](const auto& s) { return s.name == name; });
  if (found == interfaces.end())
    throw meccano::MeshingError("surface " + name + " has no interface: its approximation was not built");
  InterfaceMesh mesh;
  mesh.interface_name = name;
  const meccano::TetMesh& tets = result.mesh;
  mesh.points.reserve(tets.points.size());
  for (const Eigen::Vector3d& p : tets.points) mesh.points.push_back({p.x(), p.y(), p.z()});
  mesh.tets.reserve(tets.num_tets());
  for (meccano::TetId t = 0; t < tets.num_tets(); ++t) {
    const auto v = tets.oriented_tet(t);
    mesh.tets.push_back({static_cast<unsigned int>(v[0]), static_cast<unsigned int>(v[1]),
                         static_cast<unsigned int>(v[2]), static_cast<unsigned int>(v[3])});
  }
  for (const meccano::InterfaceFace& face : found->faces)
    mesh.interface.push_back({static_cast<unsigned int>(face.vertices[0]), static_cast<unsigned int>(face.vertices[1]),
                              static_cast<unsigned int>(face.vertices[2])});
  return mesh;
}

InterfaceMesh read_interface_mesh(const std::string& path, const std::string& interface_name) {
  if (!std::filesystem::is_regular_file(path)) throw meccano::InputError(path + ": no such file");
  const GmshSession session;
  try {
    gmsh::open(path);
  } catch (...) {
    throw meccano::InputError(path + ": Gmsh cannot read it: " + last_gmsh_error());
  }
  if (const std::string error = last_gmsh_error(); !error.empty())
    throw meccano::InputError(path + ": Gmsh cannot read it: " + error);

  std::vector<std::size_t> node_tags;
  std::vector<double> coordinates, parametric;
  gmsh::model::mesh::getNodes(node_tags, coordinates, parametric, -1, -1, false, false);
  std::unordered_map<std::size_t, std::size_t> node_position;  // tag -> position in node_tags
  for (std::size_t i = 0; i < node_tags.size(); ++i) node_position.emplace(node_tags[i], i);

  const Elements tets = elements_of_type("the volume", 3, -1, 4, path);
  if (tets.tags.empty()) throw meccano::InputError(path + ": no tetrahedra");
  const auto [group_tag, name] = interface_group(interface_name, path);
  std::vector<int> entities;
  gmsh::model::getEntitiesForPhysicalGroup(2, group_tag, entities);
  Elements triangles;
  for (const int entity : entities) {
    Elements part = elements_of_type("interface_" + name, 2, entity, 2, path);
    triangles.tags.insert(triangles.tags.end(), part.tags.begin(), part.tags.end());
    triangles.nodes.insert(triangles.nodes.end(), part.nodes.begin(), part.nodes.end());
  }
  if (triangles.tags.empty()) throw meccano::InputError(path + ": interface_" + name + " holds no triangles");

  // Only the nodes of tets become points, numbered in the file's order (deal.II refuses unused ones).
  const auto position = [&](std::size_t tag, std::size_t element) {
    const auto found = node_position.find(tag);
    if (found == node_position.end())
      throw meccano::InputError(path + ": element " + std::to_string(element) + " refers to node " +
                                std::to_string(tag) + ", which the file does not define");
    return found->second;
  };
  std::vector<bool> used(node_tags.size(), false);
  for (std::size_t e = 0; e < tets.nodes.size(); ++e) used[position(tets.nodes[e], tets.tags[e / 4])] = true;
  std::vector<unsigned int> index(node_tags.size(), ~0u);
  InterfaceMesh mesh;
  mesh.interface_name = name;
  for (std::size_t i = 0; i < node_tags.size(); ++i)
    if (used[i]) {
      index[i] = static_cast<unsigned int>(mesh.points.size());
      mesh.points.push_back({coordinates[3 * i], coordinates[3 * i + 1], coordinates[3 * i + 2]});
    }

  std::vector<std::array<unsigned int, 4>> file_tets(tets.tags.size());
  for (std::size_t t = 0; t < file_tets.size(); ++t)
    for (int i = 0; i < 4; ++i) file_tets[t][i] = index[position(tets.nodes[4 * t + i], tets.tags[t])];
  const std::vector<bool> repeated_tet = repeated_elements(file_tets);
  std::vector<std::size_t> tet_tags;  // of mesh.tets, for messages
  for (std::size_t t = 0; t < file_tets.size(); ++t) {
    if (repeated_tet[t]) continue;
    auto v = file_tets[t];
    std::array<Eigen::Vector3d, 4> p;
    for (int i = 0; i < 4; ++i) p[i] = point(mesh, v[i]);
    double longest = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (p[i] - p[j]).norm());
    const double volume6 = signed_volume_times_six(p);
    if (!(std::abs(volume6) > 1e-12 * longest * longest * longest))
      throw meccano::InputError(path + ": tetrahedron " + std::to_string(tets.tags[t]) + " is degenerate (volume " +
                                std::to_string(volume6 / 6.0) + ")");
    if (volume6 < 0.0) std::swap(v[2], v[3]);
    mesh.tets.push_back(v);
    tet_tags.push_back(tets.tags[t]);
  }

  const std::vector<FaceOfTet> faces = sorted_faces(mesh);
  for (std::size_t i = 0; i + 2 < faces.size(); ++i)
    if (faces[i].key == faces[i + 2].key)
      throw meccano::InputError(path + ": tetrahedra " + std::to_string(tet_tags[faces[i].tet]) + ", " +
                                std::to_string(tet_tags[faces[i + 1].tet]) + " and " +
                                std::to_string(tet_tags[faces[i + 2].tet]) + " share one face: the mesh is not conforming");

  std::vector<Triple> file_triangles(triangles.tags.size());
  for (std::size_t t = 0; t < file_triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) {
      const std::size_t at = position(triangles.nodes[3 * t + i], triangles.tags[t]);
      if (index[at] == ~0u)
        throw meccano::InputError(path + ": triangle " + std::to_string(triangles.tags[t]) + " of interface_" + name +
                                  " has node " + std::to_string(node_tags[at]) + ", which no tetrahedron uses");
      file_triangles[t][i] = index[at];
    }
  const std::vector<bool> repeated_triangle = repeated_elements(file_triangles);
  for (std::size_t t = 0; t < file_triangles.size(); ++t) {
    if (repeated_triangle[t]) continue;
    const auto [first, last] = std::equal_range(faces.begin(), faces.end(), FaceOfTet{sorted(file_triangles[t]), 0});
    if (last - first != 2)
      throw meccano::InputError(path + ": triangle " + std::to_string(triangles.tags[t]) + " of interface_" + name +
                                (first == last ? " is not a face of any tetrahedron"
                                               : " lies on the boundary of the mesh (a face of one tetrahedron only)") +
                                ": an interface must be made of interior faces");
    mesh.interface.push_back(file_triangles[t]);
  }
  return mesh;
}

double interface_area(const InterfaceMesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.interface)
    area += 0.5 * (point(mesh, t[1]) - point(mesh, t[0])).cross(point(mesh, t[2]) - point(mesh, t[0])).norm();
  return area;
}

void write_interface_vtu(const InterfaceMesh& mesh, const std::vector<TriangleField>& fields, const std::string& path) {
  // Only the interface's own nodes, renumbered.
  std::unordered_map<unsigned int, std::size_t> local;
  std::vector<unsigned int> nodes;
  for (const auto& t : mesh.interface)
    for (const unsigned int v : t)
      if (local.emplace(v, nodes.size()).second) nodes.push_back(v);
  meccano::write_file_atomically(path, [&](std::ostream& out) {
    out.precision(17);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << nodes.size() << "\" NumberOfCells=\""
        << mesh.interface.size() << "\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const unsigned int v : nodes) out << mesh.points[v][0] << ' ' << mesh.points[v][1] << ' ' << mesh.points[v][2] << '\n';
    out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : mesh.interface) out << local[t[0]] << ' ' << local[t[1]] << ' ' << local[t[2]] << '\n';
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 1; i <= mesh.interface.size(); ++i) out << 3 * i << '\n';
    out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < mesh.interface.size(); ++i) out << "5\n";  // VTK_TRIANGLE
    out << "</DataArray>\n</Cells>\n<CellData>\n";
    for (const auto& [name, values] : fields) {
      out << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (const double value : values) out << value << '\n';
      out << "</DataArray>\n";
    }
    out << "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  });
}

}  // namespace solver_demo
