#include <meccano/dealii_mesh.hpp>

#include <meccano/error.hpp>
#include <meccano/io/msh_reader.hpp>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <array>
#include <map>
#include <string>

namespace meccano {
namespace {

using Triple = std::array<unsigned int, 3>;

Triple sorted(Triple t) {
  std::sort(t.begin(), t.end());
  return t;
}

dealii::Point<3> to_point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

dealii::CellData<2> face_data(const Triple& vertices, dealii::types::boundary_id boundary,
                              dealii::types::manifold_id manifold = dealii::numbers::flat_manifold_id) {
  dealii::CellData<2> face(3);
  std::copy(vertices.begin(), vertices.end(), face.vertices.begin());
  face.boundary_id = boundary;
  face.manifold_id = manifold;
  return face;
}

void add_interface_face(DealiiMesh& mesh, DealiiInterface& interface, const Triple& vertices) {
  mesh.faces.boundary_quads.push_back(face_data(vertices, dealii::numbers::internal_face_boundary_id, interface.tag));
  for (const unsigned int v : vertices) interface.corners.push_back(mesh.vertices[v]);
}

// The triangles of the file's 2D group `name`, renumbered to the mesh's vertices; each must be a face
// of `tets_per_face` tets (1: on the boundary, 2: interior).
class MshFaces {
 public:
  MshFaces(const MshMesh& file, const std::vector<unsigned int>& vertex_of_node, const DealiiMesh& mesh)
      : file_(file), vertex_of_node_(vertex_of_node) {
    for (std::size_t t = 0; t < mesh.cells.size(); ++t)
      for (int f = 0; f < 4; ++f) {
        const auto& v = mesh.cells[t].vertices;
        const Triple face = sorted({v[(f + 1) % 4], v[(f + 2) % 4], v[(f + 3) % 4]});
        if (++tets_of_face_[face] == 3)
          throw InputError(file.source + ": tetrahedron " + std::to_string(file.tet_tags[t]) +
                           " shares a face with two others: the mesh is not conforming");
      }
  }

  std::vector<Triple> of_group(const MshGroup& group, int tets_per_face) const {
    std::vector<Triple> triangles;
    for (const int e : group.elements) {
      Triple triangle;
      for (int i = 0; i < 3; ++i) triangle[i] = vertex_of_node_[file_.triangles[e][i]];
      const auto found = std::find(triangle.begin(), triangle.end(), unused);
      const auto count = found != triangle.end() ? tets_of_face_.end() : tets_of_face_.find(sorted(triangle));
      if (count == tets_of_face_.end() || count->second != tets_per_face)
        throw InputError(file_.source + ": triangle " + std::to_string(file_.triangle_tags[e]) + " of " + group.name +
                         (count == tets_of_face_.end() ? " is not a face of any tetrahedron"
                          : tets_per_face == 2 ? " is on the boundary: an interface must be made of interior faces"
                                               : " is an interior face: a box side must be on the boundary"));
      triangles.push_back(triangle);
    }
    return triangles;
  }

  static constexpr unsigned int unused = ~0u;

 private:
  const MshMesh& file_;
  const std::vector<unsigned int>& vertex_of_node_;
  std::map<Triple, int> tets_of_face_;
};

// The corners of a triangle, sorted: the same key whatever the vertex numbering or order.
using CornerKey = std::array<std::array<double, 3>, 3>;

template <class Corner>
CornerKey corner_key(const Corner& corner) {
  CornerKey key;
  for (unsigned int i = 0; i < 3; ++i) key[i] = {corner(i)[0], corner(i)[1], corner(i)[2]};
  std::sort(key.begin(), key.end());
  return key;
}

}  // namespace

const DealiiInterface& DealiiMesh::interface(const std::string& name) const {
  std::string names;
  for (const DealiiInterface& candidate : interfaces) {
    if (candidate.name == name || (name.empty() && interfaces.size() == 1)) return candidate;
    names += (names.empty() ? "interface_" : ", interface_") + candidate.name;
  }
  throw InputError((source.empty() ? "" : source + ": ") +
                   (name.empty() ? std::to_string(interfaces.size()) + " interfaces" : "no interface_" + name) +
                   " in the mesh (" + (names.empty() ? "none" : names) + ")" +
                   (name.empty() ? ": name the one to use" : ""));
}

DealiiMesh dealii_mesh(const InsertionResult& result) {
  const TetMesh& tets = result.mesh;
  DealiiMesh mesh;
  mesh.vertices.reserve(tets.points.size());
  for (const Eigen::Vector3d& p : tets.points) mesh.vertices.push_back(to_point(p));
  mesh.cells.assign(tets.tets.size(), dealii::CellData<3>(4));
  for (TetId t = 0; t < tets.num_tets(); ++t) {
    const auto v = tets.oriented_tet(t);
    std::copy(v.begin(), v.end(), mesh.cells[t].vertices.begin());
    mesh.cells[t].material_id = domain_tag;
    for (int f = 0; f < 4; ++f)
      if (tets.neighbours[t][f] == no_tet && is_box_side_tag(tets.face_tags[t][f])) {
        const auto face = tets.outward_face(t, f);
        mesh.faces.boundary_quads.push_back(
            face_data({unsigned(face[0]), unsigned(face[1]), unsigned(face[2])}, tets.face_tags[t][f]));
      }
  }
  // The tets a closed surface encloses (its V_M) take the tag of inside_NAME.
  for (int s = 0; s < static_cast<int>(result.surfaces.size()); ++s)
    if (result.surfaces[s].closed)
      for (TetId t = 0; t < tets.num_tets(); ++t)
        if (result.surfaces[s].volumetric[t]) mesh.cells[t].material_id = domain_tag + 1 + s;
  for (const SurfaceInterface& surface : surface_interfaces(result)) {
    DealiiInterface& interface = mesh.interfaces.emplace_back();
    interface.name = surface.name;
    interface.tag = surface.tag;
    for (const InterfaceFace& face : surface.faces)
      add_interface_face(mesh, interface,
                         {unsigned(face.vertices[0]), unsigned(face.vertices[1]), unsigned(face.vertices[2])});
  }
  return mesh;
}

DealiiMesh read_dealii_mesh(const std::string& msh_path) {
  const MshMesh file = read_msh_mesh(msh_path);
  // Only the nodes of tets become vertices (deal.II refuses unused ones), in the file's order.
  std::vector<unsigned int> vertex_of_node(file.points.size(), MshFaces::unused);
  for (const auto& tet : file.tets)
    for (const int node : tet) vertex_of_node[node] = 0;
  DealiiMesh mesh;
  mesh.source = msh_path;
  for (std::size_t node = 0; node < file.points.size(); ++node)
    if (vertex_of_node[node] == 0) {
      vertex_of_node[node] = static_cast<unsigned int>(mesh.vertices.size());
      mesh.vertices.push_back(to_point(file.points[node]));
    }
  mesh.cells.assign(file.tets.size(), dealii::CellData<3>(4));
  for (std::size_t t = 0; t < file.tets.size(); ++t) {
    std::array<dealii::Point<3>, 4> p;
    auto& v = mesh.cells[t].vertices;
    for (int i = 0; i < 4; ++i) p[i] = mesh.vertices[v[i] = vertex_of_node[file.tets[t][i]]];
    double longest = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) longest = std::max(longest, p[i].distance(p[j]));
    const double volume6 = (p[1] - p[0]) * dealii::cross_product_3d(p[2] - p[0], p[3] - p[0]);
    if (!(std::abs(volume6) > 1e-12 * longest * longest * longest))
      throw InputError(msh_path + ": tetrahedron " + std::to_string(file.tet_tags[t]) + " is degenerate (volume " +
                       std::to_string(volume6 / 6.0) + ")");
    if (volume6 < 0.0) std::swap(v[2], v[3]);
    mesh.cells[t].material_id = domain_tag;
  }

  for (const MshGroup& group : file.groups)
    if (group.dimension == 3 && group.name.rfind("inside_", 0) == 0)
      for (const int t : group.elements) mesh.cells[t].material_id = static_cast<dealii::types::material_id>(group.tag);

  const MshFaces faces(file, vertex_of_node, mesh);
  for (const MshGroup& group : file.groups) {
    if (group.dimension != 2) continue;
    for (int side = 0; side < 6; ++side)
      if (group.name == box_side_name(static_cast<BoxSide>(side)))
        for (const Triple& triangle : faces.of_group(group, 1))
          mesh.faces.boundary_quads.push_back(face_data(triangle, box_side_tag(static_cast<BoxSide>(side))));
    if (group.name.rfind("interface_", 0) == 0) {
      DealiiInterface& interface = mesh.interfaces.emplace_back();
      interface.name = group.name.substr(10);
      interface.tag = static_cast<dealii::types::manifold_id>(group.tag);
      for (const Triple& triangle : faces.of_group(group, 2)) add_interface_face(mesh, interface, triangle);
    }
  }
  if (mesh.interfaces.empty()) throw InputError(msh_path + ": no 2D physical group named interface_NAME");
  return mesh;
}

void create_triangulation(const DealiiMesh& mesh, dealii::Triangulation<3>& triangulation) {
  triangulation.create_triangulation(mesh.vertices, mesh.cells, mesh.faces);
}

dealii::TriangulationDescription::Description<3, 3> fullydistributed_description(const DealiiMesh& mesh,
                                                                                 MPI_Comm communicator) {
  const unsigned int ranks = dealii::Utilities::MPI::n_mpi_processes(communicator);
  return dealii::TriangulationDescription::Utilities::create_description_from_triangulation_in_groups<3, 3>(
      [&mesh](dealii::Triangulation<3>& serial) { create_triangulation(mesh, serial); },
      [](dealii::Triangulation<3>& serial, const MPI_Comm&, const unsigned int group_size) {
    dealii::GridTools::partition_triangulation(group_size, serial);  // one group of all ranks: a part per rank
      },
      communicator, static_cast<int>(ranks));
}

std::vector<InterfaceCellFace> interface_cell_faces(const dealii::Triangulation<3>& triangulation,
                                                    const DealiiInterface& interface) {
  std::map<CornerKey, std::size_t> triangle_of_corners;
  for (std::size_t t = 0; t < interface.triangles(); ++t)
    triangle_of_corners.emplace(corner_key([&](unsigned int i) { return interface.corners[3 * t + i]; }), t);

  std::vector<InterfaceCellFace> faces;
  for (const auto& cell : triangulation.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (const unsigned int f : cell->face_indices()) {
      if (cell->at_boundary(f) || cell->face(f)->manifold_id() != interface.tag) continue;
      const auto found = triangle_of_corners.find(corner_key([&](unsigned int i) { return cell->face(f)->vertex(i); }));
      if (found == triangle_of_corners.end()) continue;  // marked with this id by the caller, not one of S's
      const dealii::Point<3>* corner = &interface.corners[3 * found->second];
      dealii::Tensor<1, 3> normal = dealii::cross_product_3d(corner[1] - corner[0], corner[2] - corner[0]);
      normal /= normal.norm();
      if ((cell->center() - corner[0]) * normal > 0) continue;  // in front of S: its neighbour lists the face
      faces.push_back({cell, f, cell->neighbor(f), cell->neighbor_of_neighbor(f), normal});
    }
  }
  if (dynamic_cast<const dealii::parallel::TriangulationBase<3>*>(&triangulation) == nullptr &&
      faces.size() != interface.triangles())
    throw InputError("interface_" + interface.name + ": " + std::to_string(interface.triangles() - faces.size()) +
                     " of its " + std::to_string(interface.triangles()) +
                     " triangles are not faces of the triangulation with manifold id " + std::to_string(interface.tag));
  return faces;
}

}  // namespace meccano
