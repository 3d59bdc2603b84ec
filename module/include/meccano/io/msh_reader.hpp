// A reader of tetrahedral meshes in Gmsh MSH files, whatever wrote them (this module, Gmsh, TetGen via
// Gmsh), for the invariant checker (inspect/mesh_file_check.hpp). No Gmsh library is involved.
//
// Input   a Gmsh MSH 2.2 or 4.1 file, ASCII or binary (native byte order, 8-byte data size).
// Output  an MshMesh: every node; the 4-node tets (element type 4) and 3-node triangles (type 2), other
//         element types skipped; the physical groups of dimension 3 and 2 with their names ($PhysicalNames)
//         and elements (MSH 2.2: an element's first tag; MSH 4.1: the physical tags of its entity in
//         $Entities). MSH 2.2 writes an element once per group it is in, so a record with the nodes of an
//         earlier element of another group is merged into it; repeated in the same group (or with no
//         group) it stays a separate element, a defect that the checks report.
// Errors  InputError naming the file, where (the line in ASCII data, the byte offset in binary data) and
//         the defect: unsupported version, malformed or truncated data, absurd counts (checked against
//         the bytes left before anything is allocated), a node tag defined twice or undefined, a
//         non-finite coordinate, a file without tets.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace meccano {

struct MshGroup {
  int dimension = 0;          // 3: tets, 2: triangles
  int tag = 0;                // physical tag
  std::string name;           // empty if $PhysicalNames does not name it
  std::vector<int> elements;  // indices into MshMesh::tets or MshMesh::triangles, increasing
};

struct MshMesh {
  std::string source;  // the file, for messages
  std::vector<Eigen::Vector3d> points;
  std::vector<std::uint64_t> point_tags;  // the file's node tags
  std::vector<std::array<int, 4>> tets;   // indices into points, in the file's vertex order
  std::vector<std::uint64_t> tet_tags;    // the file's element tags
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::uint64_t> triangle_tags;
  std::vector<MshGroup> groups;  // sorted by dimension, then tag
};

MshMesh read_msh_mesh(const std::string& path);

}  // namespace meccano
