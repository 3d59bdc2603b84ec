// Surface readers: round trips through every supported format, every error path, welding and parts.
#include <meccano/error.hpp>
#include <meccano/io/surface_readers.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;
using meccano::InputError;
using meccano::TriangleSurface;
using testing::AllOf;
using testing::HasSubstr;

// An (n+1) x (n+1) grid of points on a curved patch, each cell split as (p00, p10, p11), (p00, p11, p01),
// so that the quad (p00, p10, p11, p01) fan-splits into the first two triangles. The coordinates are
// exact in float and in short decimals, so every format reproduces them exactly.
TriangleSurface grid_patch(int n = 4) {
  TriangleSurface surface;
  surface.name = "grid";
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) surface.points.emplace_back(0.25 * i, 0.5 * j, 0.125 * ((i * j) % 3));
  auto index = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      surface.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      surface.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  return surface;
}

// Sum of the triangles' area vectors: flips with the orientation.
Eigen::Vector3d area_vector(const TriangleSurface& surface) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& t : surface.triangles) {
    const Eigen::Vector3d& a = surface.points[static_cast<std::size_t>(t[0])];
    sum +=
        0.5 *
        (surface.points[static_cast<std::size_t>(t[1])] - a).cross(surface.points[static_cast<std::size_t>(t[2])] - a);
  }
  return sum;
}

const Eigen::Vector3d& corner(const TriangleSurface& surface, std::size_t t, std::size_t k) {
  return surface.points[static_cast<std::size_t>(surface.triangles[t][k])];
}

// Same welded point count, same triangles in the same order, with the same corners in the same order.
void expect_same_surface(const TriangleSurface& read, const TriangleSurface& expected) {
  ASSERT_EQ(read.points.size(), expected.points.size());
  ASSERT_EQ(read.triangles.size(), expected.triangles.size());
  EXPECT_LT((area_vector(read) - area_vector(expected)).norm(), 1e-12);
  for (std::size_t t = 0; t < expected.triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k)
      ASSERT_EQ(corner(read, t, k), corner(expected, t, k)) << "triangle " << t << " corner " << k;
}

std::string number(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

std::string coordinates(const Eigen::Vector3d& p) { return number(p.x()) + " " + number(p.y()) + " " + number(p.z()); }

// Appends a value's bytes in the machine's order (Gmsh binary files).
template <class T>
void put_native(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

// Appends a 32-bit value little-endian (binary STL, whatever the machine).
void put_little32(std::string& out, std::uint32_t value) {
  for (int shift = 0; shift < 32; shift += 8) out += static_cast<char>((value >> shift) & 0xffU);
}

std::string obj_text(const TriangleSurface& surface) {
  // CRLF, comments, groups, materials, texture coordinates, normals, w, negative indices, all four
  // corner forms and a quad.
  const auto count = static_cast<long long>(surface.points.size());
  std::string text = "# written by test_surface_io\r\nmtllib grid.mtl\r\no grid\r\n";
  for (const auto& p : surface.points) text += "v " + coordinates(p) + " 1.0\r\nvt 0.5 0.5\r\n";
  text += "vn 0 0 1\r\ng patch\r\ns off\r\nusemtl steel\r\n\r\n";
  auto ref = [&](int vertex, std::size_t form) {
    const std::string index = std::to_string(vertex - count);  // relative to the last vertex
    const std::string forms[] = {index, index + "/1", index + "//1", index + "/1/1"};
    return forms[form % 4];
  };
  const auto& t = surface.triangles;
  text += "f " + ref(t[0][0], 0) + " " + ref(t[0][1], 1) + " " + ref(t[0][2], 2) + " " + ref(t[1][2], 3) + "\r\n";
  for (std::size_t i = 2; i < t.size(); ++i)
    text += "f " + ref(t[i][0], i) + " " + ref(t[i][1], i + 1) + " " + ref(t[i][2], i + 2) + "  # face\r\n";
  return text;
}

std::string stl_ascii_text(const TriangleSurface& surface) {
  std::string text = "solid grid\n";
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    text += "  facet normal 0 0 1\n    outer loop\n";
    for (std::size_t k = 0; k < 3; ++k) text += "      vertex " + coordinates(corner(surface, t, k)) + "\n";
    text += "    endloop\n  endfacet\n";
  }
  return text + "endsolid grid\n";
}

std::string stl_binary_bytes(const TriangleSurface& surface, const std::string& header) {
  std::string bytes = header;
  bytes.resize(80, ' ');
  put_little32(bytes, static_cast<std::uint32_t>(surface.triangles.size()));
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    for (int axis = 0; axis < 3; ++axis) put_little32(bytes, 0);  // normal
    for (std::size_t k = 0; k < 3; ++k)
      for (int axis = 0; axis < 3; ++axis)
        put_little32(bytes, std::bit_cast<std::uint32_t>(static_cast<float>(corner(surface, t, k)[axis])));
    bytes += std::string(2, '\0');  // attribute
  }
  return bytes;
}

std::string off_text(const TriangleSurface& surface, bool counts_on_header_line) {
  const auto& t = surface.triangles;
  const std::string counts = std::to_string(surface.points.size()) + " " + std::to_string(t.size() - 1) + " 0";
  std::string text = counts_on_header_line ? "OFF " + counts + "\n" : "OFF\n# a comment\n\n" + counts + "\n";
  for (const auto& p : surface.points) text += coordinates(p) + "\n";
  text += "4 " + std::to_string(t[0][0]) + " " + std::to_string(t[0][1]) + " " + std::to_string(t[0][2]) + " " +
          std::to_string(t[1][2]) + " 255 0 0\n";  // a quad with a colour
  for (std::size_t i = 2; i < t.size(); ++i)
    text += "3 " + std::to_string(t[i][0]) + " " + std::to_string(t[i][1]) + " " + std::to_string(t[i][2]) + "\n";
  return text;
}

// Non-contiguous node tags, to check the mapping.
std::uint64_t node_tag(int vertex) { return 100 + 7 * static_cast<std::uint64_t>(vertex); }

std::string msh22_bytes(const TriangleSurface& surface, bool binary) {
  std::string out = std::string("$MeshFormat\n2.2 ") + (binary ? "1" : "0") + " 8\n";
  if (binary) {
    put_native<std::int32_t>(out, 1);
    out += "\n";
  }
  out += "$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"patch\"\n$EndPhysicalNames\n";
  out += "$Nodes\n" + std::to_string(surface.points.size()) + "\n";
  for (std::size_t v = 0; v < surface.points.size(); ++v) {
    const auto tag = node_tag(static_cast<int>(v));
    if (!binary) {
      out += std::to_string(tag) + " " + coordinates(surface.points[v]) + "\n";
      continue;
    }
    put_native<std::int32_t>(out, static_cast<std::int32_t>(tag));
    for (int axis = 0; axis < 3; ++axis) put_native(out, surface.points[v][axis]);
  }
  out += (binary ? "\n" : "") + std::string("$EndNodes\n$Elements\n");
  const auto triangles = surface.triangles.size();
  out += std::to_string(triangles + 2) + "\n";  // plus a point and a line
  if (!binary) {
    out += "1 15 2 0 1 " + std::to_string(node_tag(0)) + "\n";
    out += "2 1 2 0 1 " + std::to_string(node_tag(0)) + " " + std::to_string(node_tag(1)) + "\n";
    for (std::size_t t = 0; t < triangles; ++t) {
      out += std::to_string(t + 3) + " 2 2 1 1";
      for (const int v : surface.triangles[t]) out.append(" ").append(std::to_string(node_tag(v)));
      out += "\n";
    }
  } else {
    for (const std::int32_t value : {15, 1, 2, 1, 0, 1, static_cast<std::int32_t>(node_tag(0))}) put_native(out, value);
    for (const std::int32_t value :
         {1, 1, 2, 2, 0, 1, static_cast<std::int32_t>(node_tag(0)), static_cast<std::int32_t>(node_tag(1))})
      put_native(out, value);
    for (const std::int32_t value : {2, static_cast<std::int32_t>(triangles), 2}) put_native(out, value);
    for (std::size_t t = 0; t < triangles; ++t) {
      for (const std::int32_t value : {static_cast<std::int32_t>(t + 3), 1, 1}) put_native(out, value);
      for (const int v : surface.triangles[t]) put_native(out, static_cast<std::int32_t>(node_tag(v)));
    }
    out += "\n";
  }
  return out + "$EndElements\n";
}

// Writes MSH 4.1 lines of fields, as text or as native binary values.
struct Msh41Writer {
  bool binary;
  std::string out;

  void sizes(std::initializer_list<std::uint64_t> values) {
    for (const std::uint64_t value : values) binary ? put_native(out, value) : void(out += std::to_string(value) + " ");
    end_line();
  }
  void reals(std::initializer_list<double> values) {
    for (const double value : values) binary ? put_native(out, value) : void(out += number(value) + " ");
    end_line();
  }
  // Entity dimension and tag, a third int (parametric flag or element type), and the block's size.
  void block_header(std::int32_t dimension, std::int32_t third, std::uint64_t count) {
    for (const std::int32_t value : {dimension, 1, third})
      binary ? put_native(out, value) : void(out += std::to_string(value) + " ");
    sizes({count});
  }
  void end_line() {
    if (!binary) out += "\n";
  }
};

// Node 0 in a point entity, the others in a parametric surface block (x y z u v); a point, a line and
// the triangles as elements; an $Entities section to skip.
std::string msh41_bytes(const TriangleSurface& surface, bool binary) {
  Msh41Writer w{binary, std::string("$MeshFormat\n4.1 ") + (binary ? "1" : "0") + " 8\n"};
  if (binary) {
    put_native<std::int32_t>(w.out, 1);
    w.out += "\n";
  }
  w.out += "$EndMeshFormat\n";
  if (!binary)
    w.out += "$Entities\n1 1 1 0\n1 0 0 0 0\n1 0 0 0 1 0 0 0 2 1 -1\n1 0 0 0 1 2 0.5 1 1 1 4\n$EndEntities\n";
  const auto count = surface.points.size();
  w.out += "$Nodes\n";
  w.sizes({2, count, node_tag(0), node_tag(static_cast<int>(count) - 1)});
  w.block_header(0, 0, 1);
  w.sizes({node_tag(0)});
  w.reals({surface.points[0].x(), surface.points[0].y(), surface.points[0].z()});
  w.block_header(2, 1, count - 1);
  for (std::size_t v = 1; v < count; ++v) w.sizes({node_tag(static_cast<int>(v))});
  for (std::size_t v = 1; v < count; ++v)
    w.reals({surface.points[v].x(), surface.points[v].y(), surface.points[v].z(), 0.5, 0.25});  // x y z u v
  w.out += (binary ? "\n" : "") + std::string("$EndNodes\n$Elements\n");
  const auto triangles = surface.triangles.size();
  w.sizes({3, triangles + 2, 1, triangles + 2});
  w.block_header(0, 15, 1);
  w.sizes({1, node_tag(0)});
  w.block_header(1, 1, 1);
  w.sizes({2, node_tag(0), node_tag(1)});
  w.block_header(2, 2, triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    const auto& [a, b, c] = surface.triangles[t];
    w.sizes({t + 3, node_tag(a), node_tag(b), node_tag(c)});
  }
  return w.out + (binary ? "\n" : "") + "$EndElements\n";
}

// Runs `read` and returns the InputError's message; any other outcome fails the test.
template <class Read>
std::string input_error(Read read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected InputError, got: " << error.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing thrown";
  return {};
}

class SurfaceIo : public testing::Test {
 protected:
  void SetUp() override {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("meccano-surface-io-") + info->name() + "-" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& bytes) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  // The message of the InputError that reading `bytes` as file `name` raises.
  std::string read_error(const std::string& name, const std::string& bytes) const {
    const std::string path = write(name, bytes);
    return input_error([&] { meccano::read_surface(path); });
  }

  fs::path dir_;
};

// ------------------------------------------------------------------------------------- round trips

TEST_F(SurfaceIo, ObjRoundTripWithNegativeIndicesQuadAndCrlf) {
  const TriangleSurface grid = grid_patch();
  const std::string path = write("grid.obj", obj_text(grid));
  const TriangleSurface read = meccano::read_surface(path);
  expect_same_surface(read, grid);
  EXPECT_EQ(read.name, "grid");
  EXPECT_EQ(read.source, path);
}

TEST_F(SurfaceIo, StlAsciiRoundTripWeldsTheUnsharedVertices) {
  const TriangleSurface grid = grid_patch();
  const TriangleSurface read = meccano::read_surface(write("grid.stl", stl_ascii_text(grid)));
  EXPECT_EQ(read.points.size(), 25U);  // 96 corners in the file
  expect_same_surface(read, grid);
}

TEST_F(SurfaceIo, StlBinaryRoundTrip) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_surface(write("grid.stl", stl_binary_bytes(grid, "binary grid"))), grid);
}

TEST_F(SurfaceIo, StlBinaryWhoseHeaderStartsWithSolidIsReadAsBinary) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_stl(write("grid.stl", stl_binary_bytes(grid, "solid grid exported by CAD"))), grid);
}

TEST_F(SurfaceIo, OffRoundTripWithQuadColourAndComments) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_surface(write("grid.off", off_text(grid, false))), grid);
}

TEST_F(SurfaceIo, OffRoundTripWithCountsOnTheHeaderLine) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_surface(write("grid.off", off_text(grid, true))), grid);
}

TEST_F(SurfaceIo, Msh22AsciiRoundTripIgnoresPointsAndLines) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_surface(write("grid.msh", msh22_bytes(grid, false))), grid);
}

TEST_F(SurfaceIo, Msh22BinaryRoundTrip) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_surface(write("grid.msh", msh22_bytes(grid, true))), grid);
}

TEST_F(SurfaceIo, Msh41AsciiRoundTripWithSparseTagsParametricNodesAndEntities) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_surface(write("grid.msh", msh41_bytes(grid, false))), grid);
}

TEST_F(SurfaceIo, Msh41BinaryRoundTrip) {
  const TriangleSurface grid = grid_patch();
  expect_same_surface(meccano::read_msh_triangles(write("grid.msh", msh41_bytes(grid, true))), grid);
}

TEST_F(SurfaceIo, ExtensionIsCaseInsensitive) {
  const TriangleSurface grid = grid_patch();
  const TriangleSurface read = meccano::read_surface(write("GRID.STL", stl_ascii_text(grid)));
  expect_same_surface(read, grid);
  EXPECT_EQ(read.name, "GRID");
}

TEST_F(SurfaceIo, UnusedVerticesAreDropped) {
  const TriangleSurface read =
      meccano::read_surface(write("t.obj", "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 7 7 7\nf 2 3 4\n"));
  ASSERT_EQ(read.points.size(), 3U);
  EXPECT_EQ(read.points[static_cast<std::size_t>(read.triangles[0][0])], Eigen::Vector3d(0, 0, 0));
}

TEST_F(SurfaceIo, ReaderWeldsOnlyWithinTheRelativeTolerance) {
  // Diagonal sqrt(2): 1e-12 apart is welded (tolerance 1.4e-10), 1e-6 apart is not.
  const std::string path = write("t.off", "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1e-12 0\n1 1 0\n0 1.000001 0\n"
                                          "3 0 1 2\n3 3 4 5\n");
  const TriangleSurface read = meccano::read_surface(path);
  EXPECT_EQ(read.points.size(), 5U);
  EXPECT_EQ(read.triangles[1][0], read.triangles[0][1]);
  EXPECT_NE(read.triangles[1][2], read.triangles[0][2]);
}

TEST(SurfaceWeld, MergesPointsWithinToleranceAndRenumbers) {
  TriangleSurface surface;
  surface.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1 + 1e-4, 0, 0}, {1, 1, 0}, {1.002, 0, 0}};
  surface.triangles = {{0, 1, 2}, {3, 4, 2}, {5, 4, 3}};
  EXPECT_EQ(meccano::weld_vertices(surface, 1e-3), 1);
  ASSERT_EQ(surface.points.size(), 5U);
  EXPECT_EQ(surface.triangles[1][0], 1);  // point 3 merged into point 1
  EXPECT_EQ(surface.triangles[2][0], 4);  // point 5 (2e-3 away) kept, renumbered
  EXPECT_EQ(surface.points[4], Eigen::Vector3d(1.002, 0, 0));
  EXPECT_EQ(meccano::weld_vertices(surface, 0.0), 0);
}

// Found by fuzz_read_msh: cell coordinates of points near the largest doubles overflowed (undefined
// behaviour, and a search over 2^64 cells).
TEST(SurfaceWeld, PointsNearTheLargestDoublesWeldWithoutOverflow) {
  TriangleSurface surface;
  surface.points = {{1.7e308, 0, 0}, {1.0e308, 0, 0}, {1.5e308, 1e308, 0}, {1.7e308, 1e300, 0}};
  surface.triangles = {{0, 1, 2}, {3, 1, 2}};
  EXPECT_EQ(meccano::weld_vertices(surface, 1e307), 1);  // the query box of point 0 reaches infinity
  EXPECT_EQ(surface.triangles[1][0], 0);
  EXPECT_THROW(meccano::weld_vertices(surface, std::numeric_limits<double>::infinity()), std::invalid_argument);
}

TEST_F(SurfaceIo, CoordinatesWhoseExtentOverflowsAreRejected) {
  EXPECT_THAT(read_error("far.off", "OFF\n3 1 0\n-1e308 0 0\n1e308 0 0\n0 1 0\n3 0 1 2\n"),
              HasSubstr("far.off: coordinates too far apart: the extent of the surface overflows a double"));
  // Unused vertices do not count for the tolerance, but they are welded too.
  EXPECT_THAT(read_error("far.obj", "v -1e308 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e308 0 0\nf 2 3 4\n"),
              HasSubstr("far.obj: coordinates too far apart to weld: the extent of the points overflows a double"));
}

TEST_F(SurfaceIo, WeldsAHundredThousandTriangleBinaryStl) {
  const TriangleSurface grid = grid_patch(224);  // 100352 triangles, 301056 corners in the file
  const TriangleSurface read = meccano::read_stl(write("big.stl", stl_binary_bytes(grid, "big")));
  EXPECT_EQ(read.points.size(), grid.points.size());
  EXPECT_EQ(read.triangles.size(), grid.triangles.size());
}

// ---------------------------------------------------------------------------------- common errors

TEST_F(SurfaceIo, MissingFile) {
  const std::string path = (dir_ / "absent.obj").string();
  const std::string message = input_error([&] { meccano::read_surface(path); });
  EXPECT_THAT(message, HasSubstr(path + ": cannot open file"));
}

TEST_F(SurfaceIo, EmptyFile) {
  for (const char* name : {"empty.obj", "empty.stl", "empty.off", "empty.msh", "empty.ts"})
    EXPECT_THAT(read_error(name, ""), HasSubstr(std::string(name) + ": empty file"));
}

TEST_F(SurfaceIo, UnknownExtensionListsTheSupportedOnes) {
  const std::string message = read_error("mesh.ply", "ply\n");
  EXPECT_THAT(message, HasSubstr("mesh.ply: unsupported surface format '.ply'"));
  EXPECT_THAT(message, HasSubstr("(supported: .obj, .stl, .off, .msh, .ts)"));
}

TEST_F(SurfaceIo, NoTriangles) {
  EXPECT_THAT(read_error("points.obj", "v 0 0 0\nv 1 0 0\n"), HasSubstr("points.obj: no triangles"));
  EXPECT_THAT(read_error("points.off", "OFF\n1 0 0\n0 0 0\n"), HasSubstr("points.off: no triangles"));
}

// ------------------------------------------------------------------------------------------ OBJ

TEST_F(SurfaceIo, ObjIndexOutOfRange) {
  const std::string message = read_error("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  EXPECT_THAT(message, HasSubstr("bad.obj:4: vertex index 9 out of range (1..3)"));
}

TEST_F(SurfaceIo, ObjNegativeIndexOutOfRange) {
  const std::string message = read_error("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
  EXPECT_THAT(message, HasSubstr("bad.obj:4: vertex index -4 out of range (-3..-1"));
}

TEST_F(SurfaceIo, ObjIndexZero) {
  EXPECT_THAT(read_error("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
              HasSubstr("bad.obj:4: vertex index 0 out of range"));
}

TEST_F(SurfaceIo, ObjMalformedNumber) {
  EXPECT_THAT(read_error("bad.obj", "# header\nv 0 0 0\nv 1 0x 0\n"),
              HasSubstr("bad.obj:3: malformed coordinate '0x'"));
  EXPECT_THAT(read_error("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a/1\n"),
              HasSubstr("bad.obj:4: malformed vertex index 'a'"));
}

TEST_F(SurfaceIo, ObjNonFiniteCoordinate) {
  EXPECT_THAT(read_error("bad.obj", "v 0 0 0\nv 1 nan 0\n"), HasSubstr("bad.obj:2: non-finite coordinate 'nan'"));
  EXPECT_THAT(read_error("bad.obj", "v 0 0 0\nv 1 1e999 0\n"), HasSubstr("bad.obj:2: non-finite coordinate '1e999'"));
}

TEST_F(SurfaceIo, ObjMissingCoordinate) {
  EXPECT_THAT(read_error("bad.obj", "v 0 0\nv 1 1 0\n"),
              HasSubstr("bad.obj:1: expected vertex coordinate before the end of the line"));
}

TEST_F(SurfaceIo, ObjFaceWithTwoVertices) {
  EXPECT_THAT(read_error("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"), HasSubstr("bad.obj:3: face with 2 vertices"));
}

// ------------------------------------------------------------------------------------------ STL

TEST_F(SurfaceIo, StlTruncatedBinary) {
  std::string bytes = stl_binary_bytes(grid_patch(), "binary grid");
  bytes.resize(bytes.size() - 30);
  const std::string message = read_error("cut.stl", bytes);
  EXPECT_THAT(message, HasSubstr("cut.stl: binary STL header announces 32 triangles"));
  EXPECT_THAT(message, HasSubstr("truncated file"));
}

TEST_F(SurfaceIo, StlAbsurdTriangleCount) {
  std::string bytes = stl_binary_bytes(grid_patch(1), "absurd");
  bytes.replace(80, 4, std::string(4, '\xff'));
  const std::string message = read_error("absurd.stl", bytes);
  EXPECT_THAT(message, HasSubstr("absurd.stl: binary STL header announces 4294967295 triangles"));
  EXPECT_THAT(message, HasSubstr("but the file has 184 bytes"));
}

TEST_F(SurfaceIo, StlTrailingDataAfterBinaryTriangles) {
  const std::string bytes = stl_binary_bytes(grid_patch(1), "binary") + std::string(7, '\0');
  EXPECT_THAT(read_error("long.stl", bytes), HasSubstr("long.stl: binary STL header announces 2 triangles"));
}

TEST_F(SurfaceIo, StlTooShort) {
  EXPECT_THAT(read_error("short.stl", std::string("\x01\x02\x03", 3)), HasSubstr("short.stl: not an STL file"));
  EXPECT_THAT(read_error("text.stl", "facet normal 0 0 1\n"), HasSubstr("text.stl: not an STL file"));
}

TEST_F(SurfaceIo, StlBinaryNonFiniteCoordinate) {
  std::string bytes = stl_binary_bytes(grid_patch(), "nan");
  const std::size_t third_triangle_second_vertex_y = 84 + 2 * 50 + 12 + 12 + 4;
  std::string nan;
  put_little32(nan, std::bit_cast<std::uint32_t>(std::numeric_limits<float>::quiet_NaN()));
  bytes.replace(third_triangle_second_vertex_y, 4, nan);
  EXPECT_THAT(read_error("nan.stl", bytes), HasSubstr("nan.stl: element 3: non-finite coordinate"));
}

TEST_F(SurfaceIo, StlAsciiStructureErrorsNameTheLine) {
  const std::string facet_start = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
  EXPECT_THAT(read_error("a.stl", facet_start + "vertex 0 1 0\nendfacet\nendsolid\n"),
              HasSubstr("a.stl:7: expected 'endloop', found 'endfacet'"));
  EXPECT_THAT(read_error("b.stl", facet_start + "endloop\nendfacet\nendsolid\n"),
              HasSubstr("b.stl:6: expected 'vertex', found 'endloop'"));
  EXPECT_THAT(read_error("c.stl", facet_start + "vertex 0 1 zero\n"),
              HasSubstr("c.stl:6: malformed coordinate 'zero'"));
  EXPECT_THAT(read_error("d.stl", facet_start + "vertex 0 1 inf\n"), HasSubstr("d.stl:6: non-finite coordinate 'inf'"));
  EXPECT_THAT(read_error("e.stl", facet_start + "vertex 0 1 0\nendloop\nendfacet\n"),
              HasSubstr("e.stl:8: unexpected end of file (expected 'facet' or 'endsolid')"));
  EXPECT_THAT(read_error("f.stl", "solid s\nfacet normal 0 0 1\nloop\n"),
              HasSubstr("f.stl:3: expected 'outer', found 'loop'"));
}

// ------------------------------------------------------------------------------------------ OFF

TEST_F(SurfaceIo, OffIndexOutOfRange) {
  EXPECT_THAT(read_error("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
              HasSubstr("bad.off:6: vertex index 3 out of range (0..2)"));
  EXPECT_THAT(read_error("neg.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"),
              HasSubstr("neg.off:6: vertex index -1 out of range (0..2)"));
}

TEST_F(SurfaceIo, OffAbsurdCounts) {
  EXPECT_THAT(read_error("big.off", "OFF\n1000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
              HasSubstr("big.off:2: absurd vertex count 1000000000"));
  EXPECT_THAT(read_error("big.off", "OFF 3 99999999999 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
              HasSubstr("big.off:1: absurd face count 99999999999"));
}

TEST_F(SurfaceIo, OffUnexpectedEndOfFile) {
  EXPECT_THAT(read_error("short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n"),
              HasSubstr("short.off:5: unexpected end of file (expected face vertex count)"));
}

TEST_F(SurfaceIo, OffMalformedHeaderCountsAndFaces) {
  EXPECT_THAT(read_error("a.off", "PLY\n3 1 0\n"), HasSubstr("a.off:1: expected the 'OFF' header, found 'PLY'"));
  EXPECT_THAT(read_error("b.off", "OFF\n3 one 0\n"), HasSubstr("b.off:2: malformed face count 'one'"));
  EXPECT_THAT(read_error("c.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
              HasSubstr("c.off:6: face with 2 vertices"));
  EXPECT_THAT(read_error("d.off", "OFF\n3 1 0\n0 0 0\n1 -nan 0\n0 1 0\n3 0 1 2\n"),
              HasSubstr("d.off:4: non-finite coordinate '-nan'"));
}

// ------------------------------------------------------------------------------------------ MSH

const std::string kMsh22Header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";

TEST_F(SurfaceIo, MshUnsupportedVersion) {
  EXPECT_THAT(read_error("old.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n"),
              HasSubstr("old.msh:2: unsupported MSH version '3.0' (supported: 2.2, 4.1)"));
  EXPECT_THAT(read_error("not.msh", "solid x\n"), HasSubstr("not.msh:1: not a Gmsh MSH file"));
}

TEST_F(SurfaceIo, MshWithoutTriangles) {
  const std::string lines_only =
      kMsh22Header + "$Nodes\n2\n1 0 0 0\n2 1 0 0\n$EndNodes\n$Elements\n1\n1 1 2 0 1 1 2\n$EndElements\n";
  EXPECT_THAT(read_error("lines.msh", lines_only), HasSubstr("lines.msh: no triangles (element type 2)"));
}

TEST_F(SurfaceIo, MshUndefinedNode) {
  const std::string text =
      kMsh22Header + "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n5 2 0 1 2 99\n$EndElements\n";
  EXPECT_THAT(read_error("undefined.msh", text), HasSubstr("undefined.msh: element 5: node 99 is not defined"));
}

TEST_F(SurfaceIo, MshDuplicateNodeTag) {
  const std::string text = kMsh22Header + "$Nodes\n2\n1 0 0 0\n1 1 0 0\n$EndNodes\n";
  EXPECT_THAT(read_error("twice.msh", text), HasSubstr("twice.msh:7: node tag 1 is defined twice"));
}

TEST_F(SurfaceIo, MshNonFiniteCoordinate) {
  const std::string text = kMsh22Header + "$Nodes\n2\n1 0 0 0\n2 1 NaN 0\n$EndNodes\n";
  EXPECT_THAT(read_error("nan.msh", text), HasSubstr("nan.msh:7: node 2 has a non-finite coordinate 'NaN'"));
}

TEST_F(SurfaceIo, MshAbsurdCounts) {
  EXPECT_THAT(read_error("nodes.msh", kMsh22Header + "$Nodes\n123456789012\n1 0 0 0\n$EndNodes\n"),
              HasSubstr("nodes.msh:5: absurd node count 123456789012"));
  std::string binary = msh41_bytes(grid_patch(), true);
  const std::size_t nodes = binary.find("$Nodes\n") + 7;
  std::string huge;
  put_native<std::uint64_t>(huge, std::uint64_t{1} << 60);
  binary.replace(nodes + 8, 8, huge);  // the node count, after the number of blocks
  EXPECT_THAT(read_error("binary.msh", binary),
              AllOf(HasSubstr("binary.msh: byte "), HasSubstr(": absurd node count 1152921504606846976")));
}

TEST_F(SurfaceIo, MshMissingEndOfSection) {
  EXPECT_THAT(read_error("open.msh", kMsh22Header + "$Nodes\n1\n1 0 0 0\n$Elements\n"),
              HasSubstr("open.msh:7: expected '$EndNodes', found '$Elements'"));
  EXPECT_THAT(read_error("skip.msh", kMsh22Header + "$Comments\nno end\n"),
              HasSubstr("skip.msh:4: section '$Comments' has no '$EndComments'"));
}

TEST_F(SurfaceIo, MshBinaryFlagsAndEndianness) {
  EXPECT_THAT(read_error("type.msh", "$MeshFormat\n4.1 2 8\n$EndMeshFormat\n"),
              HasSubstr("type.msh:2: file type '2' is neither 0 (ASCII) nor 1 (binary)"));
  EXPECT_THAT(read_error("size.msh", "$MeshFormat\n4.1 1 4\n"), HasSubstr("size.msh:2: unsupported data size '4'"));
  std::string swapped = msh41_bytes(grid_patch(), true);
  const std::size_t one = swapped.find("8\n") + 2;
  std::reverse(swapped.begin() + static_cast<std::ptrdiff_t>(one),
               swapped.begin() + static_cast<std::ptrdiff_t>(one) + 4);
  EXPECT_THAT(read_error("swapped.msh", swapped),
              AllOf(HasSubstr("swapped.msh: byte "), HasSubstr(": binary endianness check reads 16777216")));
}

TEST_F(SurfaceIo, MshTruncatedBinary) {
  const std::string bytes = msh41_bytes(grid_patch(), true);
  const std::string cut = bytes.substr(0, bytes.find("$EndElements") - 40);
  EXPECT_THAT(read_error("cut.msh", cut),
              AllOf(HasSubstr("cut.msh: byte "), HasSubstr(": unexpected end of file: truncated binary data")));
}

// ---------------------------------------------------------------------------------------- TSurf

// The real faults of shared/data/faults (README.md there): triangle counts and extents from its table
// (km, rounded to 0.1, one of them rounded up from x.45), vertex counts read independently of this reader.
TEST(SurfaceIoFaults, EverySharedFaultReadsWithItsCountsAndExtent) {
  const fs::path dir = MECCANO_FAULTS_DIR;
  if (!fs::is_directory(dir)) GTEST_SKIP() << "no fault data at " << dir << " (shared/data/faults beside the checkout)";
  struct Fault {
    const char* file;
    std::size_t triangles, vertices;
    std::array<double, 6> km;  // x, y, z ranges: min, max
  };
  const Fault faults[] = {
      {"CRFA-REHZ-EHSN-East_Huasna_fault-CFM4_1000m.ts", 1161, 664, {182.5, 224.6, 3853.2, 3911.8, -7.2, 0.9}},
      {"MJVA-HSLZ-SBMT-Pipes_Canyon_fault_north_extension-CFM5_1000m.ts",
       584,
       322,
       {518.2, 526.9, 3795.2, 3802.8, -10.4, 1.6}},
      {"PNRA-CRSF-YUHA-Shell_Beds_fault-CFM5_1000m.ts", 317, 182, {606.0, 609.5, 3618.3, 3624.3, -7.1, 0.1}},
      {"PNRA-SJFZ-SJCV-Claremont_fault-CFM4_1000m.ts", 2625, 1383, {482.6, 508.8, 3733.0, 3759.9, -18.8, 0.7}},
      {"PNRA-SJFZ-SJCV-San_Jacinto_Claremont_fault_east-CFM4_1000m.ts",
       1258,
       680,
       {483.1, 490.8, 3753.3, 3760.5, -17.5, 0.7}},
      {"WTRA-SFFS-ANCP-Malibu_Coast_fault_west_steep_alt2-CFM5_1000m.ts",
       1022,
       559,
       {289.1, 321.3, 3762.1, 3771.3, -13.4, 0.0}},
      {"WTRA-SFFS-SRSM-Western_Santa_Cruz_Island_fault_trim-CFM5_1000m.ts",
       788,
       476,
       {166.4, 227.7, 3771.8, 3792.0, -8.0, -0.1}},
      {"WTRA-SMFZ-SMDE-Sierra_Madre_fault_low_dip-CFM4_1000m.ts", 894, 482, {423.5, 430.1, 3776.5, 3787.3, -14.8, 0.7}},
  };
  for (const Fault& fault : faults) {
    SCOPED_TRACE(fault.file);
    meccano::SurfaceReadReport report;
    const TriangleSurface surface = meccano::read_surface((dir / fault.file).string(), {}, &report);
    EXPECT_EQ(surface.triangles.size(), fault.triangles);
    EXPECT_EQ(surface.points.size(), fault.vertices);
    EXPECT_EQ(report.welded_vertices + report.degenerate_triangles + report.duplicate_triangles, 0);
    Eigen::Vector3d lo = surface.points[0], hi = surface.points[0];
    for (const auto& p : surface.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(lo[axis] / 1000, fault.km[2 * axis], 0.06) << "axis " << axis;
      EXPECT_NEAR(hi[axis] / 1000, fault.km[2 * axis + 1], 0.06) << "axis " << axis;
    }
  }
}

// The lines before the geometry, numbered: a HEADER block, a coordinate system, properties, a comment.
const std::string kTsurfHeader = "GOCAD TSurf 1\n"                     // 1
                                 "HEADER {\n"                          // 2
                                 "name: square fault\n"                // 3
                                 "*solid*color:#87ceeb\n"              // 4
                                 "}\n"                                 // 5
                                 "GOCAD_ORIGINAL_COORDINATE_SYSTEM\n"  // 6
                                 "NAME Default\n"                      // 7
                                 "AXIS_NAME \"X\" \"Y\" \"Z\"\n"       // 8
                                 "AXIS_UNIT \"m\" \"m\" \"m\"\n"       // 9
                                 "ZPOSITIVE Depth\n"                   // 10
                                 "END_ORIGINAL_COORDINATE_SYSTEM\n"    // 11
                                 "PROPERTIES a b\n"                    // 12
                                 "PROPERTY_CLASS_HEADER a {\n"         // 13
                                 "low_clip:0\n"                        // 14
                                 "}\n"                                 // 15
                                 "# a comment\n";                      // 16

// A square's two triangles in TFACE 1 (vertices 10, 20, 30, 40) and, on the edge 20-30, a triangle
// in TFACE 2 (vertex 50 and atoms of 20 and 30), then the same triangle reversed.
TEST_F(SurfaceIo, TsurfWithPropertiesAtomsAndTwoTfacesSharingAnEdgeIsOneSurface) {
  const std::string text = kTsurfHeader + "TFACE\n"                       // 17
                                          "PVRTX 10 0 0 100 1.5 2.5\n"    // 18
                                          "PVRTX 20 10 0 100 1.5 2.5\n"   // 19
                                          "VRTX 30 10 10 100 # corner\n"  // 20
                                          "VRTX 40 0 10 100\n"            // 21
                                          "TRGL 10 20 30\n"               // 22
                                          "TRGL 10 30 40\n"               // 23
                                          "BSTONE 10\n"                   // 24
                                          "BORDER 41 10 20\n"             // 25
                                          "TFACE\n"                       // 26
                                          "PATOM 60 20 7 8\n"             // 27
                                          "ATOM 70 30\n"                  // 28
                                          "ATOM 80 70\n"                  // 29
                                          "VRTX 50 20 5 100\n"            // 30
                                          "TRGL 60 50 70\n"               // 31
                                          "TRGL 50 60 80\n"               // 32 (31 reversed)
                                          "END\n";
  meccano::SurfaceReadReport report;
  const std::string path = write("square.ts", text);
  const TriangleSurface read = meccano::read_surface(path, {}, &report);
  EXPECT_EQ(read.name, "square");
  EXPECT_EQ(read.source, path);
  ASSERT_EQ(read.triangles.size(), 3U);
  ASSERT_EQ(read.points.size(), 5U);
  EXPECT_EQ(report.duplicate_triangles, 1);
  EXPECT_EQ(report.welded_vertices + report.degenerate_triangles, 0);
  // The atoms are the vertices they name; z as in the file (ZPOSITIVE Depth is not applied).
  EXPECT_EQ(corner(read, 2, 0), Eigen::Vector3d(10, 0, 100));
  EXPECT_EQ(corner(read, 2, 1), Eigen::Vector3d(20, 5, 100));
  EXPECT_EQ(corner(read, 2, 2), Eigen::Vector3d(10, 10, 100));
  EXPECT_EQ(read.triangles[2][0], read.triangles[0][1]);
  EXPECT_EQ(read.triangles[2][2], read.triangles[0][2]);
  EXPECT_LT((area_vector(read) - Eigen::Vector3d(0, 0, 150)).norm(), 1e-12);  // the file's orientation
  EXPECT_EQ(meccano::read_tsurf(path).triangles.size(), 3U);
  EXPECT_EQ(meccano::read_surface(write("UPPER.TS", text)).triangles.size(), 3U);
}

// Two triangles apart in TFACE 1, one in TFACE 2 joined by an edge to the second of TFACE 1, and one
// of a second object (its own ids, no name) alone: parts {1}, {2, 3}, {4} in file order.
const std::string kThreePartTsurf = "GOCAD TSurf 1\n"         // 1
                                    "HEADER {name:faults}\n"  // 2
                                    "TFACE\n"                 // 3
                                    "VRTX 1 0 0 0\n"          // 4
                                    "VRTX 2 1 0 0\n"          // 5
                                    "VRTX 3 0 1 0\n"          // 6
                                    "VRTX 4 5 0 0\n"          // 7
                                    "VRTX 5 6 0 0\n"          // 8
                                    "VRTX 6 5 1 0\n"          // 9
                                    "TRGL 1 2 3\n"            // 10
                                    "TRGL 4 5 6\n"            // 11
                                    "TFACE\n"                 // 12
                                    "VRTX 7 6 1 0\n"          // 13
                                    "TRGL 6 5 7\n"            // 14
                                    "END\n"                   // 15
                                    "GOCAD TSurf 1\n"         // 16
                                    "TFACE\n"                 // 17
                                    "VRTX 1 0 0 9\n"          // 18
                                    "VRTX 2 1 0 9\n"          // 19
                                    "VRTX 3 0 1 9\n"          // 20
                                    "TRGL 1 2 3\n"            // 21
                                    "END\n";

TEST_F(SurfaceIo, TsurfOfSeveralPartsIsRefusedNamingEachPart) {
  const std::string message = read_error("parts.ts", kThreePartTsurf);
  EXPECT_THAT(message,
              HasSubstr("parts.ts: 3 parts (triangles joined through shared edges) where one surface is expected"));
  EXPECT_THAT(message, HasSubstr("part 1, 1 triangle in TFACE 1 (line 3) of object 'faults';"));
  EXPECT_THAT(message, HasSubstr("part 2, 2 triangles in TFACE 1 (line 3) of object 'faults' and TFACE 2 (line 12) of "
                                 "object 'faults';"));
  EXPECT_THAT(message, HasSubstr("part 3, 1 triangle in TFACE 3 (line 17) of object 2;"));
  EXPECT_THAT(message, HasSubstr("--split-parts"));
  EXPECT_THAT(input_error([&] { meccano::read_tsurf((dir_ / "parts.ts").string()); }), HasSubstr("3 parts"));
}

TEST_F(SurfaceIo, SurfacePartsAreNamedInFileOrder) {
  const std::vector<TriangleSurface> parts = meccano::read_surface_parts(write("faults.ts", kThreePartTsurf));
  ASSERT_EQ(parts.size(), 3U);
  EXPECT_EQ(parts[0].name, "faults_1");
  EXPECT_EQ(parts[1].name, "faults_2");
  EXPECT_EQ(parts[2].name, "faults_3");
  EXPECT_EQ(parts[1].source, (dir_ / "faults.ts").string());
  ASSERT_EQ(parts[0].triangles.size(), 1U);
  ASSERT_EQ(parts[1].triangles.size(), 2U);
  ASSERT_EQ(parts[2].triangles.size(), 1U);
  EXPECT_EQ(parts[1].points.size(), 4U);
  EXPECT_EQ(corner(parts[1], 1, 2), Eigen::Vector3d(6, 1, 0));
  EXPECT_EQ(corner(parts[2], 0, 0), Eigen::Vector3d(0, 0, 9));
  // Any format: the parts of an OBJ file too.
  const auto obj_parts = meccano::read_surface_parts(
      write("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf 1 2 3\nf 5 6 7\nf 4 3 2\n"));
  ASSERT_EQ(obj_parts.size(), 2U);  // the third triangle shares an edge with the first
  EXPECT_EQ(obj_parts[0].triangles.size(), 2U);
  EXPECT_EQ(obj_parts[0].points.size(), 4U);
  EXPECT_EQ(obj_parts[1].name, "two_2");
  EXPECT_EQ(corner(obj_parts[1], 0, 2), Eigen::Vector3d(5, 6, 5));
}

// 0.4 m apart: welded at 1 m. The triangle between them collapses and is dropped; one further away
// (2 m) is not welded.
std::string near_coincident_tsurf(const std::string& unit, double scale) {
  auto vertex = [scale](int id, double x, double y) {
    return "VRTX " + std::to_string(id) + " " + number(x * scale) + " " + number(y * scale) + " 0\n";
  };
  return "GOCAD TSurf 1\nGOCAD_ORIGINAL_COORDINATE_SYSTEM\nAXIS_UNIT " + unit + " " + unit + " " + unit +
         "\nEND_ORIGINAL_COORDINATE_SYSTEM\nTFACE\n" + vertex(1, 0, 0) + vertex(2, 100, 0) + vertex(3, 0, 100) +
         vertex(4, 100.4, 0) + vertex(5, 100, 100) + vertex(6, 102, 100) +
         "TRGL 1 2 3\nTRGL 3 4 5\nTRGL 2 4 5\nTRGL 4 6 5\nEND\n";
}

TEST_F(SurfaceIo, TsurfWeldsWithinOneMetreInItsUnitAndDropsCollapsedTriangles) {
  for (const auto& [unit, scale] : {std::pair{"\"m\"", 1.0}, std::pair{"km", 0.001}, std::pair{"ft", 1 / 0.3048}}) {
    SCOPED_TRACE(unit);
    meccano::SurfaceReadReport report;
    const std::string path = write("near.ts", near_coincident_tsurf(unit, scale));
    const TriangleSurface read = meccano::read_surface(path, {}, &report);
    EXPECT_EQ(report.welded_vertices, 1);
    EXPECT_EQ(report.degenerate_triangles, 1);
    EXPECT_EQ(report.duplicate_triangles, 0);
    ASSERT_EQ(read.triangles.size(), 3U);
    EXPECT_EQ(read.points.size(), 5U);
    EXPECT_EQ(read.triangles[1][1], read.triangles[0][1]);  // vertex 4 is vertex 2
  }
  // An unknown unit: 1e-6 of the diagonal (1.4e-4), which keeps them apart, and the triangles in two
  // parts.
  meccano::SurfaceReadReport report;
  const std::string unknown = write("unknown.ts", near_coincident_tsurf("furlong", 1.0));
  EXPECT_EQ(meccano::read_surface_parts(unknown, {}, &report).size(), 2U);
  EXPECT_EQ(report.welded_vertices, 0);
  // The caller's tolerance replaces the default; 2.5 m welds vertex 6 to vertex 5 too.
  const std::string metres = write("metres.ts", near_coincident_tsurf("m", 1.0));
  EXPECT_EQ(meccano::read_surface_parts(metres, {.weld_tolerance = 0.0}, &report).size(), 2U);
  EXPECT_EQ(report.welded_vertices + report.degenerate_triangles, 0);
  const TriangleSurface wide = meccano::read_surface(metres, {.weld_tolerance = 2.5}, &report);
  EXPECT_EQ(report.welded_vertices, 2);
  EXPECT_EQ(report.degenerate_triangles, 2);
  EXPECT_EQ(wide.triangles.size(), 2U);
}

TEST_F(SurfaceIo, WeldToleranceAppliesToEveryFormat) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1.001 0 0\nv 1 1 0\nf 1 2 3\nf 2 4 5\nf 2 5 3\nf 1 2 3\n";
  // By default nothing is dropped: the repeated triangle is left for the validation to report.
  meccano::SurfaceReadReport report;
  EXPECT_EQ(meccano::read_surface(write("t.obj", obj), {}, &report).triangles.size(), 4U);
  EXPECT_EQ(report.welded_vertices + report.degenerate_triangles + report.duplicate_triangles, 0);
  const TriangleSurface welded = meccano::read_surface(write("t.obj", obj), {.weld_tolerance = 0.01}, &report);
  EXPECT_EQ(welded.triangles.size(), 2U);
  EXPECT_EQ(welded.points.size(), 4U);
  EXPECT_EQ(report.welded_vertices, 1);
  EXPECT_EQ(report.degenerate_triangles, 1);
  EXPECT_EQ(report.duplicate_triangles, 1);
  // STL shares vertices by repeating them exactly: those merges are not counted as welds.
  meccano::read_surface(write("grid.stl", stl_ascii_text(grid_patch())), {}, &report);
  EXPECT_EQ(report.welded_vertices, 0);
}

TEST_F(SurfaceIo, TsurfErrorsNameTheLineAndTheDefect) {
  const std::string start = "GOCAD TSurf 1\nTFACE\nVRTX 1 0 0 0\nVRTX 2 1 0 0\n";  // lines 1-4
  const std::pair<std::string, std::string> cases[] = {
      {start + "VRTX 3 0 1 0\nTRGL 1 2 9\nEND\n",
       "bad.ts:6: TRGL refers to unknown vertex id 9 (no VRTX, PVRTX, ATOM or PATOM of the object defines it before)"},
      {start + "PVRTX 2 0 1 0 5\n", "bad.ts:5: vertex id 2 is defined twice in the object (first at line 4)"},
      {start + "ATOM 3 1\nATOM 1 2\n", "bad.ts:6: vertex id 1 is defined twice in the object (first at line 3)"},
      {start + "ATOM 3 7\n", "bad.ts:5: ATOM refers to unknown vertex id 7"},
      {start + "PATOM 3 x 1.0\n", "bad.ts:5: malformed vertex id 'x'"},
      {start + "VRTX 3 0 1.0.0 0\n", "bad.ts:5: malformed coordinate '1.0.0'"},
      {start + "VRTX 3 0 nan 0\n", "bad.ts:5: non-finite coordinate 'nan'"},
      {start + "VRTX 3 0 1e999 0\n", "bad.ts:5: non-finite coordinate '1e999'"},
      {start + "VRTX 3 0 1\nTRGL 1 2 3\n", "bad.ts:5: expected vertex coordinate before the end of the line"},
      {start + "TRGL 1 2\n", "bad.ts:5: expected vertex id before the end of the line"},
      {"GOCAD TSurf 1\nVRTX 1 0 0 0\n", "bad.ts:2: 'VRTX' outside a TFACE block (no TFACE since the object's start at "
                                        "line 1)"},
      {start + "END\nGOCAD TSurf 1\nTRGL 1 2 3\n", "bad.ts:7: 'TRGL' outside a TFACE block"},
      {start + "END\n", "bad.ts: no triangles in the file"},
      {start + "VRTX 3 0 0 1e-9\nTRGL 1 2 3\nEND\n", "bad.ts: no triangles left after welding: all 1 collapsed"},
      {"# exported\nsolid fault\n",
       "bad.ts:2: not a GOCAD TSurf file: it starts with 'solid' instead of 'GOCAD TSurf'"},
      {"# only a comment\n", "bad.ts:1: unexpected end of file (expected 'GOCAD TSurf' header)"},
      {"GOCAD PLine 1\nHEADER {name:trace}\nEND\n", "bad.ts:1: not a TSurf: a GOCAD 'PLine' object"},
      {start + "VRTX 3 0 1 0\nTRGL 1 2 3\nEND\nGOCAD Well 1\n", "bad.ts:8: not a TSurf: a GOCAD 'Well' object"},
      {start + "VRTX 3 0 1 0\nTRGL 1 2 3\nEND\nTFACE\n", "bad.ts:8: expected 'GOCAD TSurf' (another object) or the end "
                                                         "of the file after END, found 'TFACE'"},
      {start + "VRTX 3 0 1 0\nTRGL 1 2 3\n", "bad.ts:6: unexpected end of file (expected 'END' of the object that "
                                             "starts at line 1)"},
      {start + "GOCAD TSurf 1\n",
       "bad.ts:5: 'GOCAD' starts an object before the END of the object that starts at line 1"},
      {"GOCAD TSurf 1\nHEADER {\nname:x\n", "bad.ts:2: the 'HEADER' block has no closing '}'"},
  };
  for (const auto& [text, expected] : cases) EXPECT_THAT(read_error("bad.ts", text), HasSubstr(expected)) << text;
}

}  // namespace
