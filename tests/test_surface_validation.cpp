// require_surface_topology: valid disks pass, and each defect is reported with its element.
#include <meccano/error.hpp>
#include <meccano/surface/validation.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace {

using meccano::InputError;
using meccano::TriangleSurface;
using testing::HasSubstr;

TriangleSurface make_surface(std::vector<Eigen::Vector3d> points, std::vector<std::array<int, 3>> triangles) {
  TriangleSurface surface;
  surface.name = "patch";
  surface.source = "patch.obj";
  surface.points = std::move(points);
  surface.triangles = std::move(triangles);
  return surface;
}

// An (n+1) x (n+1) grid on a curved patch, 2 n^2 consistently oriented triangles.
TriangleSurface grid_patch(int n = 4) {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) points.emplace_back(0.25 * i, 0.5 * j, 0.125 * ((i * j) % 3));
  auto index = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  return make_surface(std::move(points), std::move(triangles));
}

// `sides` triangles around a centre vertex 0: a hexagon for 6.
TriangleSurface fan(int sides) {
  std::vector<Eigen::Vector3d> points = {{0, 0, 0}};
  std::vector<std::array<int, 3>> triangles;
  for (int k = 0; k < sides; ++k) {
    const double angle = 2 * std::numbers::pi * k / sides;
    points.emplace_back(std::cos(angle), std::sin(angle), 0.1 * (k % 2));
    triangles.push_back({0, 1 + k, 1 + (k + 1) % sides});
  }
  return make_surface(std::move(points), std::move(triangles));
}

TriangleSurface octahedron() {
  std::vector<Eigen::Vector3d> points = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<std::array<int, 3>> triangles;
  for (int k = 0; k < 4; ++k) {
    triangles.push_back({k, (k + 1) % 4, 4});
    triangles.push_back({(k + 1) % 4, k, 5});
  }
  return make_surface(std::move(points), std::move(triangles));
}

// A ring of 16 triangles between an inner and an outer square: two boundary loops.
TriangleSurface annulus() {
  std::vector<Eigen::Vector3d> points = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0},
                                         {2, 0, 0}, {0, 2, 0}, {-2, 0, 0}, {0, -2, 0}};
  std::vector<std::array<int, 3>> triangles;
  for (int k = 0; k < 4; ++k) {
    const int next = (k + 1) % 4;
    triangles.push_back({k, 4 + k, 4 + next});
    triangles.push_back({k, 4 + next, next});
  }
  return make_surface(std::move(points), std::move(triangles));
}

// A 4 x 4 torus (closed, genus 1), or with one triangle removed: one boundary loop but a handle
// (V - E + F = -1).
TriangleSurface torus(bool punctured) {
  constexpr int n = 4;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = 2 * std::numbers::pi * i / n;
      const double v = 2 * std::numbers::pi * j / n;
      points.emplace_back((2 + std::cos(v)) * std::cos(u), (2 + std::cos(v)) * std::sin(u), std::sin(v));
    }
  auto index = [](int i, int j) { return (i % n) * n + j % n; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  if (punctured) triangles.pop_back();
  return make_surface(std::move(points), std::move(triangles));
}

// The InputError's message; any other outcome fails the test.
std::string topology_error(const TriangleSurface& surface) {
  try {
    meccano::require_surface_topology(surface);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected InputError, nothing thrown";
  return {};
}

TEST(SurfaceTopology, ValidDisksPass) {
  EXPECT_NO_THROW(meccano::require_surface_topology(grid_patch()));
  EXPECT_NO_THROW(meccano::require_surface_topology(grid_patch(1)));
  EXPECT_NO_THROW(meccano::require_surface_topology(fan(6)));
  EXPECT_NO_THROW(meccano::require_surface_topology(make_surface({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{{0, 1, 2}}})));
}

TEST(SurfaceTopology, UnusedVerticesAreAllowed) {
  TriangleSurface surface = grid_patch();
  surface.points.emplace_back(9, 9, 9);
  EXPECT_NO_THROW(meccano::require_surface_topology(surface));
}

TEST(SurfaceTopology, NoTriangles) {
  EXPECT_THAT(topology_error(make_surface({{0, 0, 0}}, {})), HasSubstr("patch.obj: the surface has no triangles"));
}

TEST(SurfaceTopology, NonFiniteCoordinate) {
  TriangleSurface surface = grid_patch();
  surface.points[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(topology_error(surface), HasSubstr("patch.obj: vertex 3 has a non-finite coordinate"));
  surface.points[2].y() = std::numeric_limits<double>::infinity();
  EXPECT_THAT(topology_error(surface), HasSubstr("vertex 3 has a non-finite coordinate (0.5, inf, 0)"));
}

TEST(SurfaceTopology, IndexOutOfRange) {
  TriangleSurface surface = grid_patch();
  surface.triangles[1][2] = 25;
  EXPECT_THAT(topology_error(surface),
              HasSubstr("patch.obj: triangle 2 refers to vertex 26, out of range (the surface has vertices 1..25)"));
  surface.triangles[1][2] = -1;
  EXPECT_THAT(topology_error(surface), HasSubstr("triangle 2 refers to vertex 0, out of range"));
}

TEST(SurfaceTopology, RepeatedVertex) {
  TriangleSurface surface = grid_patch();
  surface.triangles[4] = {7, 8, 7};
  EXPECT_THAT(topology_error(surface), HasSubstr("patch.obj: triangle 5 repeats vertex 8"));
}

TEST(SurfaceTopology, ZeroAreaTriangle) {
  TriangleSurface surface = grid_patch();
  surface.points.emplace_back(0.125, 0.25, 0.0625);  // the midpoint of vertices 1 and 7
  surface.triangles.push_back({0, 25, 6});
  const std::string message = topology_error(surface);
  EXPECT_THAT(message, HasSubstr("patch.obj: triangle 33 has zero area (area "));
  EXPECT_THAT(message, HasSubstr("1e-14 x squared bounding-box diagonal"));
}

TEST(SurfaceTopology, DuplicateTriangle) {
  TriangleSurface surface = grid_patch();
  const auto [a, b, c] = surface.triangles[4];
  surface.triangles.push_back({b, c, a});
  EXPECT_THAT(topology_error(surface), HasSubstr("patch.obj: triangle 5 and triangle 33 are duplicates"));
  surface.triangles.back() = {a, c, b};  // the flipped copy is a duplicate too
  EXPECT_THAT(topology_error(surface), HasSubstr("triangle 5 and triangle 33 are duplicates"));
}

TEST(SurfaceTopology, NonManifoldEdge) {
  const TriangleSurface surface =
      make_surface({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}}, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  EXPECT_THAT(topology_error(surface),
              HasSubstr("patch.obj: non-manifold edge between vertex 1 and vertex 2: shared by 3 triangles (1, 2, 3)"));
}

TEST(SurfaceTopology, FlippedTriangle) {
  TriangleSurface surface = grid_patch();
  std::swap(surface.triangles[6][1], surface.triangles[6][2]);
  const std::string message = topology_error(surface);
  EXPECT_THAT(message, HasSubstr("patch.obj: inconsistent orientation: triangle"));
  EXPECT_THAT(message, HasSubstr("triangle 7 "));
  EXPECT_THAT(message, HasSubstr("both traverse their shared edge"));
}

TEST(SurfaceTopology, TwoComponents) {
  TriangleSurface surface = grid_patch();
  const int first = static_cast<int>(surface.points.size());
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(5, 0, 0), Eigen::Vector3d(6, 0, 0), Eigen::Vector3d(5, 1, 0)})
    surface.points.push_back(p);
  surface.triangles.insert(surface.triangles.begin() + 3, {first, first + 1, first + 2});
  EXPECT_THAT(topology_error(surface),
              HasSubstr("patch.obj: the surface has 2 connected components (triangle 4 is in the second one)"));
}

TEST(SurfaceTopology, BowTieVertex) {
  const TriangleSurface surface =
      make_surface({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}}, {{0, 1, 2}, {0, 3, 4}});
  EXPECT_THAT(topology_error(surface),
              HasSubstr("patch.obj: non-manifold vertex 1: its triangles form 2 separate fans instead of one "
                        "(e.g. triangle 1 and triangle 2 are in different fans)"));
}

TEST(SurfaceTopology, TwoFansOfAGridTouchingAtACorner) {
  // Two grids whose corners coincide: one connected component, pinched at the shared vertex.
  TriangleSurface surface = grid_patch(2);
  const int offset = static_cast<int>(surface.points.size());
  const TriangleSurface other = grid_patch(2);
  for (const Eigen::Vector3d& p : other.points) surface.points.push_back(p + Eigen::Vector3d(0.5, 1.0, 0.0));
  for (auto triangle : other.triangles) {
    for (int& v : triangle) v = v == 0 ? 8 : v + offset;  // the other grid's first point is this grid's last
    surface.triangles.push_back(triangle);
  }
  EXPECT_THAT(topology_error(surface),
              HasSubstr("patch.obj: non-manifold vertex 9: its triangles form 2 separate fans"));
}

TEST(SurfaceTopology, ClosedSurfacesOfGenusZeroPassOthersNot) {
  EXPECT_NO_THROW(meccano::require_surface_topology(octahedron()));
  EXPECT_THAT(topology_error(torus(false)),
              HasSubstr("patch.obj: closed surface of genus 1 (Euler characteristic V - E + F = 16 - 48 + 32 = 0 "
                        "instead of 2): only closed surfaces of genus 0 (spheres) are supported"));
}

TEST(SurfaceTopology, Annulus) {
  EXPECT_THAT(topology_error(annulus()), HasSubstr("patch.obj: not a topological disk: 2 boundary loops"));
}

TEST(SurfaceTopology, Handle) {
  EXPECT_THAT(topology_error(torus(true)),
              HasSubstr("patch.obj: not a topological disk: Euler characteristic V - E + F = 16 - 48 + 31 = -1"));
}

TEST(SurfaceTopology, ReportsTheFirstDefectInOrder) {
  // An octahedron plus a separate triangle: the components are reported first, before the topology of each.
  TriangleSurface surface = octahedron();
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(5, 0, 0), Eigen::Vector3d(6, 0, 0), Eigen::Vector3d(5, 1, 0)})
    surface.points.push_back(p);
  surface.triangles.push_back({6, 7, 8});
  EXPECT_THAT(topology_error(surface), HasSubstr("2 connected components"));
}

TEST(SurfaceTopology, MessageNamesTheSurface) {
  TriangleSurface surface = torus(false);
  surface.source.clear();
  EXPECT_THAT(topology_error(surface), HasSubstr("patch: closed surface of genus 1"));
  surface.name.clear();
  EXPECT_THAT(topology_error(surface), HasSubstr("surface: closed surface of genus 1"));
}

}  // namespace
