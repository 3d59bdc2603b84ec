// What the mesh writers share: fast text output, the check of the groups, and the traversal of the
// groups' elements with their vertices in the order files expect (tets positively oriented, faces
// oriented out of their tet).
#pragma once

#include <meccano/io/mesh_writers.hpp>

#include <array>
#include <charconv>
#include <cstdint>
#include <ostream>
#include <string_view>

namespace meccano::mesh_io {

// Fast text output of numbers: meshes of millions of tets are written as ASCII. Doubles are written in
// the shortest form that reads back to the same value.
class TextWriter {
 public:
  explicit TextWriter(std::ostream& out) : out_(out) {}
  ~TextWriter() { flush(); }
  TextWriter(const TextWriter&) = delete;
  TextWriter& operator=(const TextWriter&) = delete;

  TextWriter& operator<<(std::int64_t value) { return put_number(value); }
  TextWriter& operator<<(int value) { return put_number(value); }
  TextWriter& operator<<(double value) { return put_number(value); }
  TextWriter& operator<<(char c) {
    reserve(1);
    buffer_[size_++] = c;
    return *this;
  }
  TextWriter& operator<<(std::string_view text) {
    flush();
    out_ << text;
    return *this;
  }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(size_));
    size_ = 0;
  }

 private:
  template <class T>
  TextWriter& put_number(T value) {
    reserve(32);
    const auto result = std::to_chars(buffer_.data() + size_, buffer_.data() + buffer_.size(), value);
    size_ = static_cast<std::size_t>(result.ptr - buffer_.data());
    return *this;
  }
  void reserve(std::size_t n) {
    if (size_ + n > buffer_.size()) flush();
  }
  std::ostream& out_;
  std::array<char, 1 << 16> buffer_{};
  std::size_t size_ = 0;
};

// Throws std::invalid_argument naming the group and the element if a tet or face does not exist, or the
// group's name cannot be written in every format.
void check_groups(const TetMesh& mesh, const MeshGroups& groups);

// std::invalid_argument unless every field has a valid name and one value per node of `mesh`.
void check_node_fields(const TetMesh& mesh, std::span<const NodeField> node_fields);

// A field's value as written in a format whose first node is numbered `first_node` (MSH 1, VTU 0).
inline std::int64_t written_value(const NodeField& field, std::int64_t value, std::int64_t first_node) {
  if (!field.node_references) return value;
  return value < 0 ? -1 : value + first_node;
}

// Elements counted once per group they are in.
std::int64_t group_tet_count(const MeshGroups& groups);
std::int64_t group_triangle_count(const MeshGroups& groups);

// visit(group tag, tet, positively oriented vertices) for every tet of every 3D group, group by group.
template <class Visit>
void for_each_group_tet(const TetMesh& mesh, const MeshGroups& groups, Visit&& visit) {
  for (const TetGroup& group : groups.volumes)
    for (const TetId t : group.tets) visit(group.tag, t, mesh.oriented_tet(t));
}

// visit(group tag, vertices oriented out of the face's tet) for every face of every 2D group.
template <class Visit>
void for_each_group_triangle(const TetMesh& mesh, const MeshGroups& groups, Visit&& visit) {
  for (const FaceGroup& group : groups.surfaces)
    for (const FaceRef& face : group.faces) visit(group.tag, mesh.outward_face(face.tet, face.local_face));
}

}  // namespace meccano::mesh_io
