// A tetrahedral mesh with one immersed surface, as the demo solver takes it, whatever made it.
//
// Sources  the module in the same process (interface_mesh_from_insertion), or an MSH file written by
//          the module, Gmsh or any other mesher (read_interface_mesh): its linear tets (all of them,
//          whatever their groups) and the triangles of the 2D physical group `interface_NAME`. The file
//          is read with the Gmsh C++ API, not with deal.II's MSH readers, which refuse a physical group
//          on interior faces.
// Output   points, positively oriented tets (what deal.II expects), and the interface triangles as
//          vertex triples, each an interior face of the mesh.
// Invariants (read_interface_mesh checks them and throws InputError naming the file, the element
//          and the defect): at least one tet, only linear tets, no degenerate tet, every point used by a
//          tet, no face shared by more than two tets, every interface triangle shared by two tets.
//          An element repeated with the same vertices is taken once (MSH 2.2 repeats an element in
//          every physical group it belongs to).
#pragma once

#include <meccano/pipeline.hpp>

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace solver_demo {

struct InterfaceMesh {
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<unsigned int, 4>> tets;       // positively oriented
  std::vector<std::array<unsigned int, 3>> interface;  // triangles of S, interior faces
  std::string interface_name;                          // NAME of interface_NAME
};

// The whole mesh of an insertion and the faces of its surface `surface_index`, oriented like it.
InterfaceMesh interface_mesh_from_insertion(const meccano::InsertionResult& result, int surface_index = 0);

// `interface_name` empty: the file's only group interface_NAME (an error if there are none or several).
InterfaceMesh read_interface_mesh(const std::string& path, const std::string& interface_name = "");

double interface_area(const InterfaceMesh& mesh);

// The interface triangles as a VTU file (atomic write) with one value per triangle for each field.
using TriangleField = std::pair<std::string, std::vector<double>>;
void write_interface_vtu(const InterfaceMesh& mesh, const std::vector<TriangleField>& fields, const std::string& path);

}  // namespace solver_demo
