// The Gmsh MSH parser behind read_msh_triangles (io/surface_readers.hpp) and read_msh_mesh
// (io/msh_reader.hpp), which each take what they need from its result. No Gmsh library is involved.
//
// Input   a file's path (for messages) and bytes: MSH 2.2 or 4.1, ASCII or binary (native byte order,
//         8-byte data size); the element types to keep (types of known node count, e.g. 2 and 4).
// Output  an MshFile: every node; the elements of the kept types, their nodes resolved to points, each
//         with its physical tags (MSH 2.2: its first tag unless 0; MSH 4.1: its entity's, from
//         $Entities); the physical names. Other elements are skipped (by line in ASCII, by the node
//         count of their type in binary data), other sections too.
// Errors  InputError (io/byte_cursor.hpp) naming the file, the line or the byte offset and the defect:
//         not an MSH file, an unsupported version, file type or data size, another byte order,
//         malformed or truncated data, a missing $End, absurd counts, blocks that disagree with their
//         section header, a node tag defined twice, a non-finite coordinate, an element type of
//         unknown node count in binary data; naming the file and the element: a node not in $Nodes.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace meccano::readers {

struct MshElements {                // the elements of one type, in the file's order
  std::vector<std::uint64_t> tags;  // the file's element tags
  std::vector<int> vertices;        // the type's node count per element: indices into MshFile::points
  std::vector<int> physical;        // per element: its physical tags, an index into MshFile::physical_sets
};

struct MshFile {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::uint64_t> point_tags;                      // the file's node tags
  std::map<int, MshElements> elements;                        // by Gmsh element type: the kept types that occur
  std::vector<std::vector<int>> physical_sets;                // the lists of physical tags elements refer to; [0]: none
  std::map<std::pair<int, int>, std::string> physical_names;  // (dimension, physical tag) -> name
};

MshFile parse_msh_file(const std::string& path, std::string_view bytes, std::span<const int> kept_types);

}  // namespace meccano::readers
