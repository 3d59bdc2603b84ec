// Floater parameterizations onto the unit square, corner matching and the composed projection
// φ(φ_M^{-1}(x)) of a blocky S_M onto S, checked on real test surfaces and a staircase S_M built here.
#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/stages/parameterization.hpp>
#include <meccano/surface/rim_chords.hpp>
#include <meccano/surface/validation.hpp>

#include "test_surfaces.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace meccano {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using ::testing::HasSubstr;

constexpr FloaterWeights both_weights[] = {FloaterWeights::mean_value, FloaterWeights::shape_preserving};

const char* weights_name(FloaterWeights weights) {
  return weights == FloaterWeights::mean_value ? "mean_value" : "shape_preserving";
}

double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double signed_area(const SquareParameterization& p, const std::array<int, 3>& t) {
  return 0.5 * cross2(p.uv[t[1]] - p.uv[t[0]], p.uv[t[2]] - p.uv[t[0]]);
}

// Position along the square's boundary, counter-clockwise from (0,0): side k covers [k, k + 1).
double boundary_parameter(const Vector2d& uv) {
  if (uv.y() == 0.0 && uv.x() < 1.0) return uv.x();
  if (uv.x() == 1.0 && uv.y() < 1.0) return 1.0 + uv.y();
  if (uv.y() == 1.0 && uv.x() > 0.0) return 3.0 - uv.x();
  return 4.0 - uv.y();
}

Vector2d uniform_point(std::mt19937_64& generator) {
  return {double(generator() >> 11) * 0x1.0p-53, double(generator() >> 11) * 0x1.0p-53};
}

// Every invariant of a SquareParameterization of `disk`.
void expect_bijective(DiskView disk, const SquareParameterization& p, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(p.uv.size(), disk.points.size());
  ASSERT_TRUE(p.orientation == 1 || p.orientation == -1);
  int flipped = 0;
  double total = 0.0;
  for (const auto& t : disk.triangles) {
    const double area = p.orientation * signed_area(p, t);
    flipped += !(area > 0.0);
    total += area;
  }
  EXPECT_EQ(flipped, 0);
  EXPECT_NEAR(total, 1.0, 1e-12);

  // The rim is rim_loop's loop, walked from corner 0 in the direction of the orientation, and it goes
  // once counter-clockwise around the square boundary, with the corners exactly at the corners.
  const std::vector<int> loop = rim_loop(disk);
  ASSERT_EQ(p.rim.size(), loop.size());
  ASSERT_EQ(p.rim.front(), p.corners[0]);
  const auto start = std::find(loop.begin(), loop.end(), p.rim.front()) - loop.begin();
  const auto n = static_cast<std::ptrdiff_t>(loop.size());
  for (std::ptrdiff_t i = 0; i < n; ++i) ASSERT_EQ(p.rim[i], loop[((start + p.orientation * i) % n + n) % n]);
  const Vector2d square[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int k = 0; k < 4; ++k) EXPECT_EQ(p.uv[p.corners[k]], square[k]) << "corner " << k;
  double previous = -1.0;
  for (int v : p.rim) {
    const Vector2d& uv = p.uv[v];
    EXPECT_TRUE(uv.x() == 0.0 || uv.x() == 1.0 || uv.y() == 0.0 || uv.y() == 1.0) << "rim vertex " << v;
    EXPECT_TRUE(uv.minCoeff() >= 0.0 && uv.maxCoeff() <= 1.0) << "rim vertex " << v;
    EXPECT_GT(boundary_parameter(uv), previous) << "rim vertex " << v;
    previous = boundary_parameter(uv);
  }
}

// ---------------------------------------------------------------------------------------------------

TEST(Parameterization, RimLoopKeepsTheDiskOnItsLeft) {
  const TriangleSurface plane = testing::tilted_plane(4);
  const std::vector<int> rim = rim_loop(plane);
  EXPECT_EQ(rim.size(), 16u);
  EXPECT_EQ(rim[0], 0);
  EXPECT_EQ(rim[1], 1);  // along the bottom row first: the disk (normals +z) is on the left
  // The vector area of the rim is the sum of the triangles' area vectors (Stokes).
  Vector3d triangles = Vector3d::Zero();
  for (const auto& t : plane.triangles)
    triangles += 0.5 * (plane.points[t[1]] - plane.points[t[0]]).cross(plane.points[t[2]] - plane.points[t[0]]);
  EXPECT_LT((vector_area(plane.points, rim) - triangles).norm(), 1e-15);
  EXPECT_GT(triangles.z(), 0.0);
}

TEST(Parameterization, EveryTestSurfaceMapsOneToOne) {
  int parameterizations = 0;
  for (const auto& named : testing::named_test_surfaces(10)) {
    for (const TriangleSurface& smooth : named.surfaces) {
      for (const TriangleSurface& surface : {smooth, testing::perturbed(smooth, 0.2, 7)}) {
        const std::array<int, 4> corners = corners_by_arc_length(surface);
        for (FloaterWeights weights : both_weights) {
          const SquareParameterization p = parameterize_to_square(surface, corners, weights);
          expect_bijective(surface, p, surface.name + " " + weights_name(weights));
          EXPECT_EQ(p.orientation, 1);
          ++parameterizations;
        }
      }
    }
  }
  EXPECT_EQ(parameterizations, 36);
}

TEST(Parameterization, RectangularRimsKeepTheirCorners) {
  // The curved sheet's rim is a 1.15 x 0.6 rectangle: quarters of the perimeter fall mid-side, but the
  // natural corners within 1/8 of them win, and they include both ears of the grid.
  const TriangleSurface sheet = testing::strongly_curved_sheet(6);  // 12 x 6 cells, vertex (i, j) = 13 j + i
  const std::array<int, 4> corners = corners_by_arc_length(sheet, 0);
  EXPECT_EQ(corners, (std::array<int, 4>{0, 12, 90, 78}));

  // Renumbered so that the rim loop starts mid-side, at (6, 0): the default start is a sharpest vertex,
  // so the same 4 corners come out, in some rotation.
  TriangleSurface renumbered = sheet;
  const auto renumber = [](int v) { return (v + 91 - 6) % 91; };
  for (std::size_t v = 0; v < sheet.points.size(); ++v)
    renumbered.points[renumber(static_cast<int>(v))] = sheet.points[v];
  for (auto& t : renumbered.triangles)
    for (int& v : t) v = renumber(v);
  ASSERT_EQ(rim_loop(renumbered).front(), 0);
  std::array<int, 4> found = corners_by_arc_length(renumbered);
  std::array<int, 4> expected{renumber(0), renumber(12), renumber(78), renumber(90)};
  std::sort(found.begin(), found.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(found, expected);
}

// Anchors pin rim vertices at given perimeter coordinates; between pins the rim is spaced by chord length,
// and without anchors the parameters are those of the corners alone, bit for bit.
TEST(Parameterization, AnchorsPinRimVerticesOnThePerimeter) {
  const TriangleSurface sheet = testing::strongly_curved_sheet(6);  // 12 x 6 cells, vertex (i, j) = 13 j + i
  const std::array<int, 4> corners{0, 12, 90, 78};
  const SquareParameterization plain = parameterize_to_square(sheet, corners);
  EXPECT_EQ(parameterize_to_square(sheet, corners, FloaterWeights::mean_value, {}).uv, plain.uv);
  // Vertex 3 (on side 0) pinned at 0.6, vertex 84 (on side 2, from 90 back to 78) at 2.25.
  const std::vector<RimAnchor> anchors{{3, 0.6}, {84, 2.25}};
  const SquareParameterization pinned = parameterize_to_square(sheet, corners, FloaterWeights::mean_value, anchors);
  EXPECT_EQ(perimeter_coordinate(pinned.uv[3]), 0.6);
  EXPECT_DOUBLE_EQ(perimeter_coordinate(pinned.uv[84]), 2.25);
  for (int corner = 0; corner < 4; ++corner) EXPECT_EQ(pinned.uv[corners[corner]], plain.uv[corners[corner]]);
  // Chord-length spacing between the pins: the rim vertices 1, 2 of the uniform side share 0.6 evenly.
  EXPECT_NEAR(pinned.uv[1].x(), 0.2, 1e-12);
  EXPECT_NEAR(pinned.uv[2].x(), 0.4, 1e-12);
  EXPECT_NEAR(pinned.uv[7].x(), 0.6 + 0.4 * 4.0 / 9.0, 1e-12);
  // Rim parameters stay on the square's sides.
  for (int v : pinned.rim) {
    const Vector2d& uv = pinned.uv[v];
    EXPECT_TRUE(uv.x() == 0.0 || uv.x() == 1.0 || uv.y() == 0.0 || uv.y() == 1.0) << v;
  }
  // Out of order, or off the rim: refused.
  const std::vector<RimAnchor> crossed{{3, 0.6}, {5, 0.5}};
  EXPECT_THROW(parameterize_to_square(sheet, corners, FloaterWeights::mean_value, crossed), std::invalid_argument);
  const std::vector<RimAnchor> inside{{20, 0.5}};
  EXPECT_THROW(parameterize_to_square(sheet, corners, FloaterWeights::mean_value, inside), std::invalid_argument);
}

TEST(Parameterization, CircularRimGetsQuarterCorners) {
  const TriangleSurface cap = testing::spherical_cap(12);  // 72 rim vertices, no natural corner
  const std::array<int, 4> corners = corners_by_arc_length(cap);
  const std::vector<int> rim = rim_loop(cap);
  std::array<std::ptrdiff_t, 4> at{};
  for (int k = 0; k < 4; ++k) at[k] = std::find(rim.begin(), rim.end(), corners[k]) - rim.begin();
  for (int k = 0; k < 4; ++k) EXPECT_EQ((at[(k + 1) % 4] - at[k] + 72) % 72, 18) << "side " << k;
  for (FloaterWeights weights : both_weights)
    expect_bijective(cap, parameterize_to_square(cap, corners, weights), weights_name(weights));
}

TEST(Parameterization, EarOffTheCornersIsRepaired) {
  // Grid vertex (i, j) of tilted_plane(8) is 9 j + i; (8, 0) is the apex of an ear. Starting at (7, 0)
  // the natural corners (8, 8), (0, 8), (0, 0) are taken and corner 0 steps onto the ear's apex; the
  // same happens when S_M's corners are matched to those positions.
  const TriangleSurface plane = testing::tilted_plane(8);
  const std::array<int, 4> expected{8, 80, 72, 0};
  EXPECT_EQ(corners_by_arc_length(plane, 7), expected);
  const std::array<Vector3d, 4> targets{plane.points[7], plane.points[80], plane.points[72], plane.points[0]};
  EXPECT_EQ(matching_corners(plane, targets, vector_area(plane.points, rim_loop(plane))), expected);
}

// ---------------------------------------------------------------------------------------------------
// Planar disks: Floater's weights have linear precision, so with the rim affine the map is affine.

TEST(Parameterization, PlanarGridIsMappedAffinely) {
  // Graded spacing (x' = 0.2 + 0.6 s^1.5) makes the rim's chord lengths uneven; the perturbation makes the
  // interior irregular. The square [0.2, 0.8]^2 must still map to P by its normalised coordinates.
  const auto flat = [](double, double) { return 0.5; };
  const TriangleSurface square = testing::graph_patch(flat, {0.2, 0.8}, {0.2, 0.8}, 9, "square");
  TriangleSurface graded = square;
  for (Vector3d& x : graded.points) x.x() = 0.2 + 0.6 * std::pow((x.x() - 0.2) / 0.6, 1.5);
  for (const TriangleSurface& surface : {square, testing::perturbed(square, 0.25, 3), graded}) {
    const std::array<int, 4> corners = corners_by_arc_length(surface, 0);
    ASSERT_EQ(corners, (std::array<int, 4>{0, 9, 99, 90}));
    for (FloaterWeights weights : both_weights) {
      const SquareParameterization p = parameterize_to_square(surface, corners, weights);
      double worst = 0.0;
      for (std::size_t v = 0; v < surface.points.size(); ++v) {
        const Vector2d expected = (surface.points[v].head<2>() - Vector2d(0.2, 0.2)) / 0.6;
        worst = std::max(worst, (p.uv[v] - expected).cwiseAbs().maxCoeff());
      }
      EXPECT_LT(worst, 1e-12) << weights_name(weights);
    }
  }
}

TEST(Parameterization, TiltedPlaneIsReproducedExactly) {
  const TriangleSurface plane = testing::tilted_plane(12);
  const std::array<int, 4> corners = corners_by_arc_length(plane);
  std::vector<int> sorted(corners.begin(), corners.end());
  std::sort(sorted.begin(), sorted.end());
  ASSERT_EQ(sorted, (std::vector<int>{0, 12, 156, 168}));  // the parallelogram's corners, in some rotation
  for (FloaterWeights weights : both_weights) {
    SCOPED_TRACE(weights_name(weights));
    const ParametricSurface phi(plane, parameterize_to_square(plane, corners, weights));
    const Vector3d& origin = plane.points[corners[0]];
    const Vector3d du = plane.points[corners[1]] - origin;
    const Vector3d dv = plane.points[corners[3]] - origin;
    const auto affine = [&](const Vector2d& uv) -> Vector3d { return origin + uv.x() * du + uv.y() * dv; };
    std::mt19937_64 generator(11);
    double worst = 0.0;
    for (int q = 0; q < 1000; ++q) {
      const Vector2d uv = uniform_point(generator);
      worst = std::max(worst, (phi.evaluate(phi.locate(uv)) - affine(uv)).norm());
    }
    EXPECT_LT(worst, 1e-12);
    for (std::size_t v = 0; v < plane.points.size(); ++v)
      EXPECT_LT((affine(phi.parameterization().uv[v]) - plane.points[v]).norm(), 1e-12) << "vertex " << v;
    Eigen::Matrix<double, 3, 2> expected;
    expected << du, dv;
    for (int t = 0; t < phi.triangle_count(); ++t) EXPECT_LT((phi.derivative(t) - expected).norm(), 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------------
// A blocky S_M: the upper boundary of voxel columns under a graph surface. `graph` is an m x m cell grid
// patch (testing::graph_patch numbering, vertex (i, j) = (m + 1) j + i) with square cells of size h; column
// (i, j) rises to the level (a multiple of h) nearest the mean height of its cell's 4 vertices. Tops and
// risers are h x h lattice squares, each split into two right triangles and oriented outwards (tops +z,
// risers towards the lower column): every face lies on a coordinate plane and the rim is a staircase of
// axis-parallel edges.
TriangleSurface staircase_under(const TriangleSurface& graph, int m) {
  const Vector3d origin = graph.points.front();
  const double h = graph.points[1].x() - origin.x();
  TriangleSurface surface;
  surface.name = "staircase";
  std::map<std::array<int, 3>, int> lattice;
  const auto node = [&](int i, int j, int l) {
    const auto [it, added] = lattice.try_emplace({i, j, l}, static_cast<int>(surface.points.size()));
    if (added) surface.points.emplace_back(origin.x() + i * h, origin.y() + j * h, l * h);
    return it->second;
  };
  // Square a b c d, counter-clockwise seen from the side its normal points to.
  const auto square = [&](int a, int b, int c, int d) {
    surface.triangles.push_back({a, b, c});
    surface.triangles.push_back({a, c, d});
  };
  const auto height = [&](int i, int j) { return graph.points[(m + 1) * j + i].z(); };
  std::vector<std::vector<int>> level(m, std::vector<int>(m));
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      level[i][j] = static_cast<int>(
          std::lround((height(i, j) + height(i + 1, j) + height(i + 1, j + 1) + height(i, j + 1)) / (4 * h)));
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const int k = level[i][j];
      square(node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k));
      if (i + 1 < m) {  // riser in the plane x = i + 1, normal +x when column (i, j) is the higher
        for (int l = std::min(k, level[i + 1][j]); l < std::max(k, level[i + 1][j]); ++l) {
          const int a = node(i + 1, j, l), b = node(i + 1, j + 1, l), c = node(i + 1, j + 1, l + 1),
                    d = node(i + 1, j, l + 1);
          k > level[i + 1][j] ? square(a, b, c, d) : square(d, c, b, a);
        }
      }
      if (j + 1 < m) {  // riser in the plane y = j + 1, normal +y when column (i, j) is the higher
        for (int l = std::min(k, level[i][j + 1]); l < std::max(k, level[i][j + 1]); ++l) {
          const int a = node(i, j + 1, l), b = node(i + 1, j + 1, l), c = node(i + 1, j + 1, l + 1),
                    d = node(i, j + 1, l + 1);
          k > level[i][j + 1] ? square(d, c, b, a) : square(a, b, c, d);
        }
      }
    }
  }
  return surface;
}

TriangleSurface flipped(TriangleSurface surface) {
  for (auto& t : surface.triangles) std::swap(t[1], t[2]);
  return surface;
}

double segment_distance(const Vector3d& x, const Vector3d& a, const Vector3d& b) {
  const double t = std::clamp((x - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (x - (a + t * (b - a))).norm();
}

// Projects every S_M vertex with φ(φ_M^{-1}(x)) and checks that it lands on S (rim vertices on S's rim),
// near where it was, and that no triangle is turned over: its image faces like S_M's triangles do.
void expect_projection_onto(const TriangleSurface& s, const TriangleSurface& s_m, FloaterWeights weights,
                            double spacing) {
  SCOPED_TRACE(std::string(weights_name(weights)) + (s_m.name.empty() ? "" : " " + s_m.name));
  const std::array<int, 4> corners = corners_by_arc_length(s);
  const ParametricSurface phi(s, parameterize_to_square(s, corners, weights));
  const std::vector<int> s_rim = rim_loop(s);
  const Vector3d normal = vector_area(s.points, s_rim);
  std::array<Vector3d, 4> targets;
  for (int k = 0; k < 4; ++k) targets[k] = s.points[corners[k]];
  const std::array<int, 4> m_corners = matching_corners(s_m, targets, normal);
  const SquareParameterization m = parameterize_to_square(s_m, m_corners, weights);
  expect_bijective(s_m, m, "S_M");
  const int facing = vector_area(s_m.points, rim_loop(s_m)).dot(normal) > 0 ? 1 : -1;
  EXPECT_EQ(m.orientation, facing);
  for (int k = 0; k < 4; ++k) EXPECT_LT((s_m.points[m_corners[k]] - targets[k]).norm(), spacing) << "corner " << k;

  const TriangleBVH tree(s);
  const double tolerance = 1e-12 * tree.bounds().diagonal().norm();
  std::vector<Vector3d> image(s_m.points.size());
  double off_surface = 0.0, off_rim = 0.0, moved = 0.0;
  int hint = -1;
  for (std::size_t v = 0; v < s_m.points.size(); ++v) {
    const ParametricSurface::Location location = phi.locate(m.uv[v], hint);
    hint = location.triangle;
    image[v] = phi.evaluate(location);
    off_surface = std::max(off_surface, std::sqrt(tree.closest_point(image[v]).squared_distance));
    moved = std::max(moved, (image[v] - s_m.points[v]).norm());
  }
  for (int v : m.rim) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < s_rim.size(); ++i)
      nearest =
          std::min(nearest, segment_distance(image[v], s.points[s_rim[i]], s.points[s_rim[(i + 1) % s_rim.size()]]));
    off_rim = std::max(off_rim, nearest);
  }
  for (int k = 0; k < 4; ++k) EXPECT_LT((image[m_corners[k]] - targets[k]).norm(), tolerance) << "corner " << k;
  EXPECT_LT(off_surface, tolerance);
  EXPECT_LT(off_rim, tolerance);
  // Risers shift S_M's parameters by up to about 2 h (measured: 1.97 h); a mirrored or twisted map would
  // carry vertices across the patch, 0.6 wide.
  EXPECT_LT(moved, 3.0 * spacing);
  int turned = 0;
  for (const auto& t : s_m.triangles) {
    const Vector3d n = (image[t[1]] - image[t[0]]).cross(image[t[2]] - image[t[0]]);
    const Vector3d centre = (image[t[0]] + image[t[1]] + image[t[2]]) / 3.0;
    const auto& closest = tree.triangle(tree.closest_point(centre).triangle);
    turned += facing * n.dot((closest[1] - closest[0]).cross(closest[2] - closest[0])) <= 0.0;
  }
  EXPECT_EQ(turned, 0);
}

TEST(Parameterization, StaircaseIsProjectedOntoTheSmoothSurface) {
  const TriangleSurface s = testing::paper_like_patch(20);
  const TriangleSurface s_m = staircase_under(testing::paper_like_patch(16), 16);
  ASSERT_GT(s_m.triangles.size(), 2u * 16 * 16);  // risers present
  for (FloaterWeights weights : both_weights) expect_projection_onto(s, s_m, weights, 0.6 / 16);
}

TEST(Parameterization, StaircaseOrientedAgainstSIsMatchedWithoutTwist) {
  const TriangleSurface s = testing::paper_like_patch(20);
  const TriangleSurface s_m = staircase_under(testing::paper_like_patch(16), 16);
  const TriangleSurface against = flipped(s_m);
  for (FloaterWeights weights : both_weights) expect_projection_onto(s, against, weights, 0.6 / 16);

  // Same corners and the same parameters: only the sign of the parametric areas changes.
  const std::array<int, 4> corners = corners_by_arc_length(s);
  std::array<Vector3d, 4> targets;
  for (int k = 0; k < 4; ++k) targets[k] = s.points[corners[k]];
  const Vector3d normal = vector_area(s.points, rim_loop(s));
  const std::array<int, 4> along = matching_corners(s_m, targets, normal);
  ASSERT_EQ(matching_corners(against, targets, normal), along);
  const SquareParameterization p = parameterize_to_square(s_m, along);
  const SquareParameterization q = parameterize_to_square(against, along);
  EXPECT_EQ(p.orientation, 1);
  EXPECT_EQ(q.orientation, -1);
  double worst = 0.0;
  for (std::size_t v = 0; v < p.uv.size(); ++v) worst = std::max(worst, (p.uv[v] - q.uv[v]).norm());
  EXPECT_LT(worst, 1e-12);
}

// ---------------------------------------------------------------------------------------------------
// Point location.

TEST(ParameterizationLocate, LocateAgreesWithBruteForce) {
  const TriangleSurface s = testing::perturbed(testing::paper_like_patch(24), 0.2, 5);
  const SquareParameterization p = parameterize_to_square(s, corners_by_arc_length(s));
  const ParametricSurface phi(s, p);
  std::mt19937_64 generator(17);
  for (int q = 0; q < 2000; ++q) {
    const Vector2d uv = uniform_point(generator);
    const ParametricSurface::Location location = phi.locate(uv);
    ASSERT_GE(location.barycentric.minCoeff(), 0.0);
    ASSERT_NEAR(location.barycentric.sum(), 1.0, 1e-15);
    int brute = -1;
    double best = -1.0;
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
      const auto& tri = s.triangles[t];
      const double area = signed_area(p, tri);
      const double b0 = 0.5 * cross2(p.uv[tri[1]] - uv, p.uv[tri[2]] - uv) / area;
      const double b1 = 0.5 * cross2(p.uv[tri[2]] - uv, p.uv[tri[0]] - uv) / area;
      const double smallest = std::min({b0, b1, 1.0 - b0 - b1});
      if (smallest > best) {
        best = smallest;
        brute = static_cast<int>(t);
      }
    }
    ASSERT_EQ(location.triangle, brute) << "uv " << uv.transpose();
    const auto& tri = s.triangles[brute];
    Vector2d back = Vector2d::Zero();
    Vector3d x = Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      back += location.barycentric[k] * p.uv[tri[k]];
      x += location.barycentric[k] * s.points[tri[k]];
    }
    EXPECT_LT((back - uv).norm(), 1e-14);
    EXPECT_LT((phi.evaluate(location) - x).norm(), 1e-15);
  }
}

TEST(ParameterizationLocate, WalksFindTheSameTriangle) {
  const TriangleSurface s = testing::perturbed(testing::saddle(24), 0.2, 9);
  const ParametricSurface phi(s, parameterize_to_square(s, corners_by_arc_length(s)));
  std::mt19937_64 generator(23);
  int far_walks = 0;
  for (int q = 0; q < 2000; ++q) {
    const Vector2d uv = uniform_point(generator);
    const int expected = phi.locate(uv).triangle;
    // A nearby previous point (about one triangle away): the hinted walk arrives.
    const Vector2d previous = (uv + 0.04 * (uniform_point(generator) - Vector2d(0.5, 0.5))).cwiseMax(0.0).cwiseMin(1.0);
    const int hint = phi.locate(previous).triangle;
    ASSERT_TRUE(phi.walk(uv, hint, 32).has_value()) << "uv " << uv.transpose();
    EXPECT_EQ(phi.walk(uv, hint, 32)->triangle, expected);
    EXPECT_EQ(phi.locate(uv, hint).triangle, expected);
    // From anywhere, with no step limit, the straight walk arrives too.
    const int start = static_cast<int>(generator() % s.triangles.size());
    const auto far = phi.walk(uv, start, phi.triangle_count());
    far_walks += far.has_value();
    if (far) {
      EXPECT_EQ(far->triangle, expected);
    }
  }
  EXPECT_EQ(far_walks, 2000);
}

// Whether the segment pq meets the interior of triangle abc (separating axes: the 3 edge normals and the
// segment's normal).
bool segment_meets_triangle(const Vector2d& p, const Vector2d& q, const std::array<Vector2d, 3>& tri) {
  const auto separated = [&](const Vector2d& direction) {
    const Vector2d axis(-direction.y(), direction.x());
    const double t_lo = std::min({axis.dot(tri[0]), axis.dot(tri[1]), axis.dot(tri[2])});
    const double t_hi = std::max({axis.dot(tri[0]), axis.dot(tri[1]), axis.dot(tri[2])});
    return std::max(axis.dot(p), axis.dot(q)) <= t_lo || t_hi <= std::min(axis.dot(p), axis.dot(q));
  };
  return !separated(q - p) && !separated(tri[1] - tri[0]) && !separated(tri[2] - tri[1]) && !separated(tri[0] - tri[2]);
}

TEST(ParameterizationLocate, WalkIsStraight) {
  // The walk visits exactly the triangles that the segment from the start's centroid to the target
  // crosses: it arrives in (crossed - 1) steps and not in fewer.
  const TriangleSurface s = testing::perturbed(testing::spherical_cap(12), 0.2, 13);
  const SquareParameterization p = parameterize_to_square(s, corners_by_arc_length(s));
  const ParametricSurface phi(s, p);
  std::mt19937_64 generator(37);
  for (int q = 0; q < 200; ++q) {
    const Vector2d target = uniform_point(generator);
    const int start = static_cast<int>(generator() % s.triangles.size());
    const auto& first = s.triangles[start];
    const Vector2d centroid = (p.uv[first[0]] + p.uv[first[1]] + p.uv[first[2]]) / 3.0;
    int crossed = 0;
    for (const auto& t : s.triangles)
      crossed += segment_meets_triangle(centroid, target, {p.uv[t[0]], p.uv[t[1]], p.uv[t[2]]});
    ASSERT_GE(crossed, 1);
    EXPECT_TRUE(phi.walk(target, start, crossed - 1).has_value()) << "query " << q;
    if (crossed > 1) {
      EXPECT_FALSE(phi.walk(target, start, crossed - 2).has_value()) << "query " << q;
    }
  }
}

TEST(ParameterizationLocate, ConcurrentQueriesMatchSerialOnes) {
  const TriangleSurface s = testing::spherical_cap(16);
  const ParametricSurface phi(s, parameterize_to_square(s, corners_by_arc_length(s)));
  std::mt19937_64 generator(29);
  std::vector<Vector2d> points(4000);
  for (Vector2d& uv : points) uv = uniform_point(generator);
  std::vector<Vector3d> serial(points.size()), parallel(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) serial[i] = phi.evaluate(phi.locate(points[i], i ? 0 : -1));
#pragma omp parallel for num_threads(4)
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
    parallel[i] = phi.evaluate(phi.locate(points[i], i ? 0 : -1));
  EXPECT_EQ(serial, parallel);
}

TEST(ParameterizationLocate, PointsOnEdgesLandOnTheEdges) {
  // Rounding puts an edge's midpoint slightly outside one of its two triangles; located from either
  // (the walk accepts it at once), the location is still valid and evaluates to the 3D midpoint.
  const TriangleSurface s = testing::perturbed(testing::saddle(12), 0.2, 41);
  const SquareParameterization p = parameterize_to_square(s, corners_by_arc_length(s));
  const ParametricSurface phi(s, p);
  for (int t = 0; t < phi.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
      const ParametricSurface::Location location = phi.locate(0.5 * (p.uv[a] + p.uv[b]), t);
      EXPECT_EQ(location.triangle, t);
      ASSERT_GE(location.barycentric.minCoeff(), 0.0);
      EXPECT_LT((phi.evaluate(location) - 0.5 * (s.points[a] + s.points[b])).norm(), 1e-15);
    }
  }
}

TEST(ParameterizationLocate, DerivativeIsTheSlopeWithinATriangle) {
  const TriangleSurface s = testing::strongly_curved_sheet(8);
  for (FloaterWeights weights : both_weights) {
    const ParametricSurface phi(s, parameterize_to_square(s, corners_by_arc_length(s), weights));
    const std::vector<Vector2d>& uv_of = phi.parameterization().uv;
    std::mt19937_64 generator(31);
    for (int q = 0; q < 1000; ++q) {
      const Vector2d uv = uniform_point(generator);
      const ParametricSurface::Location here = phi.locate(uv);
      const auto& tri = s.triangles[here.triangle];
      const Vector2d step = 0.01 * ((uv_of[tri[0]] + uv_of[tri[1]] + uv_of[tri[2]]) / 3.0 - uv);
      const auto there = phi.walk(uv + step, here.triangle, 0);  // towards the centroid: same triangle
      ASSERT_TRUE(there.has_value());
      const Vector3d difference = phi.evaluate(*there) - phi.evaluate(here);
      EXPECT_LT((phi.derivative(here.triangle) * step - difference).norm(), 1e-12 * difference.norm() + 1e-15);
    }
  }
}

TEST(ParameterizationLocate, PointsOutsideTheSquareAreClamped) {
  const TriangleSurface s = testing::paper_like_patch(8);
  const std::array<int, 4> corners = corners_by_arc_length(s, 0);
  const ParametricSurface phi(s, parameterize_to_square(s, corners));
  EXPECT_LT((phi.evaluate(phi.locate({-0.5, 1.5})) - s.points[corners[3]]).norm(), 1e-15);
  EXPECT_LT((phi.evaluate(phi.locate({2.0, -1.0}, 0)) - s.points[corners[1]]).norm(), 1e-15);
  EXPECT_THROW(phi.locate({std::nan(""), 0.5}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------
// Errors.

template <class Call>
std::string meshing_error(Call&& call) {
  try {
    call();
  } catch (const MeshingError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a MeshingError";
  return {};
}

TEST(Parameterization, TriangleOnOneSideIsReported) {
  // Corners (0,0), (8,1), (8,8), (0,8) of tilted_plane(8): the ear at (8,0) has all vertices on side 0.
  const TriangleSurface plane = testing::tilted_plane(8);
  const std::string message = meshing_error([&] { parameterize_to_square(plane, {0, 17, 80, 72}); });
  EXPECT_THAT(message, HasSubstr("triangle 14 (vertices 7, 8, 17) has all three vertices on side 0"));
}

TEST(Parameterization, DividingEdgeOnOneSideIsReported) {
  // A hexagon a..f split by the interior edge a-d into two quads, each a fan around an inner vertex.
  TriangleSurface hexagon;
  for (int k = 0; k < 6; ++k)
    hexagon.points.emplace_back(std::cos(k * std::numbers::pi / 3), std::sin(k * std::numbers::pi / 3), 0.0);
  hexagon.points.emplace_back(0.0, 0.5, 0.0);   // 6, inside a b c d
  hexagon.points.emplace_back(0.0, -0.5, 0.0);  // 7, inside d e f a
  hexagon.triangles = {{0, 1, 6}, {1, 2, 6}, {2, 3, 6}, {3, 0, 6}, {3, 4, 7}, {4, 5, 7}, {5, 0, 7}, {0, 3, 7}};
  const std::string message = meshing_error([&] { parameterize_to_square(hexagon, {0, 3, 4, 5}); });
  EXPECT_THAT(message, HasSubstr("interior edge 0-3 joins two vertices of side 0"));
  expect_bijective(hexagon, parameterize_to_square(hexagon, corners_by_arc_length(hexagon)), "repaired");
}

TEST(Parameterization, RimThatIsNotOneLoopIsReported) {
  TriangleSurface annulus = testing::tilted_plane(3);
  annulus.triangles.erase(annulus.triangles.begin() + 8, annulus.triangles.begin() + 10);  // the middle cell
  EXPECT_THAT(meshing_error([&] { rim_loop(annulus); }), HasSubstr("not one loop"));

  TriangleSurface bowtie;
  bowtie.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
  EXPECT_THAT(meshing_error([&] { rim_loop(bowtie); }), HasSubstr("pinched at vertex 0"));

  TriangleSurface twisted = testing::tilted_plane(3);
  std::swap(twisted.triangles[4][1], twisted.triangles[4][2]);
  EXPECT_THAT(meshing_error([&] { rim_loop(twisted); }), HasSubstr("same direction"));
}

TEST(Parameterization, SurfacesThatAreNotDisksAreReported) {
  TriangleSurface tetrahedron;
  tetrahedron.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  EXPECT_THAT(meshing_error([&] { rim_loop(tetrahedron); }), HasSubstr("no rim"));

  // A 4 x 4 torus grid less one triangle: one rim loop of 3 edges, but Euler characteristic -1.
  TriangleSurface torus;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      const double a = i * std::numbers::pi / 2, b = j * std::numbers::pi / 2;
      torus.points.emplace_back((2 + std::cos(b)) * std::cos(a), (2 + std::cos(b)) * std::sin(a), std::sin(b));
    }
  }
  const auto vertex = [](int i, int j) { return (j % 4) * 4 + i % 4; };
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      torus.triangles.push_back({vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)});
      torus.triangles.push_back({vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
    }
  }
  torus.triangles.pop_back();
  EXPECT_THAT(meshing_error([&] { rim_loop(torus); }), HasSubstr("not a disk: Euler characteristic -1"));
}

TEST(Parameterization, CornersMustBeRimVerticesInCyclicOrder) {
  const TriangleSurface plane = testing::tilted_plane(4);
  EXPECT_THROW(parameterize_to_square(plane, {0, 6, 24, 20}), std::invalid_argument);  // 6 is interior
  EXPECT_THROW(parameterize_to_square(plane, {0, 24, 4, 20}), std::invalid_argument);  // not cyclic
  EXPECT_EQ(parameterize_to_square(plane, {0, 20, 24, 4}).orientation, -1);            // cyclic, against the rim
}

// ---------------------------------------------------------------------------------------------------
// Rim chords (surface/rim_chords.hpp): interior edges joining two rim vertices.

TEST(RimChords, ASawtoothRimMapsOneToOneOnceItsChordsAreSplit) {
  // Each tooth's base is a chord with the tooth's apex alone on its short arc: a corner must sit on every
  // apex, and eight teeth need more than four corners.
  const TriangleSurface patch = testing::sawtooth_patch(8);
  ASSERT_EQ(count_rim_chords(patch), 8 + 2);  // and the grid's own, cutting off its corners (8, 0) and (0, 8)
  EXPECT_THAT(meshing_error([&] { corners_by_arc_length(patch); }), HasSubstr("no choice of corners"));

  const TriangleSurface split = split_rim_chords(patch);
  EXPECT_EQ(count_rim_chords(split), 0);
  ASSERT_EQ(split.points.size(), patch.points.size() + 10);
  EXPECT_EQ(split.triangles.size(), patch.triangles.size() + 20);
  for (std::size_t i = 0; i < patch.points.size(); ++i) EXPECT_EQ(split.points[i], patch.points[i]) << "point " << i;
  EXPECT_NO_THROW(require_surface_topology(split));
  EXPECT_EQ(rim_loop(split), rim_loop(patch));
  EXPECT_NEAR(surface_area(split), surface_area(patch), 1e-14);
  // Each new point is the midpoint of a chord, so it lies on the patch: the geometry did not change.
  const TriangleBVH tree(patch);
  for (std::size_t i = patch.points.size(); i < split.points.size(); ++i)
    EXPECT_LT(tree.closest_point(split.points[i]).squared_distance, 1e-30) << "point " << i;
  for (FloaterWeights weights : both_weights)
    expect_bijective(split, parameterize_to_square(split, corners_by_arc_length(split), weights),
                     weights_name(weights));
}

TEST(RimChords, AreSplitAlikeWhateverThePoints) {
  // A moving surface keeps its triangulation: its split must not depend on where its points are.
  const TriangleSurface patch = testing::sawtooth_patch(6);
  TriangleSurface moved = patch;
  for (Vector3d& p : moved.points) p = Vector3d(p.z(), -p.x(), 2.0 * p.y());
  EXPECT_EQ(split_rim_chords(moved).triangles, split_rim_chords(patch).triangles);
}

TEST(RimChords, ASurfaceWithoutChordsIsUnchanged) {
  const TriangleSurface cap = testing::spherical_cap(6);
  ASSERT_EQ(count_rim_chords(cap), 0);
  const TriangleSurface split = split_rim_chords(cap);
  EXPECT_EQ(split.points, cap.points);
  EXPECT_EQ(split.triangles, cap.triangles);
}

}  // namespace
}  // namespace meccano
