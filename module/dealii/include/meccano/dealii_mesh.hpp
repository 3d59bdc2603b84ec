// The deal.II adapter (CMake target meccano::dealii): a mesh with inserted surfaces as a deal.II 9.4
// Triangulation<3>, serial or fully distributed, and each surface's faces with the cells on both sides.
//
// deal.II stores no boundary id on an interior face (create_triangulation and its MSH readers throw),
// so the faces of an inserted surface S are marked the one way deal.II keeps through distribution: a
// manifold id, equal to the surface's tag (7, 8, ... in input order, as in every file the project
// writes). With no Manifold object attached the id changes no geometry.
//
// Input    an InsertionResult (dealii_mesh), or an MSH file (read_dealii_mesh: 2.2 or 4.1, ASCII or
//          binary, this module's, reference-gmsh's, reference-tetgen's, Gmsh's) with the groups `xmin` ...
//          `zmax`, `interface_NAME` and `inside_NAME` (doc/user_guide.md, "Tags"); other groups are ignored.
// Output   DealiiMesh: vertices; positively oriented tets (material id = domain_tag, or the tag of
//          `inside_NAME`, 2 + k, for the tets a closed surface k encloses: an inclusion's coefficient can
//          be set by material id); the box-side faces
//          with boundary id = their side's tag 1-6 (other boundary faces keep 0); S's faces with
//          boundary id numbers::internal_face_boundary_id and manifold id = S's tag; per surface its
//          triangles as corner points, oriented like S.
// Then     create_triangulation (serial) or fullydistributed_description (for a
//          parallel::fullydistributed::Triangulation<3>), and interface_cell_faces per surface. Reset the
//          manifold ids afterwards (triangulation.set_all_manifold_ids(numbers::flat_manifold_id)):
//          MappingFE checks in Debug builds that a cell and its faces share one manifold id.
// Errors   InputError naming the file and the element: no tets, a tet that is not linear or is
//          degenerate, a face shared by three tets, a box-side triangle that is not on the boundary, an
//          interface triangle that is not an interior face, an MSH file without interface_NAME group.
//
// deal.II 9.4 degrades tets under refine_global: refine with meccano-immerse (a smaller --resolution).
#pragma once

#include <meccano/stages/pipeline.hpp>

#include <deal.II/base/mpi.h>
#include <deal.II/base/point.h>
#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>

#include <boost/serialization/string.hpp>
#include <boost/serialization/vector.hpp>

#include <string>
#include <vector>

namespace meccano {

struct DealiiInterface {
  std::string name;                       // NAME of interface_NAME
  dealii::types::manifold_id tag = 0;     // the manifold id of its faces
  std::vector<dealii::Point<3>> corners;  // 3 per triangle, right-hand normal = S's normal

  std::size_t triangles() const { return corners.size() / 3; }
  // For Utilities::MPI::broadcast: the fully distributed ranks need the interfaces, not the mesh.
  template <class Archive>
  void serialize(Archive& archive, unsigned int /*version*/) {
    archive& name& tag& corners;
  }
};

struct DealiiMesh {
  std::string source;  // the MSH file read, for messages (empty for an InsertionResult)
  std::vector<dealii::Point<3>> vertices;
  std::vector<dealii::CellData<3>> cells;
  dealii::SubCellData faces;  // box sides and interface faces, in boundary_quads
  std::vector<DealiiInterface> interfaces;

  // The interface of that NAME, or the only one when `name` is empty. Throws InputError naming the source
  // and listing the interfaces otherwise.
  const DealiiInterface& interface(const std::string& name = "") const;
};

DealiiMesh dealii_mesh(const InsertionResult& result);
DealiiMesh read_dealii_mesh(const std::string& msh_path);

void create_triangulation(const DealiiMesh& mesh, dealii::Triangulation<3>& triangulation);

// The coarse mesh built on rank 0 (only rank 0's `mesh` is read) and cut by METIS into one part per rank
// of `communicator`; each rank gets its cells and a layer of ghosts. Boundary and manifold ids survive.
// Collective. Give the ranks the interfaces with Utilities::MPI::broadcast(communicator, mesh.interfaces, 0).
dealii::TriangulationDescription::Description<3, 3> fullydistributed_description(const DealiiMesh& mesh,
                                                                                 MPI_Comm communicator);

// One face of S between two cells. The normal is S's: it points out of `negative` into `positive`.
struct InterfaceCellFace {
  dealii::Triangulation<3>::active_cell_iterator negative;
  unsigned int negative_face = 0;
  dealii::Triangulation<3>::active_cell_iterator positive;  // may be a ghost cell
  unsigned int positive_face = 0;
  dealii::Tensor<1, 3> normal;  // unit
};

// The faces of `interface` whose negative cell this process owns, found by their corners (any
// numbering of vertices and cells). Every face of S is listed by exactly one rank; on a serial
// triangulation every face is listed, or InputError says how many were not found.
std::vector<InterfaceCellFace> interface_cell_faces(const dealii::Triangulation<3>& triangulation,
                                                    const DealiiInterface& interface);

}  // namespace meccano
