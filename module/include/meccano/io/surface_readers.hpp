// The readers that load a triangulated surface to be immersed (surface/triangle_surface.hpp).
//
// Input   a file in OBJ, STL (ASCII or binary), OFF, Gmsh MSH 2.2/4.1 (triangles only) or GOCAD TSurf,
//         chosen by the file's extension (case-insensitive).
// Output  a TriangleSurface: points and triangles, vertices duplicated within a tolerance welded,
//         triangles keeping the file's orientation and the file's coordinates (a TSurf's z as written,
//         whether its ZPOSITIVE is Elevation or Depth).
// Welding The default tolerance is tiny (1e-10 of the bounding-box diagonal) and drops nothing: a
//         degenerate or repeated triangle is left for the validation to report. A TSurf file, whose
//         coincident vertices may lie up to a metre apart, is welded at 1 m in its AXIS_UNIT (1e-6 of the
//         diagonal when the unit is missing or unknown); so is any file given a weld_tolerance. Such a
//         weld then drops the triangles it collapsed and the repeats of a triangle, and counts them.
// Parts   the triangles joined through shared edges. A TSurf file of several parts is not one surface:
//         read_surface refuses it, naming the parts; read_surface_parts returns them (any format).
// Errors  InputError naming the file, the line (text formats), the byte offset (binary MSH data) or the
//         element, and the defect. A reader checks the syntax and the index ranges only; the geometric
//         and topological requirements of the method (disk topology, no self-intersection, inside the
//         box, ...) are checked by surface/validation.hpp.
#pragma once

#include <meccano/surface/triangle_surface.hpp>

#include <optional>
#include <string>
#include <vector>

namespace meccano {

struct SurfaceReadOptions {
  // Absolute, in the file's units: overrides the format's default weld (see above). Finite, >= 0.
  std::optional<double> weld_tolerance;
};

// What welding did to a file (zero when it was clean).
struct SurfaceReadReport {
  int welded_vertices = 0;       // merged into a vertex at another position (exact repeats not counted)
  int degenerate_triangles = 0;  // dropped: two corners welded together
  int duplicate_triangles = 0;   // dropped: the same three vertices as an earlier triangle
};

// Reads a surface; the format follows the extension (.obj, .stl, .off, .msh, .ts). `report`, if
// given, receives what welding did.
TriangleSurface read_surface(const std::string& path, const SurfaceReadOptions& options = {},
                             SurfaceReadReport* report = nullptr);
// The parts of a surface file, each a surface named STEM_1, STEM_2, ... (STEM: the file's name
// without its extension), in the order of their first triangles in the file; welded as read_surface.
std::vector<TriangleSurface> read_surface_parts(const std::string& path, const SurfaceReadOptions& options = {},
                                                SurfaceReadReport* report = nullptr);

TriangleSurface read_obj(const std::string& path);
TriangleSurface read_stl(const std::string& path);  // ASCII or binary, detected from the content
TriangleSurface read_off(const std::string& path);
TriangleSurface read_msh_triangles(const std::string& path);  // MSH 2.2 or 4.1, ASCII or binary
TriangleSurface read_tsurf(const std::string& path);          // GOCAD TSurf, one or more objects, of one part

// Merges points closer than `tolerance` and renumbers the triangles; returns the number merged.
int weld_vertices(TriangleSurface& surface, double tolerance);

}  // namespace meccano
