// Mesh output with named, numbered groups, in the formats solvers and viewers read.
//
// Groups: named sets of tets (3D groups) and of faces (2D groups), each with a tag (its number), unique
// within its dimension. A face is given by a tet and its local face and is written with its normal
// pointing out of that tet, so the caller fixes each group's orientation; tets are written positively
// oriented. standard_groups() gives what every output carries, numbered as every writer of the project
// numbers it (doc/user_guide.md, "Tags"):
//   3D  `domain` 1 (all tets); other 3D groups (the stages' `volumetric_NAME`) 2, 3, ...
//   2D  the box sides `xmin` 1, `xmax` 2, `ymin` 3, `ymax` 4, `zmin` 5, `zmax` 6 (outward normals), and
//       `interface_NAME` 7, 8, ... for the surfaces in input order (= the face tags of mesh/tet_mesh.hpp).
// Group names may not be empty nor hold '"' or control characters; tags must be positive and unique per
// dimension; every tet and face of a group must exist (std::invalid_argument otherwise). Only elements
// of some group are written; every vertex is.
//
// The formats (write_mesh picks one from the file's extension) all carry the groups' own tags:
//   .msh   Gmsh MSH 4.1 ASCII (write_msh41, the default): physical groups with the groups' tags. Groups
//          may overlap (a tet in `domain` and in `volumetric_1`); elements are written once, in
//          entities that partition them by group membership, and every physical group is the union of
//          its entities.
//          Gmsh MSH 2.2 ASCII (write_msh22, for older readers): an element in several groups is written
//          once per group (Gmsh's convention), each group in an elementary entity of its own (entity
//          tag = physical tag), so that a reader counts every group's elements exactly.
//   .vtu   VTK XML UnstructuredGrid (write_vtu, for ParaView), little-endian, base64 binary arrays with
//          UInt64 headers (millions of tets): points Float64 x 3; cells are the tets of every 3D group
//          (VTK_TETRA), group by group, then the faces of every 2D group (VTK_TRIANGLE), an element once
//          per group like MSH 2.2; connectivity Int32, offsets Int64. Cell data:
//            group                Int32, the tag of the cell's group (tags are per dimension, as in
//                                 MSH: the cell type tells a tet of `domain` from a face of `xmin`);
//            quality_meccano      Float64, mean ratio of the tet against its computational (meccano)
//                                 counterpart (mesh/quality.hpp), negative for an inverted tet;
//            quality_equilateral  Float64, mean ratio against the equilateral tet;
//            both are 1 on triangles, a neutral value that never shows up among bad elements.
//          Field data: one Int32 array of 2 components per group, named like the group, holding its
//          tag and dimension (meshio's `field_data` convention).
//   .mesh  Medit ASCII (write_medit, MeshVersionFormatted 2): a tet once, with reference = the tag of
//          its first 3D group (`domain`: 1); a face once per 2D group, with reference = that group's tag.
//          Comment lines after the header name the references: `# Tetrahedra ref 1 domain`,
//          `# Triangles ref 7 interface_patch`.
// Node fields (optional): integer values per node, such as the `sequence` command's `previous_node`.
//   .msh   a $NodeData section per field after $Elements (both versions; Gmsh shows each as a view):
//          string tag the field's name, real tag the time 0, integer tags step 0, 1 component, the
//          node count; then one line per node: its tag and value.
//   .vtu   PointData, an Int64 array per field named like it.
//   .mesh  Medit holds no node data: write_mesh refuses node fields for it.
//   A field of node references (NodeField::node_references) holds nodes of some mesh, or a negative
//   value for none; each format writes them in its own node numbering (MSH's node tags, VTU's 0-based
//   point indices), and none as -1.
// Writes are atomic (io/atomic_file.hpp): a failed write leaves no file; InputError names the path.
#pragma once

#include <meccano/mesh/tet_mesh.hpp>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace meccano {

struct TetGroup {
  std::string name;
  int tag;  // unique among the 3D groups
  std::vector<TetId> tets;
};

struct FaceGroup {
  std::string name;
  int tag;  // unique among the 2D groups
  std::vector<FaceRef> faces;
};

struct MeshGroups {
  std::vector<TetGroup> volumes;
  std::vector<FaceGroup> surfaces;
};

// One value per node; the name follows the group names' rules (not empty, no '"' nor control characters).
struct NodeField {
  std::string name;
  std::vector<std::int64_t> values;
  bool node_references = false;  // values are VertexIds of some mesh (negative: none), renumbered per format
};

// `domain`, the six box sides, and `interface_NAME` for every interface tag in use, NAME taken from
// `interface_names` (index = interface index), numbered as above. Interface faces are oriented out of the tet on the side
// of the face where the tag was set first in tet order; stages that know the surface's normal build
// their own group instead.
MeshGroups standard_groups(const TetMesh& mesh, const std::vector<std::string>& interface_names = {});

void write_msh41(const TetMesh& mesh, const MeshGroups& groups, const std::string& path,
                 std::span<const NodeField> node_fields = {});
void write_msh22(const TetMesh& mesh, const MeshGroups& groups, const std::string& path,
                 std::span<const NodeField> node_fields = {});
void write_vtu(const TetMesh& mesh, const MeshGroups& groups, const std::string& path,
               std::span<const NodeField> node_fields = {});
void write_medit(const TetMesh& mesh, const MeshGroups& groups, const std::string& path);

enum class MeshFormat { msh, vtu, medit };
enum class MshVersion { v41, v22 };

struct MeshWriteOptions {
  MshVersion msh_version = MshVersion::v41;  // for .msh files
};

// The format of a file name's extension (.msh, .vtu, .mesh), or nothing for any other name.
std::optional<MeshFormat> mesh_format_of(const std::string& path);

// Writes with the writer of the path's extension. Throws InputError naming the path if the extension is
// not one of .msh, .vtu, .mesh, or if node fields are given for a .mesh file (nothing is written then).
void write_mesh(const TetMesh& mesh, const MeshGroups& groups, const std::string& path,
                const MeshWriteOptions& options = {}, std::span<const NodeField> node_fields = {});

}  // namespace meccano
