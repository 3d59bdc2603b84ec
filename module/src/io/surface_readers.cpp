// Surface readers (OBJ, STL, OFF, Gmsh MSH, GOCAD TSurf), vertex welding and the parts of a surface.
//
// Every reader loads the whole file, parses it with a ByteCursor (io/byte_cursor.hpp), and hands
// the raw points and triangles to finish_surface, which welds the duplicated vertices, drops the
// triangles a deliberate weld collapsed, and drops the unused vertices. Header counts are checked
// against the bytes left in the file before anything is allocated from them, so a corrupt count
// yields an error instead of a bad_alloc.
#include <meccano/error.hpp>
#include <meccano/io/surface_readers.hpp>

#include "io/byte_cursor.hpp"
#include "io/msh_parser.hpp"
#include "mesh/topology_helpers.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <utility>

namespace meccano {
namespace {

using readers::ByteCursor;
using readers::iequals;
using readers::quoted;
using readers::read_file_bytes;
using readers::Token;
using Triangle = std::array<int, 3>;

[[noreturn]] void fail_file(const std::string& path, const std::string& defect) {
  throw InputError(path + ": " + defect);
}

// Diagonal of the bounding box of the vertices that triangles use (an OBJ file may hold others).
double used_bounding_box_diagonal(const TriangleSurface& surface) {
  Eigen::Vector3d lo = surface.points[static_cast<std::size_t>(surface.triangles[0][0])];
  Eigen::Vector3d hi = lo;
  for (const Triangle& triangle : surface.triangles)
    for (const int vertex : triangle) {
      lo = lo.cwiseMin(surface.points[static_cast<std::size_t>(vertex)]);
      hi = hi.cwiseMax(surface.points[static_cast<std::size_t>(vertex)]);
    }
  return (hi - lo).stableNorm();
}

// The points that `triangles` use, in their order in `points` (messages number them), the triangles
// renumbered to them. Sorting, not marking, costs a part of a surface only its own size.
std::vector<Eigen::Vector3d> used_vertices(const std::vector<Eigen::Vector3d>& points,
                                           std::vector<Triangle>& triangles) {
  std::vector<int> used;
  used.reserve(3 * triangles.size());
  for (const Triangle& triangle : triangles) used.insert(used.end(), triangle.begin(), triangle.end());
  std::ranges::sort(used);
  used.erase(std::unique(used.begin(), used.end()), used.end());
  for (Triangle& triangle : triangles)
    for (int& vertex : triangle) vertex = static_cast<int>(std::ranges::lower_bound(used, vertex) - used.begin());
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(used.size());
  for (const int vertex : used) kept.push_back(points[static_cast<std::size_t>(vertex)]);
  return kept;
}

// How a reader welds: within `tolerance` when it is set, else within `relative` times the bounding-box
// diagonal. A deliberate weld (`drop_collapsed`) merges vertices that the file keeps apart, so the
// triangles it collapses or makes repeat another are its doing and are dropped; the tiny default
// weld leaves such triangles to the validation, which reports them as defects of the file.
struct Weld {
  std::optional<double> tolerance;
  double relative = 0.0;
  bool drop_collapsed = false;
};

constexpr Weld kTinyWeld{std::nullopt, 1e-10, false};

// What a reader is asked for, and what it reports.
struct ReadContext {
  SurfaceReadOptions options;
  SurfaceReadReport report;
};

// Drops the triangles with two equal corners and the repeats of an earlier triangle (the same three
// vertices, in either orientation), counting both; `tags`, one per triangle, follow the kept ones.
void drop_collapsed_triangles(TriangleSurface& surface, SurfaceReadReport& report, std::vector<int>* tags) {
  std::set<Triangle> seen;
  std::size_t kept = 0;
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const Triangle triangle = surface.triangles[t];
    Triangle sorted = triangle;
    std::ranges::sort(sorted);
    if (sorted[0] == sorted[1] || sorted[1] == sorted[2]) {
      ++report.degenerate_triangles;
    } else if (!seen.insert(sorted).second) {
      ++report.duplicate_triangles;
    } else {
      if (tags) (*tags)[kept] = (*tags)[t];
      surface.triangles[kept++] = triangle;
    }
  }
  surface.triangles.resize(kept);
  if (tags) tags->resize(kept);
}

// The common end of every reader: the raw data has finite coordinates and in-range indices. The
// user's weld tolerance, if any, replaces the format's `weld`; `tags`, one per triangle, follow the
// triangles kept.
TriangleSurface finish_surface(const std::string& path, std::vector<Eigen::Vector3d> points,
                               std::vector<Triangle> triangles, ReadContext& context,
                               const Weld& format_weld = kTinyWeld, std::vector<int>* tags = nullptr) {
  if (triangles.empty()) fail_file(path, "no triangles in the file");
  TriangleSurface surface;
  surface.name = std::filesystem::path(path).stem().string();
  surface.source = path;
  surface.points = std::move(points);
  surface.triangles = std::move(triangles);
  const double diagonal = used_bounding_box_diagonal(surface);
  if (!std::isfinite(diagonal))
    fail_file(path, "coordinates too far apart: the extent of the surface overflows a double");
  const Weld weld = context.options.weld_tolerance ? Weld{context.options.weld_tolerance, 0.0, true} : format_weld;
  // Exact repeats first, uncounted: they are how an STL file shares its vertices (about six times
  // each), and merging them leaves fewer vertices to scan.
  weld_vertices(surface, 0.0);
  context.report.welded_vertices = weld_vertices(surface, weld.tolerance.value_or(weld.relative * diagonal));
  if (weld.drop_collapsed) {
    drop_collapsed_triangles(surface, context.report, tags);
    if (surface.triangles.empty())
      fail_file(path, "no triangles left after welding: all " + std::to_string(context.report.degenerate_triangles) +
                          " collapsed");
  }
  surface.points = used_vertices(surface.points, surface.triangles);
  return surface;
}

// Splits a convex polygon into a fan around its first vertex, keeping its orientation.
void add_polygon(const std::vector<int>& polygon, std::vector<Triangle>& triangles) {
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) triangles.push_back({polygon[0], polygon[i], polygon[i + 1]});
}

// The valid vertex indices, for messages.
std::string index_range(long long first, long long count) {
  if (count == 0) return "the file defines no vertices";
  return std::to_string(first) + ".." + std::to_string(first + count - 1);
}

// ---------------------------------------------------------------------------------------------- OBJ

TriangleSurface parse_obj(const std::string& path, std::string_view bytes, ReadContext& context) {
  ByteCursor cursor(path, bytes, '#');
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> triangles;
  std::vector<int> triangle_lines;  // positive indices may refer to later vertices: checked at the end
  std::vector<int> polygon;
  while (const std::optional<Token> keyword = cursor.next_token()) {
    if (keyword->text == "v") {
      Eigen::Vector3d p;
      for (int axis = 0; axis < 3; ++axis)
        p[axis] = cursor.coordinate(cursor.expect_token_on_line("vertex coordinate"));
      points.push_back(p);
    } else if (keyword->text == "f") {
      polygon.clear();
      while (const std::optional<Token> corner = cursor.next_token_on_line()) {
        // i, i/j, i//k, i/j/k: only the vertex index matters.
        const Token index_token{corner->text.substr(0, corner->text.find('/')), corner->line};
        const long long index = cursor.integer(index_token, "vertex index");
        const long long defined = static_cast<long long>(points.size());
        if (index == 0) cursor.fail_at(corner->line, "vertex index 0 out of range (OBJ indices start at 1)");
        if (index < -defined)
          cursor.fail_at(corner->line, "vertex index " + std::to_string(index) + " out of range (-" +
                                           std::to_string(defined) + "..-1 with " + std::to_string(defined) +
                                           " vertices defined so far)");
        if (index > std::numeric_limits<int>::max())
          cursor.fail_at(corner->line, "vertex index " + std::to_string(index) + " out of range");
        polygon.push_back(static_cast<int>(index < 0 ? defined + index : index - 1));
      }
      if (polygon.size() < 3)
        cursor.fail_at(keyword->line, "face with " + std::to_string(polygon.size()) + " vertices (at least 3 needed)");
      add_polygon(polygon, triangles);
      triangle_lines.resize(triangles.size(), keyword->line);
    }
    // vt, vn, g, o, s, usemtl, mtllib, l, p and the rest do not describe the surface.
    cursor.skip_line();
  }
  const int vertex_count = static_cast<int>(points.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const int vertex : triangles[t])
      if (vertex >= vertex_count)
        cursor.fail_at(triangle_lines[t], "vertex index " + std::to_string(vertex + 1) + " out of range (" +
                                              index_range(1, vertex_count) + ")");
  return finish_surface(path, std::move(points), std::move(triangles), context);
}

// ---------------------------------------------------------------------------------------------- STL

constexpr std::size_t kStlHeaderBytes = 84;  // 80-byte header + uint32 triangle count
constexpr std::size_t kStlRecordBytes = 50;  // normal, 3 vertices (12 floats) + uint16 attribute

// Little-endian uint32 triangle count of a binary STL.
std::uint64_t binary_stl_count(std::string_view bytes) {
  std::uint64_t count = 0;
  for (std::size_t i = 4; i-- > 0;) count = (count << 8) | static_cast<unsigned char>(bytes[80 + i]);
  return count;
}

bool starts_with_solid(std::string_view bytes) {
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  return start != std::string_view::npos && iequals(bytes.substr(start, 5), "solid");
}

// A binary header and count almost always hold control characters; text never does.
bool looks_like_text(std::string_view bytes) {
  return std::ranges::none_of(bytes.substr(0, 512), [](char ch) {
    const auto code = static_cast<unsigned char>(ch);
    return code < 0x20 && !std::isspace(code);
  });
}

TriangleSurface parse_binary_stl(const std::string& path, std::string_view bytes, ReadContext& context) {
  const std::uint64_t count = binary_stl_count(bytes);
  const std::uint64_t expected = kStlHeaderBytes + kStlRecordBytes * count;
  if (expected != bytes.size())
    fail_file(path, "binary STL header announces " + std::to_string(count) + " triangles, which need " +
                        std::to_string(expected) + " bytes, but the file has " + std::to_string(bytes.size()) +
                        " bytes" +
                        (expected > bytes.size() ? " (truncated file or corrupt triangle count)"
                                                 : " (unexpected data after the last triangle)"));
  if (count > std::numeric_limits<int>::max() / 3)
    fail_file(path, std::to_string(count) + " triangles: more than a surface can hold");
  ByteCursor cursor(path, bytes);
  cursor.skip_bytes(kStlHeaderBytes, "header");
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> triangles;
  points.reserve(3 * count);  // count checked against the file size above
  triangles.reserve(count);
  for (std::uint64_t t = 0; t < count; ++t) {
    cursor.skip_bytes(12, "normal");  // recomputed from the vertices wherever needed
    const int first = static_cast<int>(points.size());
    for (int corner = 0; corner < 3; ++corner) {
      Eigen::Vector3d p;
      for (int axis = 0; axis < 3; ++axis) p[axis] = cursor.binary<float>("vertex", std::endian::little);
      if (!p.allFinite()) fail_file(path, "element " + std::to_string(t + 1) + ": non-finite coordinate");
      points.push_back(p);
    }
    cursor.skip_bytes(2, "attribute");
    triangles.push_back({first, first + 1, first + 2});
  }
  return finish_surface(path, std::move(points), std::move(triangles), context);
}

TriangleSurface parse_ascii_stl(const std::string& path, std::string_view bytes, ReadContext& context) {
  ByteCursor cursor(path, bytes);
  std::vector<Eigen::Vector3d> points;
  std::vector<Triangle> triangles;
  cursor.expect_keyword("solid");
  cursor.skip_line();  // the solid's name
  while (true) {
    const Token token = cursor.expect_token("'facet' or 'endsolid'");
    if (iequals(token.text, "endsolid")) {
      cursor.skip_line();  // the solid's name
      const std::optional<Token> next = cursor.next_token();
      if (!next) break;
      // Some exporters write one solid per part into the same file.
      if (!iequals(next->text, "solid"))
        cursor.fail_at(next->line,
                       "expected 'solid' or the end of the file after 'endsolid', found " + quoted(next->text));
      cursor.skip_line();
      continue;
    }
    if (!iequals(token.text, "facet"))
      cursor.fail_at(token.line, "expected 'facet' or 'endsolid', found " + quoted(token.text));
    Token next = cursor.expect_token("'normal' or 'outer'");
    if (iequals(next.text, "normal")) {
      for (int axis = 0; axis < 3; ++axis) cursor.number(cursor.expect_token("normal component"), "normal component");
      next = cursor.expect_token("'outer'");
    }
    if (!iequals(next.text, "outer")) cursor.fail_at(next.line, "expected 'outer', found " + quoted(next.text));
    cursor.expect_keyword("loop");
    const int first = static_cast<int>(points.size());
    for (int corner = 0; corner < 3; ++corner) {
      cursor.expect_keyword("vertex");
      Eigen::Vector3d p;
      for (int axis = 0; axis < 3; ++axis) p[axis] = cursor.coordinate(cursor.expect_token("vertex coordinate"));
      points.push_back(p);
    }
    cursor.expect_keyword("endloop");
    cursor.expect_keyword("endfacet");
    triangles.push_back({first, first + 1, first + 2});
  }
  return finish_surface(path, std::move(points), std::move(triangles), context);
}

TriangleSurface parse_stl(const std::string& path, std::string_view bytes, ReadContext& context) {
  const bool binary_size =
      bytes.size() >= kStlHeaderBytes && bytes.size() == kStlHeaderBytes + kStlRecordBytes * binary_stl_count(bytes);
  if (!binary_size && looks_like_text(bytes)) {
    if (!starts_with_solid(bytes)) fail_file(path, "not an STL file: text that does not start with 'solid'");
    return parse_ascii_stl(path, bytes, context);
  }
  if (bytes.size() < kStlHeaderBytes)
    fail_file(path, "not an STL file: " + std::to_string(bytes.size()) +
                        " bytes, too short for a binary STL (at least 84 bytes)");
  return parse_binary_stl(path, bytes, context);
}

// ---------------------------------------------------------------------------------------------- OFF

// "OFF" with the optional per-vertex prefixes ST (texture), C (colour), N (normal), whose values follow
// the coordinates and are skipped; "4OFF" and "nOFF" are not 3D surfaces.
bool is_off_keyword(std::string_view text) {
  return text.size() >= 3 && text.ends_with("OFF") &&
         text.substr(0, text.size() - 3).find_first_not_of("STCN") == std::string_view::npos;
}

TriangleSurface parse_off(const std::string& path, std::string_view bytes, ReadContext& context) {
  ByteCursor cursor(path, bytes, '#');
  const Token header = cursor.expect_token("'OFF' header");
  if (!is_off_keyword(header.text))
    cursor.fail_at(header.line, "expected the 'OFF' header, found " + quoted(header.text));
  std::optional<Token> vertex_token = cursor.next_token_on_line();  // counts may follow the keyword
  if (!vertex_token) vertex_token = cursor.expect_token("vertex count");
  const long long vertex_count = cursor.integer(*vertex_token, "vertex count");
  const Token face_token = cursor.expect_token_on_line("face count");
  const long long face_count = cursor.integer(face_token, "face count");
  if (vertex_count < 0 || face_count < 0) cursor.fail_at(face_token.line, "negative vertex or face count");
  // A vertex line holds at least 3 numbers (5 bytes), a face line at least 4 (7 bytes).
  cursor.check_count(static_cast<std::uint64_t>(vertex_count), 5, "vertex");
  cursor.check_count(static_cast<std::uint64_t>(face_count), 7, "face");
  cursor.skip_line();  // the edge count, unused

  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(vertex_count));
  for (long long v = 0; v < vertex_count; ++v) {
    Eigen::Vector3d p;
    p[0] = cursor.coordinate(cursor.expect_token("vertex coordinate"));
    for (int axis = 1; axis < 3; ++axis) p[axis] = cursor.coordinate(cursor.expect_token_on_line("vertex coordinate"));
    points.push_back(p);
    cursor.skip_line();  // texture coordinates, colour, normal
  }
  std::vector<Triangle> triangles;
  std::vector<int> polygon;
  for (long long f = 0; f < face_count; ++f) {
    const Token size_token = cursor.expect_token("face vertex count");
    const long long size = cursor.integer(size_token, "face vertex count");
    if (size < 3)
      cursor.fail_at(size_token.line, "face with " + std::to_string(size) + " vertices (at least 3 needed)");
    polygon.clear();
    for (long long k = 0; k < size; ++k) {
      const Token index_token = cursor.expect_token_on_line("vertex index");
      const long long index = cursor.integer(index_token, "vertex index");
      if (index < 0 || index >= vertex_count)
        cursor.fail_at(index_token.line, "vertex index " + std::to_string(index) + " out of range (" +
                                             index_range(0, vertex_count) + ")");
      polygon.push_back(static_cast<int>(index));
    }
    add_polygon(polygon, triangles);
    cursor.skip_line();  // colour
  }
  return finish_surface(path, std::move(points), std::move(triangles), context);
}

// ---------------------------------------------------------------------------------------------- MSH

constexpr int kGmshTriangle = 2;  // element type of the 3-node triangle

// Gmsh MSH 2.2 and 4.1 (io/msh_parser.hpp): the 3-node triangles; other elements are ignored.
TriangleSurface parse_msh(const std::string& path, std::string_view bytes, ReadContext& context) {
  constexpr std::array<int, 1> kKept{kGmshTriangle};
  readers::MshFile file = readers::parse_msh_file(path, bytes, kKept);
  const auto found = file.elements.find(kGmshTriangle);
  if (found == file.elements.end()) fail_file(path, "no triangles (element type 2) in the file");
  const std::vector<int>& vertices = found->second.vertices;
  std::vector<Triangle> triangles(vertices.size() / 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    triangles[t] = {vertices[3 * t], vertices[3 * t + 1], vertices[3 * t + 2]};
  return finish_surface(path, std::move(file.points), std::move(triangles), context);
}

// -------------------------------------------------------------------------------------------- parts

// The parts of a surface: its triangles joined through shared edges, numbered from 0 in the order of
// their first triangles.
struct Parts {
  std::vector<int> of_triangle;
  int count = 0;
};

Parts surface_parts(const std::vector<Triangle>& triangles) {
  std::vector<std::pair<detail::Edge, std::size_t>> edges;  // (edge, triangle)
  edges.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k)
      edges.push_back({detail::make_edge(triangles[t][k], triangles[t][(k + 1) % 3]), t});
  std::ranges::sort(edges);
  detail::UnionFind sets(triangles.size());
  for (std::size_t i = 1; i < edges.size(); ++i)
    if (edges[i].first == edges[i - 1].first) sets.join(edges[i - 1].second, edges[i].second);
  Parts parts;
  std::vector<int> part_of_root(triangles.size(), -1);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    int& part = part_of_root[sets.find(t)];
    if (part < 0) part = parts.count++;
    parts.of_triangle.push_back(part);
  }
  return parts;
}

// One surface per part, named NAME_1, NAME_2, ...
std::vector<TriangleSurface> split_into_parts(const TriangleSurface& surface) {
  const Parts parts = surface_parts(surface.triangles);
  std::vector<TriangleSurface> split(static_cast<std::size_t>(parts.count));
  for (std::size_t p = 0; p < split.size(); ++p) {
    split[p].name = surface.name + "_" + std::to_string(p + 1);
    split[p].source = surface.source;
  }
  for (std::size_t t = 0; t < surface.triangles.size(); ++t)
    split[static_cast<std::size_t>(parts.of_triangle[t])].triangles.push_back(surface.triangles[t]);
  for (TriangleSurface& part : split) part.points = used_vertices(surface.points, part.triangles);
  return split;
}

// -------------------------------------------------------------------------------------------- TSurf

constexpr double kTsurfWeldMetres = 1.0;              // coincident vertices of real files lie up to this apart
constexpr double kTsurfRelativeWeldTolerance = 1e-6;  // times the bounding-box diagonal, when the unit is unknown

// Metres in one AXIS_UNIT of a GOCAD coordinate system (quoted or not); 0 when the unit is unknown.
double metres_per_unit(std::string_view unit) {
  constexpr std::array<std::pair<std::string_view, double>, 13> kUnits{{{"m", 1.0},
                                                                        {"meter", 1.0},
                                                                        {"meters", 1.0},
                                                                        {"metre", 1.0},
                                                                        {"metres", 1.0},
                                                                        {"km", 1000.0},
                                                                        {"kilometer", 1000.0},
                                                                        {"kilometers", 1000.0},
                                                                        {"kilometre", 1000.0},
                                                                        {"kilometres", 1000.0},
                                                                        {"ft", 0.3048},
                                                                        {"foot", 0.3048},
                                                                        {"feet", 0.3048}}};
  if (unit.size() >= 2 && unit.front() == '"' && unit.back() == '"') unit = unit.substr(1, unit.size() - 2);
  for (const auto& [name, metres] : kUnits)
    if (iequals(unit, name)) return metres;
  return 0.0;
}

std::string_view trimmed(std::string_view text) {
  const std::size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

// A TSurf file's surface (all its objects), with the TFACE each triangle comes from, for messages.
struct TsurfFile {
  struct Tface {
    int line;    // of its TFACE keyword
    int object;  // index in `objects`
  };
  TriangleSurface surface;
  std::vector<int> tface_of_triangle;  // index in `tfaces`
  std::vector<Tface> tfaces;
  std::vector<std::string> objects;  // each object's HEADER name, empty when it has none
};

// GOCAD TSurf: one or more objects `GOCAD TSurf 1` ... `END`, each numbering its own vertices. Read:
// the geometry (VRTX, PVRTX, ATOM, PATOM and TRGL, in TFACE blocks), the HEADER's name and the
// AXIS_UNIT; other keyword lines (BSTONE, BORDER, PROPERTIES, ...) and blocks in braces are skipped.
class TsurfReader {
 public:
  TsurfReader(const std::string& path, std::string_view bytes) : cursor_(path, bytes, '#') {}

  TsurfFile read(ReadContext& context) {
    start_object(cursor_.expect_token("'GOCAD TSurf' header"));
    while (const std::optional<Token> keyword = cursor_.next_token()) {
      if (object_line_ == 0) start_object(*keyword);
      else read_keyword(*keyword);
    }
    if (object_line_ != 0)
      cursor_.fail_at_end("'END' of the object that starts at line " + std::to_string(object_line_));
    file_.surface = finish_surface(cursor_.path(), std::move(points_), std::move(triangles_), context, weld(),
                                   &file_.tface_of_triangle);
    return std::move(file_);
  }

 private:
  struct Definition {  // of a vertex id
    int point;
    int line;
  };

  int object() const { return static_cast<int>(file_.objects.size()) - 1; }

  void start_object(const Token& gocad) {
    if (!iequals(gocad.text, "GOCAD")) {
      if (file_.objects.empty())
        cursor_.fail_at(gocad.line,
                        "not a GOCAD TSurf file: it starts with " + quoted(gocad.text) + " instead of 'GOCAD TSurf'");
      cursor_.fail_at(gocad.line, "expected 'GOCAD TSurf' (another object) or the end of the file after END, found " +
                                      quoted(gocad.text));
    }
    const Token type = cursor_.expect_token_on_line("GOCAD object type");
    if (!iequals(type.text, "TSurf"))
      cursor_.fail_at(type.line, "not a TSurf: a GOCAD " + quoted(type.text) +
                                     " object (only TSurf objects, triangulated surfaces, can be read)");
    cursor_.skip_line();  // the version
    object_line_ = gocad.line;
    file_.objects.emplace_back();
    ids_.clear();
    unit_ = 0.0;
  }

  void read_keyword(const Token& keyword) {
    const std::string_view text = keyword.text;
    if (text == "VRTX" || text == "PVRTX") {
      add_vertex(keyword);
    } else if (text == "ATOM" || text == "PATOM") {
      add_atom(keyword);
    } else if (text == "TRGL") {
      add_triangle(keyword);
    } else if (text == "TFACE") {
      file_.tfaces.push_back({keyword.line, object()});
      cursor_.skip_line();
    } else if (text == "END") {
      object_units_.push_back(unit_);
      object_line_ = 0;
      cursor_.skip_line();
    } else if (text == "AXIS_UNIT") {
      read_axis_unit();
    } else if (iequals(text, "GOCAD")) {
      cursor_.fail_at(keyword.line, "'GOCAD' starts an object before the END of the object that starts at line " +
                                        std::to_string(object_line_));
    } else {
      skip_keyword(keyword);
    }
  }

  // The geometry of an object lies in its TFACE blocks: a vertex before them has no part to go to.
  void require_tface(const Token& keyword) const {
    if (file_.tfaces.empty() || file_.tfaces.back().object != object())
      cursor_.fail_at(keyword.line, quoted(keyword.text) + " outside a TFACE block (no TFACE since the object's " +
                                        "start at line " + std::to_string(object_line_) + ")");
  }

  void add_vertex(const Token& keyword) {
    require_tface(keyword);
    define(cursor_.expect_token_on_line("vertex id"), static_cast<int>(points_.size()));
    Eigen::Vector3d& p = points_.emplace_back();
    for (int axis = 0; axis < 3; ++axis)
      p[axis] = cursor_.coordinate(cursor_.expect_token_on_line("vertex coordinate"));
    cursor_.skip_line();  // PVRTX's property values
  }

  // An atom is another id for an existing vertex.
  void add_atom(const Token& keyword) {
    require_tface(keyword);
    const Token id = cursor_.expect_token_on_line("atom id");
    define(id, point(keyword, cursor_.expect_token_on_line("vertex id")));
    cursor_.skip_line();  // PATOM's property values
  }

  void add_triangle(const Token& keyword) {
    require_tface(keyword);
    Triangle& triangle = triangles_.emplace_back();
    for (int& corner : triangle) corner = point(keyword, cursor_.expect_token_on_line("vertex id"));
    file_.tface_of_triangle.push_back(static_cast<int>(file_.tfaces.size()) - 1);
    cursor_.skip_line();
  }

  void define(const Token& id, int point) {
    const long long value = cursor_.integer(id, "vertex id");
    const auto [found, inserted] = ids_.try_emplace(value, Definition{point, id.line});
    if (!inserted)
      cursor_.fail_at(id.line, "vertex id " + std::to_string(value) +
                                   " is defined twice in the object (first at line " +
                                   std::to_string(found->second.line) + ")");
  }

  // The point a vertex id of the current object names.
  int point(const Token& keyword, const Token& id) const {
    const long long value = cursor_.integer(id, "vertex id");
    const auto found = ids_.find(value);
    if (found == ids_.end())
      cursor_.fail_at(id.line, std::string(keyword.text) + " refers to unknown vertex id " + std::to_string(value) +
                                   " (no VRTX, PVRTX, ATOM or PATOM of the object defines it before)");
    return found->second.point;
  }

  // AXIS_UNIT "m" "m" "m": the unit common to the three axes; unknown (0) when they differ.
  void read_axis_unit() {
    std::optional<double> unit;
    while (const std::optional<Token> token = cursor_.next_token_on_line()) {
      const double metres = metres_per_unit(token->text);
      unit = !unit || *unit == metres ? metres : 0.0;
    }
    unit_ = unit.value_or(0.0);
    cursor_.skip_line();
  }

  // Skips a keyword line and the block in braces it opens, if any, keeping the HEADER's name.
  void skip_keyword(const Token& keyword) {
    const std::string_view rest = cursor_.rest_of_line();
    const std::size_t open = rest.find('{');
    if (open == std::string_view::npos) return;
    std::string block(rest.substr(open + 1));
    if (const std::size_t close = block.find('}'); close != std::string::npos) {
      block.resize(close);
    } else {
      const std::optional<std::string_view> more = cursor_.text_until("}");
      if (!more) cursor_.fail_at(keyword.line, "the " + quoted(keyword.text) + " block has no closing '}'");
      block += '\n';
      block += *more;
      cursor_.skip_line();  // what follows the '}'
    }
    if (keyword.text == "HEADER") read_header(block);
  }

  // HEADER { key:value lines }: the name.
  void read_header(std::string_view block) {
    while (!block.empty()) {
      const std::size_t end = block.find('\n');
      const std::string_view line = trimmed(block.substr(0, end));
      block = end == std::string_view::npos ? std::string_view() : block.substr(end + 1);
      if (line.starts_with("name:")) file_.objects.back() = std::string(trimmed(line.substr(5)));
    }
  }

  // One metre in the file's unit when every object gives the same known one; a deliberate weld.
  Weld weld() const {
    const bool known = !object_units_.empty() && std::ranges::all_of(object_units_, [&](double unit) {
      return unit > 0.0 && unit == object_units_[0];
    });
    return {known ? std::optional(kTsurfWeldMetres / object_units_[0]) : std::nullopt, kTsurfRelativeWeldTolerance,
            true};
  }

  ByteCursor cursor_;
  TsurfFile file_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<Triangle> triangles_;
  std::unordered_map<long long, Definition> ids_;  // of the current object
  int object_line_ = 0;                            // of the current object's GOCAD line; 0 after its END
  double unit_ = 0.0;                              // metres per AXIS_UNIT of the current object, 0 if unknown
  std::vector<double> object_units_;
};

// Names a TFACE for messages: "TFACE 2 (line 40) of object 'fault A'".
std::string tface_label(const TsurfFile& file, int tface) {
  const TsurfFile::Tface& block = file.tfaces[static_cast<std::size_t>(tface)];
  const std::string& name = file.objects[static_cast<std::size_t>(block.object)];
  return "TFACE " + std::to_string(tface + 1) + " (line " + std::to_string(block.line) + ") of object " +
         (name.empty() ? std::to_string(block.object + 1) : quoted(name, 100));
}

[[noreturn]] void fail_several_parts(const TsurfFile& file, const Parts& parts) {
  constexpr int kMaxNamed = 20;
  const auto named = static_cast<std::size_t>(std::min(parts.count, kMaxNamed));
  std::vector<std::set<int>> tfaces(named);
  std::vector<int> triangles(named, 0);
  for (std::size_t t = 0; t < parts.of_triangle.size(); ++t)
    if (const auto part = static_cast<std::size_t>(parts.of_triangle[t]); part < named) {
      tfaces[part].insert(file.tface_of_triangle[t]);
      ++triangles[part];
    }
  std::string message =
      std::to_string(parts.count) + " parts (triangles joined through shared edges) where one surface is expected:";
  for (std::size_t p = 0; p < named; ++p) {
    message += " part " + std::to_string(p + 1) + ", " + std::to_string(triangles[p]) +
               (triangles[p] == 1 ? " triangle in " : " triangles in ");
    for (const int tface : tfaces[p])
      message += (tface == *tfaces[p].begin() ? "" : " and ") + tface_label(file, tface);
    message += ";";
  }
  if (parts.count > kMaxNamed) message += " and " + std::to_string(parts.count - kMaxNamed) + " more parts;";
  fail_file(file.surface.source,
            message + " --split-parts (read_surface_parts in the library) reads each part as its own surface");
}

// A TSurf file as one surface: refused, naming its parts, when it has several.
TriangleSurface parse_tsurf(const std::string& path, std::string_view bytes, ReadContext& context) {
  TsurfFile file = TsurfReader(path, bytes).read(context);
  const Parts parts = surface_parts(file.surface.triangles);
  if (parts.count > 1) fail_several_parts(file, parts);
  return std::move(file.surface);
}

// A TSurf file whatever its parts.
TriangleSurface parse_whole_tsurf(const std::string& path, std::string_view bytes, ReadContext& context) {
  return TsurfReader(path, bytes).read(context).surface;
}

// ------------------------------------------------------------------------------------------ formats

using Parser = TriangleSurface (*)(const std::string& path, std::string_view bytes, ReadContext& context);

constexpr std::array<std::pair<std::string_view, Parser>, 5> kFormats{
    {{".obj", parse_obj}, {".stl", parse_stl}, {".off", parse_off}, {".msh", parse_msh}, {".ts", parse_tsurf}}};

std::string lowercase_extension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::ranges::transform(extension, extension.begin(),
                         [](char ch) { return static_cast<char>(std::tolower(static_cast<unsigned char>(ch))); });
  return extension;
}

Parser parser_for(const std::string& path) {
  const std::string extension = lowercase_extension(path);
  std::string supported;
  for (const auto& [known, parser] : kFormats) {
    if (extension == known) return parser;
    supported += (supported.empty() ? "" : ", ") + std::string(known);
  }
  fail_file(path, (extension.empty() ? "no file extension" : "unsupported surface format '" + extension + "'") +
                      " (supported: " + supported + ")");
}

TriangleSurface read_with(Parser parser, const std::string& path, const SurfaceReadOptions& options = {},
                          SurfaceReadReport* report = nullptr) {
  ReadContext context{options, {}};
  TriangleSurface surface = parser(path, read_file_bytes(path), context);
  if (report) *report = context.report;
  return surface;
}

// ------------------------------------------------------------------------------------------ welding

struct Cell {
  std::int64_t x, y, z;
  bool operator==(const Cell&) const = default;
};

struct CellHash {
  std::size_t operator()(const Cell& cell) const noexcept {
    std::uint64_t h = static_cast<std::uint64_t>(cell.x) * 0x9E3779B97F4A7C15ULL;
    h ^= static_cast<std::uint64_t>(cell.y) * 0xC2B2AE3D27D4EB4FULL;
    h ^= static_cast<std::uint64_t>(cell.z) * 0x165667B19E3779F9ULL;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

// Points bucketed in a uniform grid, each cell listing its points through a linked list.
class PointGrid {
 public:
  // The points lie in [origin, origin + extent] on every axis.
  PointGrid(const Eigen::Vector3d& origin, double cell_size, double extent)
      : origin_(origin), cell_size_(cell_size), last_cell_(std::floor(extent / cell_size)) {}

  // A stored point within `tolerance` of p, or -1. The point's own cell first: it holds the exact
  // duplicates, which are most of the points of an STL file.
  int find_within(const Eigen::Vector3d& p, double tolerance, const std::vector<Eigen::Vector3d>& stored) const {
    const Cell own = cell_of(p);
    if (const int found = find_in_cell(own, p, tolerance, stored); found >= 0) return found;
    const Cell lo = cell_of((p.array() - tolerance).matrix());
    const Cell hi = cell_of((p.array() + tolerance).matrix());
    for (std::int64_t x = lo.x; x <= hi.x; ++x)
      for (std::int64_t y = lo.y; y <= hi.y; ++y)
        for (std::int64_t z = lo.z; z <= hi.z; ++z)
          if (const Cell cell{x, y, z}; !(cell == own))
            if (const int found = find_in_cell(cell, p, tolerance, stored); found >= 0) return found;
    return -1;
  }
  void insert(int index, const Eigen::Vector3d& p) {
    if (next_.size() <= static_cast<std::size_t>(index)) next_.resize(static_cast<std::size_t>(index) + 1, -1);
    auto [slot, inserted] = first_.try_emplace(cell_of(p), index);
    if (!inserted) {
      next_[static_cast<std::size_t>(index)] = slot->second;
      slot->second = index;
    }
  }

 private:
  int find_in_cell(const Cell& cell, const Eigen::Vector3d& p, double tolerance,
                   const std::vector<Eigen::Vector3d>& stored) const {
    const auto found = first_.find(cell);
    if (found == first_.end()) return -1;
    for (int i = found->second; i >= 0; i = next_[static_cast<std::size_t>(i)])
      if ((stored[static_cast<std::size_t>(i)] - p).squaredNorm() <= tolerance * tolerance) return i;
    return -1;
  }
  // Clamped to one cell beyond the occupied ones: a query box next to the largest doubles can reach
  // infinity, and would otherwise span an unbounded number of cells.
  Cell cell_of(const Eigen::Vector3d& p) const {
    const Eigen::Array3d q = ((p - origin_) / cell_size_).array().floor().cwiseMax(-1.0).cwiseMin(last_cell_ + 1.0);
    return {static_cast<std::int64_t>(q.x()), static_cast<std::int64_t>(q.y()), static_cast<std::int64_t>(q.z())};
  }

  Eigen::Vector3d origin_;
  double cell_size_;
  double last_cell_;
  std::unordered_map<Cell, int, CellHash> first_;
  std::vector<int> next_;
};

}  // namespace

int weld_vertices(TriangleSurface& surface, double tolerance) {
  if (!(tolerance >= 0.0) || std::isinf(tolerance))
    throw std::invalid_argument("weld_vertices: the tolerance must be finite and >= 0");
  std::vector<Eigen::Vector3d>& points = surface.points;
  const std::size_t count = points.size();
  for (std::size_t t = 0; t < surface.triangles.size(); ++t)
    for (const int vertex : surface.triangles[t])
      if (vertex < 0 || static_cast<std::size_t>(vertex) >= count)
        throw InputError((surface.source.empty() ? surface.name : surface.source) + ": triangle " +
                         std::to_string(t + 1) + " refers to vertex index " + std::to_string(vertex) +
                         ", out of range (0.." + std::to_string(static_cast<long long>(count) - 1) + ")");

  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d& p : points)
    if (p.allFinite()) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  const double extent = lo.x() <= hi.x() ? (hi - lo).maxCoeff() : 0.0;
  // Cell coordinates come from differences of points, which must not overflow.
  if (!std::isfinite(extent))
    throw InputError((surface.source.empty() ? surface.name : surface.source) +
                     ": coordinates too far apart to weld: the extent of the points overflows a double");
  // Cells 4 tolerances wide: most points then look up a single cell. Never finer than 2^-40 of the
  // extent, so that cell coordinates fit in 64 bits whatever the tolerance.
  double cell_size = std::max(4.0 * tolerance, extent * 0x1p-40);
  if (cell_size == 0.0) cell_size = 1.0;  // a single location and a zero tolerance
  PointGrid grid(lo.allFinite() ? lo : Eigen::Vector3d::Zero(), cell_size, extent);

  std::vector<Eigen::Vector3d> kept;
  std::vector<int> new_index(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d& p = points[i];
    // Non-finite points are kept apart, for the validation to report.
    int match = p.allFinite() ? grid.find_within(p, tolerance, kept) : -1;
    if (match < 0) {
      match = static_cast<int>(kept.size());
      kept.push_back(p);
      if (p.allFinite()) grid.insert(match, p);
    }
    new_index[i] = match;
  }
  for (Triangle& triangle : surface.triangles)
    for (int& vertex : triangle) vertex = new_index[static_cast<std::size_t>(vertex)];
  const int merged = static_cast<int>(count - kept.size());
  points = std::move(kept);
  return merged;
}

TriangleSurface read_obj(const std::string& path) { return read_with(parse_obj, path); }
TriangleSurface read_stl(const std::string& path) { return read_with(parse_stl, path); }
TriangleSurface read_off(const std::string& path) { return read_with(parse_off, path); }
TriangleSurface read_msh_triangles(const std::string& path) { return read_with(parse_msh, path); }
TriangleSurface read_tsurf(const std::string& path) { return read_with(parse_tsurf, path); }

TriangleSurface read_surface(const std::string& path, const SurfaceReadOptions& options, SurfaceReadReport* report) {
  return read_with(parser_for(path), path, options, report);
}

std::vector<TriangleSurface> read_surface_parts(const std::string& path, const SurfaceReadOptions& options,
                                                SurfaceReadReport* report) {
  // The TSurf parser refuses a file of several parts: read it whole.
  const Parser parser = lowercase_extension(path) == ".ts" ? parse_whole_tsurf : parser_for(path);
  return split_into_parts(read_with(parser, path, options, report));
}

}  // namespace meccano
