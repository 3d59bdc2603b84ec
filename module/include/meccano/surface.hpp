// Triangulated surfaces to be immersed, and the readers that load them.
//
// Input   a file in OBJ, STL (ASCII or binary), OFF or Gmsh MSH 2.2/4.1 (triangles only), chosen by
//         the file's extension (case-insensitive).
// Output  a TriangleSurface: points and triangles, vertices duplicated within a tiny tolerance welded
//         (relative to the bounding-box diagonal), triangles keeping the file's orientation.
// Errors  InputError naming the file, the line (text formats) or the element, and the defect. A reader
//         checks the syntax and the index ranges only; the geometric and topological requirements of
//         the method (disk topology, no self-intersection, inside the box, ...) are checked by
//         surface_validation.hpp.
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace meccano {

struct TriangleSurface {
  std::string name;         // used in output group names, e.g. interface_NAME
  std::string source;       // file the surface came from (for messages); empty when built in code
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
};

// Reads a surface; the format follows the extension (.obj, .stl, .off, .msh).
TriangleSurface read_surface(const std::string& path);

TriangleSurface read_obj(const std::string& path);
TriangleSurface read_stl(const std::string& path);  // ASCII or binary, detected from the content
TriangleSurface read_off(const std::string& path);
TriangleSurface read_msh_triangles(const std::string& path);  // MSH 2.2 or 4.1, ASCII or binary

// Merges points closer than `tolerance` and renumbers the triangles; returns the number merged.
int weld_vertices(TriangleSurface& surface, double tolerance);

}  // namespace meccano
