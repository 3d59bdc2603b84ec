// The measurements of `meccano-immerse measure FILE.msh`: one tool that measures any tetrahedral mesh in
// an MSH file (io/msh_reader.hpp), this module's, Gmsh's or TetGen's, the same way, so that their figures
// compare. It measures what is in the file; timings are the producers' own.
//
// Input   an MshMesh, and surfaces S (TriangleSurface) whose `name` picks the 2D group interface_NAME
//         each is compared with. A surface need not match every group, nor a group a surface. A surface
//         that reaches beyond the bounding box of the mesh's nodes is clipped to it first, as the insertion
//         clips it (surface/box_clipping.hpp; several parts are named NAME_1, NAME_2, ...).
// Output  a MeshMeasure:
//   nodes, tets   as in the file;
//   inverted      tets whose signed volume in the file's vertex order is not positive (or not finite);
//   quality       the equilateral mean ratio eta of every tet (mesh/quality.hpp: mean_ratio_equilateral),
//                 an inverted tet counting as 0, as in the module's own report (summarize_quality):
//                 min, mean, std (population) and the count of tets below 0.1, 0.2 and 0.3; the
//                 smallest and largest dihedral angle of the non-inverted tets (0 and 180 if none).
//                 The measure against the meccano counterpart needs computational coordinates that a
//                 foreign mesh lacks: it is left out;
//   interfaces    per 2D group interface_NAME, by physical tag: its face count and area, and when a
//                 surface S named NAME is given, its accuracy against S:
//     node distance    max and mean over the group's nodes of the distance to S (exact closest point,
//                      TriangleBVH::closest_point);
//     hausdorff        the two-sided Hausdorff distance between the group's triangles I and S: the
//                      larger of max_{x in I} d(x, S) and max_{y in S} d(y, I). Each one-sided sup is
//                      taken over samples: on every triangle the vertices of its subdivision into 64
//                      similar triangles (8 per edge: the vertices and edge midpoints of its subdivision
//                      into 16), 45 points spaced 1/8 of each edge apart, each with the exact closest
//                      point on the other side. Distance to a set is 1-Lipschitz, so a sampled value
//                      falls short of the true one by at most 1/8 of the triangle's longest edge, and
//                      is exact when the other side is a plane over the triangle;
//     normal deviation for each face of I, the angle between its unit normal (right-hand rule on the
//                      file's vertex order) and the normal of the triangle of S that holds the closest
//                      point of S to the face's centroid (at an edge or a vertex of S, one of the
//                      triangles there), as an angle between lines, in [0, 90] degrees: max and
//                      area-weighted mean. Orientation is reported apart: flipped_faces counts the faces
//                      whose normal points against S's (angle between the vectors above 90 degrees);
//     area_ratio       area of I / area of S.
//   text() for a terminal; json() for a report, with the keys
//     {"file", "nodes", "tets", "inverted",
//      "quality": {"equilateral": {"min", "mean", "std", "below_0.1", "below_0.2", "below_0.3"},
//                  "min_dihedral_deg", "max_dihedral_deg"},
//      "interfaces": [{"name" (interface_NAME), "faces", "area", and with a surface also "surface" (its
//                      file), "node_distance": {"max", "mean"}, "hausdorff",
//                      "normal_deviation_deg": {"max", "mean"}, "flipped_faces", "area_ratio"}]}
// Errors  InputError naming the mesh file and the surface when a surface's NAME has no interface_NAME
//         group (the message lists the groups there are), two surfaces share a name, or S or its group
//         has no triangles; the readers' InputError for a file that cannot be read.
// Deterministic for any number of OpenMP threads.
#pragma once

#include <meccano/io/msh_reader.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace meccano {

struct SurfaceAccuracy {
  std::string surface;  // S's file (TriangleSurface::source)
  double node_distance_max = 0, node_distance_mean = 0;
  double hausdorff = 0;
  double normal_deviation_max_deg = 0, normal_deviation_mean_deg = 0;  // mean weighted by face area
  std::int64_t flipped_faces = 0;
  double area_ratio = 0;
};

struct InterfaceMeasure {
  std::string name;  // the group's name, interface_NAME
  std::int64_t faces = 0;
  double area = 0;
  std::optional<SurfaceAccuracy> accuracy;  // when a surface named NAME was given
};

// JSON keys of the low-quality counts (mesh/quality.hpp: low_quality_thresholds).
inline constexpr std::array<const char*, 3> low_quality_keys{"below_0.1", "below_0.2", "below_0.3"};

struct MeshMeasure {
  std::string source;
  std::int64_t nodes = 0, tets = 0, inverted = 0;
  QualityStatistics equilateral;
  std::array<std::int64_t, 3> below{};  // tets with eta below each of low_quality_thresholds
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  std::vector<InterfaceMeasure> interfaces;

  const InterfaceMeasure* find(const std::string& name) const;  // by group name; nullptr if absent
  std::string text() const;
  std::string json() const;
};

MeshMeasure measure_msh_mesh(const MshMesh& mesh, std::span<const TriangleSurface> surfaces = {});

// The accuracy of an interface (its faces as a triangle surface, oriented like S) against S: what
// measure_msh_mesh reports for an interface group whose surface was given.
SurfaceAccuracy accuracy_against(const TriangleSurface& interface, const TriangleSurface& surface);

// read_msh_mesh then measure_msh_mesh.
MeshMeasure measure_mesh_file(const std::string& path, std::span<const TriangleSurface> surfaces = {});

}  // namespace meccano
