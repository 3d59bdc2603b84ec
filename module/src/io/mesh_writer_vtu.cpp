// VTK XML UnstructuredGrid: base64 binary arrays, each preceded by its byte count (UInt64), all
// little-endian; the layout is described in io/mesh_writers.hpp.
#include <meccano/io/mesh_writers.hpp>

#include "io/writer_helpers.hpp"

#include <meccano/io/atomic_file.hpp>
#include <meccano/mesh/quality.hpp>

#include <algorithm>
#include <bit>
#include <cstring>
#include <string_view>
#include <type_traits>

namespace meccano {
namespace {

constexpr std::uint8_t vtk_triangle = 5;
constexpr std::uint8_t vtk_tetra = 10;
constexpr double triangle_quality = 1.0;  // neutral: never among the bad elements

// Base64 of little-endian values, encoded as they come: an array of millions of cells is never copied
// whole into memory.
class Base64Writer {
 public:
  explicit Base64Writer(std::ostream& out) : out_(out) {}

  template <class T>
  void put(T value) {
    if (size_ + sizeof(T) > raw_.size()) encode(false);
    unsigned char* bytes = raw_.data() + size_;
    std::memcpy(bytes, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
    size_ += sizeof(T);
  }
  // Encodes what is left, padding the last group.
  void finish() { encode(true); }

 private:
  // Whole groups of 3 bytes become 4 characters; the remainder waits for more bytes unless `last`.
  void encode(bool last) {
    static constexpr std::string_view alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string text;
    text.reserve((size_ + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 3 <= size_; i += 3) {
      const std::uint32_t bits = std::uint32_t{raw_[i]} << 16 | std::uint32_t{raw_[i + 1]} << 8 | raw_[i + 2];
      for (int shift = 18; shift >= 0; shift -= 6) text += alphabet[bits >> shift & 63];
    }
    const std::size_t rest = size_ - i;
    if (last && rest > 0) {
      const std::uint32_t bits = std::uint32_t{raw_[i]} << 16 | (rest == 2 ? std::uint32_t{raw_[i + 1]} << 8 : 0);
      text += alphabet[bits >> 18 & 63];
      text += alphabet[bits >> 12 & 63];
      text += rest == 2 ? alphabet[bits >> 6 & 63] : '=';
      text += '=';
      i = size_;
    }
    out_ << text;
    std::memmove(raw_.data(), raw_.data() + i, size_ - i);
    size_ -= i;
  }

  std::ostream& out_;
  std::array<unsigned char, 3 << 14> raw_{};
  std::size_t size_ = 0;
};

template <class T>
constexpr std::string_view vtk_type_name() {
  if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
  if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  if constexpr (std::is_same_v<T, double>) return "Float64";
}

// A binary DataArray of `count` values of type T, which fill(put) passes to put one by one.
template <class T, class Fill>
void write_data_array(std::ostream& out, std::string_view attributes, std::int64_t count, Fill&& fill) {
  out << "<DataArray type=\"" << vtk_type_name<T>() << "\" " << attributes << " format=\"binary\">\n";
  Base64Writer data(out);
  data.put(static_cast<std::uint64_t>(count) * sizeof(T));
  fill([&data](T value) { data.put(value); });
  data.finish();
  out << "\n</DataArray>\n";
}

std::string xml_escaped(std::string_view text) {
  std::string escaped;
  for (const char c : text) {
    if (c == '&') escaped += "&amp;";
    else if (c == '<') escaped += "&lt;";
    else if (c == '>') escaped += "&gt;";
    else escaped += c;
  }
  return escaped;
}

}  // namespace

void write_vtu(const TetMesh& mesh, const MeshGroups& groups, const std::string& path,
               std::span<const NodeField> node_fields) {
  mesh_io::check_groups(mesh, groups);
  mesh_io::check_node_fields(mesh, node_fields);
  std::vector<double> meccano_quality(mesh.tets.size()), equilateral_quality(mesh.tets.size());
#pragma omp parallel for schedule(static)
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    const TetPoints p = oriented_points(mesh, t);
    meccano_quality[t] = mean_ratio_meccano(mesh, t);
    equilateral_quality[t] = mean_ratio_equilateral(p);
  }
  const std::int64_t tets = mesh_io::group_tet_count(groups);
  const std::int64_t triangles = mesh_io::group_triangle_count(groups);

  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
           "<!-- meccano-immerse: cell data `group` holds the tag of each cell's group; the field data name the "
           "groups (tag, dimension), tags being per dimension as in MSH; tets of the 3D groups come first, then "
           "the triangles of the 2D groups, an element once per group it is in; "
           "quality_meccano and quality_equilateral are 1 on triangles. -->\n"
           "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
           "<UnstructuredGrid>\n<FieldData>\n";
    auto name_group = [&out](const std::string& name, int tag, int dimension) {
      out << "<DataArray type=\"Int32\" Name=\"" << xml_escaped(name)
          << "\" NumberOfComponents=\"2\" NumberOfTuples=\"1\" format=\"ascii\">" << tag << ' ' << dimension
          << "</DataArray>\n";
    };
    for (const TetGroup& group : groups.volumes) name_group(group.name, group.tag, 3);
    for (const FaceGroup& group : groups.surfaces) name_group(group.name, group.tag, 2);
    out << "</FieldData>\n<Piece NumberOfPoints=\"" << mesh.num_vertices() << "\" NumberOfCells=\"" << tets + triangles
        << "\">\n<Points>\n";
    write_data_array<double>(out, "Name=\"Points\" NumberOfComponents=\"3\"", 3 * std::int64_t{mesh.num_vertices()},
                             [&](auto put) {
      for (const auto& p : mesh.points) {
        put(p.x());
        put(p.y());
        put(p.z());
      }
    });

    out << "</Points>\n<Cells>\n";
    // Cell-wise arrays: tets value, triangles value, or per element of the traversal.
    auto per_cell = [&](auto tet_value, auto triangle_value) {
      return [&, tet_value, triangle_value](auto put) {
        mesh_io::for_each_group_tet(mesh, groups, [&](int group, TetId t, const auto&) { put(tet_value(group, t)); });
        mesh_io::for_each_group_triangle(mesh, groups, [&](int group, const auto&) { put(triangle_value(group)); });
      };
    };
    static_assert(std::is_same_v<VertexId, std::int32_t>, "connectivity is written as Int32");
    write_data_array<std::int32_t>(out, "Name=\"connectivity\"", 4 * tets + 3 * triangles, [&](auto put) {
      mesh_io::for_each_group_tet(mesh, groups, [&](int, TetId, const auto& tet) {
        for (const VertexId v : tet) put(v);
      });
      mesh_io::for_each_group_triangle(mesh, groups, [&](int, const auto& face) {
        for (const VertexId v : face) put(v);
      });
    });
    std::int64_t end = 0;
    write_data_array<std::int64_t>(out, "Name=\"offsets\"", tets + triangles,
                                   per_cell([&](int, TetId) { return end += 4; }, [&](int) { return end += 3; }));
    write_data_array<std::uint8_t>(out, "Name=\"types\"", tets + triangles,
                                   per_cell([](int, TetId) { return vtk_tetra; }, [](int) { return vtk_triangle; }));

    out << "</Cells>\n<CellData Scalars=\"group\">\n";
    write_data_array<std::int32_t>(out, "Name=\"group\"", tets + triangles,
                                   per_cell([](int tag, TetId) { return tag; }, [](int tag) { return tag; }));
    write_data_array<double>(
        out, "Name=\"quality_meccano\"", tets + triangles,
        per_cell([&](int, TetId t) { return meccano_quality[t]; }, [](int) { return triangle_quality; }));
    write_data_array<double>(
        out, "Name=\"quality_equilateral\"", tets + triangles,
        per_cell([&](int, TetId t) { return equilateral_quality[t]; }, [](int) { return triangle_quality; }));
    out << "</CellData>\n<PointData>\n";
    for (const NodeField& field : node_fields)
      write_data_array<std::int64_t>(out, "Name=\"" + xml_escaped(field.name) + "\"", mesh.num_vertices(),
                                     [&](auto put) {
        for (const std::int64_t value : field.values) put(mesh_io::written_value(field, value, 0));
      });
    out << "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  });
}

}  // namespace meccano
