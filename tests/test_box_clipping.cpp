// Clipping a surface to the box (surface/box_clipping.hpp): the part inside, its rim exactly on the box
// planes where S crosses them, one surface per part, and clear errors for what cannot be inserted.

#include <meccano/error.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/validation.hpp>

#include <test_surfaces.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <vector>

namespace meccano {
namespace {

using ::testing::HasSubstr;

const Box kUnitBox{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};

double area(const TriangleSurface& s) {
  double sum = 0.0;
  for (const auto& t : s.triangles)
    sum += 0.5 * (s.points[t[1]] - s.points[t[0]]).cross(s.points[t[2]] - s.points[t[0]]).norm();
  return sum;
}

// Rim vertices lie on box planes exactly or inside; interior vertices strictly inside.
void expect_rim_on_box_planes(const TriangleSurface& s, const Box& box) {
  std::vector<std::uint8_t> rim(s.points.size(), 0);
  for (const auto& [a, b] : testing::rim_edges(s)) rim[a] = rim[b] = 1;
  for (std::size_t v = 0; v < s.points.size(); ++v) {
    const Eigen::Array3d p = s.points[v].array();
    EXPECT_TRUE((p >= box.min.array()).all() && (p <= box.max.array()).all()) << v;
    if (!rim[v]) {
      EXPECT_EQ(box_sides(s.points[v], box), 0) << "interior vertex " << v << " on the box";
    }
  }
  EXPECT_NO_THROW(require_surface_topology(s));
  EXPECT_NO_THROW(require_inside_box(s, box));
}

TEST(BoxClipping, APlaneAcrossTheBoxKeepsTheUnitSquare) {
  const TriangleSurface plane =
      testing::graph_patch([](double, double) { return 0.5; }, {-0.3, 1.3}, {-0.2, 1.4}, 13, "plane");
  const std::vector<TriangleSurface> parts = clip_to_box(plane, kUnitBox);
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_EQ(parts[0].name, plane.name);
  EXPECT_NEAR(area(parts[0]), 1.0, 1e-12);
  expect_rim_on_box_planes(parts[0], kUnitBox);
  EXPECT_TRUE(reaches_box(parts[0], kUnitBox));
  int on_box = 0;
  for (const auto& p : parts[0].points) on_box += box_sides(p, kUnitBox) != 0;
  EXPECT_GT(on_box, 4 * 13);
}

// A vertex of S 1e-5 inside a plane moves onto it rather than leaving a sliver beside the crossing.
TEST(BoxClipping, AVertexNearlyOnAPlaneMovesOntoIt) {
  TriangleSurface plane = testing::graph_patch([](double, double) { return 0.5; }, {-0.2, 1.2}, {0.2, 0.8}, 14);
  // Grid x = -0.2 + 0.1 i: the vertices at i = 2 lie at x = 0, shift them 1e-5 inside.
  for (Eigen::Vector3d& p : plane.points)
    if (std::abs(p.x()) < 1e-9) p.x() = 1e-5;
  const TriangleSurface part = clip_to_box(plane, kUnitBox).front();
  expect_rim_on_box_planes(part, kUnitBox);
  const auto smallest_angle = [](const TriangleSurface& s) {
    double smallest = std::numbers::pi;
    for (const auto& t : s.triangles)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d a = s.points[t[(k + 1) % 3]] - s.points[t[k]];
        const Eigen::Vector3d b = s.points[t[(k + 2) % 3]] - s.points[t[k]];
        smallest = std::min(smallest, std::acos(a.normalized().dot(b.normalized())));
      }
    return smallest;
  };
  EXPECT_GT(smallest_angle(part), 0.99 * smallest_angle(plane)) << "a sliver next to the cut";
}

TEST(BoxClipping, ACornerCutOffIsATriangleWithThreeCornersOnBoxEdges) {
  const TriangleSurface plane =
      testing::graph_patch([](double x, double y) { return 0.6 - x - y; }, {-0.3, 0.9}, {-0.3, 0.9}, 12);
  const TriangleSurface part = clip_to_box(plane, kUnitBox).front();
  EXPECT_NEAR(area(part), std::sqrt(3.0) / 4.0 * 0.72, 1e-12);
  expect_rim_on_box_planes(part, kUnitBox);
  int on_edges = 0;
  for (const auto& p : part.points) on_edges += std::popcount(box_sides(p, kUnitBox)) == 2;
  EXPECT_EQ(on_edges, 3);
}

TEST(BoxClipping, SeveralPartsAreNumbered) {
  // A sheet that dips out of the box bottom in the middle: two parts.
  const TriangleSurface sheet =
      testing::graph_patch([](double x, double) { return 0.3 - 0.5 * std::exp(-40 * (x - 0.5) * (x - 0.5)); },
                           {0.1, 0.9}, {0.1, 0.9}, 20, "sheet");
  const std::vector<TriangleSurface> parts = clip_to_box(sheet, kUnitBox);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].name, "sheet_1");
  EXPECT_EQ(parts[1].name, "sheet_2");
  EXPECT_GE(area(parts[0]), area(parts[1]));
  for (const auto& part : parts) expect_rim_on_box_planes(part, kUnitBox);
}

TEST(BoxClipping, WhatCannotBeInsertedIsRefused) {
  const TriangleSurface inside = testing::tilted_plane(6);
  const std::vector<TriangleSurface> unchanged = clip_to_box(inside, kUnitBox);
  ASSERT_EQ(unchanged.size(), 1u);
  EXPECT_EQ(unchanged[0].points, inside.points);
  EXPECT_EQ(unchanged[0].triangles, inside.triangles);

  const auto refused = [](const TriangleSurface& s, const Box& box) {
    try {
      clip_to_box(s, box);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  TriangleSurface outside = inside;
  for (auto& p : outside.points) p.z() += 2.0;
  EXPECT_THAT(refused(outside, kUnitBox), HasSubstr("no part of the surface lies inside the box"));
  const TriangleSurface sphere = testing::ellipsoid({0.5, 0.5, 0.9}, {0.3, 0.3, 0.3}, 6);
  EXPECT_THAT(refused(sphere, kUnitBox), HasSubstr("closed surface must lie strictly inside"));
  // A tube along z through the box: its part inside is an annulus.
  TriangleSurface tube;
  tube.name = "tube";
  const int around = 12, along = 6;
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i < around; ++i) {
      const double a = 2 * std::numbers::pi * i / around;
      tube.points.emplace_back(0.5 + 0.2 * std::cos(a), 0.5 + 0.2 * std::sin(a), -0.2 + 1.4 * j / along);
    }
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      const int a = j * around + i, b = j * around + (i + 1) % around;
      tube.triangles.push_back({a, b, b + around});
      tube.triangles.push_back({a, b + around, a + around});
    }
  EXPECT_THAT(refused(tube, kUnitBox), HasSubstr("the part of the surface inside the box"));
  // A plane lying in the box's top face.
  const TriangleSurface top = testing::graph_patch([](double, double) { return 1.0; }, {0.2, 0.8}, {0.2, 0.8}, 4);
  EXPECT_THAT(refused(top, kUnitBox), HasSubstr("lies in the box plane"));
}

TEST(BoxClipping, ARimTouchingTheBoxAtAPointIsRefusedByValidation) {
  TriangleSurface patch = testing::paper_like_patch(6);
  patch.points[0].x() = 0.0;  // a rim corner on the plane x = 0, its rim edges inside
  try {
    require_inside_box(patch, kUnitBox);
    FAIL() << "accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("touches the box at a point"));
  }
}

// The vertices of a surface's grid row at y (within 1e-9), by increasing x.
std::vector<int> row_at(const TriangleSurface& s, double y) {
  std::vector<int> row;
  for (int v = 0; v < static_cast<int>(s.points.size()); ++v)
    if (std::abs(s.points[v].y() - y) < 1e-9) row.push_back(v);
  std::ranges::sort(row, {}, [&](int v) { return s.points[v].x(); });
  return row;
}

// A sheet whose edge at y = 0.95 zigzags across the box side y = 1: out of the box at every other vertex,
// 0.015 inside at the others but one, 0.04 inside there. Snapping within 0.02 sets the shallow ones onto
// the plane (each on rim edges whose other end lies beyond it) and leaves the deep one; a vertex of the
// opposite edge 0.01 from y = 0, whose rim neighbours are far from it, stays too: alone on the plane it
// would touch the box at a point.
TEST(BoxClipping, SnappingSetsShallowRimEdgesOntoTheBox) {
  TriangleSurface sheet =
      testing::graph_patch([](double x, double) { return 0.5 + 0.1 * x; }, {0.2, 0.8}, {0.2, 0.95}, 12, "sheet");
  const std::vector<int> edge = row_at(sheet, 0.95), opposite = row_at(sheet, 0.2);
  ASSERT_EQ(edge.size(), 13u);
  for (std::size_t i = 0; i < edge.size(); ++i) sheet.points[edge[i]].y() = i % 2 == 0 ? 1.03 : 0.985;
  sheet.points[edge[5]].y() = 0.96;
  sheet.points[opposite[3]].y() = 0.01;
  const TriangleSurface before = sheet;

  const RimSnap snap = snap_rim_to_box(sheet, kUnitBox, 0.02);
  EXPECT_EQ(snap.vertices, 5);  // edge[1], [3], [7], [9], [11]
  EXPECT_NEAR(snap.largest_move, 0.015, 1e-12);
  for (std::size_t v = 0; v < sheet.points.size(); ++v) {
    const auto i = std::ranges::find(edge, static_cast<int>(v)) - edge.begin();
    const bool snapped = i < 13 && i % 2 == 1 && i != 5;
    if (snapped) {
      EXPECT_EQ(sheet.points[v].y(), 1.0) << "edge vertex " << i;
      EXPECT_EQ(sheet.points[v].x(), before.points[v].x());
    } else {
      EXPECT_EQ(sheet.points[v], before.points[v]) << "vertex " << v;
    }
  }
  // Clipped, its rim runs along the box side wherever the edge came within 0.02 of it.
  const TriangleSurface part = clip_to_box(sheet, kUnitBox).front();
  expect_rim_on_box_planes(part, kUnitBox);
  int dipping = 0;  // vertices near the side but not on it: only edge[5]'s dip
  for (const Eigen::Vector3d& p : part.points) dipping += p.y() > 0.9 && p.y() < 1.0;
  EXPECT_EQ(dipping, 1);
}

// A rim that folds back under its neighbours (a hook at the edge): setting it onto the box would turn
// triangles over. Refused, naming a triangle and the move, and the surface is left as it was.
TEST(BoxClipping, SnappingThatTurnsATriangleOverIsRefused) {
  TriangleSurface sheet =
      testing::graph_patch([](double x, double) { return 0.5 + 0.1 * x; }, {0.2, 0.8}, {0.2, 0.8}, 6, "hook");
  const std::vector<int> edge = row_at(sheet, 0.8);
  for (const int v : edge) {
    sheet.points[v].y() = 0.65;  // below the row at 0.7: the last strip folds back
    sheet.points[v].z() += 0.1;
  }
  const TriangleSurface before = sheet;
  const Box box{{-1.0, -1.0, -1.0}, {2.0, 1.0, 2.0}};  // the hook's edge alone within 0.4 of a side
  try {
    snap_rim_to_box(sheet, box, 0.4);
    FAIL() << "accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("hook: setting its rim onto the box within 0.4"));
    EXPECT_THAT(error.what(), HasSubstr("turns triangle"));
    EXPECT_THAT(error.what(), HasSubstr(" moves by 0."));
  }
  EXPECT_EQ(sheet.points, before.points);
  // Within 0.1 nothing is near the box, and nothing moves.
  EXPECT_EQ(snap_rim_to_box(sheet, box, 0.1).vertices, 0);
  EXPECT_EQ(sheet.points, before.points);
}

}  // namespace
}  // namespace meccano
