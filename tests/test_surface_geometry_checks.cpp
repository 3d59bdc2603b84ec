// The geometric surface checks: every generated test surface is accepted; folds, surfaces outside or
// on the boundary of the box, and crossing or touching pairs are rejected with a message that says so.
#include <meccano/error.hpp>
#include <meccano/surface/validation.hpp>

#include "test_surfaces.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

namespace meccano {
namespace {

using Eigen::Vector3d;

const Box unit_box{Vector3d(0, 0, 0), Vector3d(1, 1, 1)};

// Runs `check` and returns the InputError message ("" if nothing was thrown).
template <class Check>
std::string error_of(Check&& check) {
  try {
    check();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

#define EXPECT_MESSAGE_HAS(message, part) \
  EXPECT_NE(std::string(message).find(part), std::string::npos) << "message: \"" << (message) << "\""

TEST(GeometryChecks, EveryTestSurfacePasses) {
  for (int n : {3, 8, 20}) {
    for (const auto& entry : testing::named_test_surfaces(n)) {
      EXPECT_NO_THROW(validate_surfaces(entry.surfaces, unit_box)) << entry.name << " n = " << n;
    }
  }
}

TEST(GeometryChecks, TestSurfacesPassInANonCubicBox) {
  const Box box{Vector3d(-2, 0, 10), Vector3d(3, 0.5, 11)};
  for (const auto& entry : testing::named_test_surfaces(6)) {
    std::vector<TriangleSurface> scaled;
    for (const TriangleSurface& surface : entry.surfaces) scaled.push_back(testing::scaled_into(surface, box));
    EXPECT_NO_THROW(validate_surfaces(scaled, box)) << entry.name;
    EXPECT_NE(error_of([&] { validate_surfaces(scaled, unit_box); }), "") << entry.name;
  }
}

TEST(GeometryChecks, PerturbedSurfacesPass) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    for (const TriangleSurface& surface :
         {testing::spherical_cap(10), testing::strongly_curved_sheet(10), testing::near_vertical_patch(12)}) {
      const TriangleSurface jittered = testing::perturbed(surface, 0.25, seed);
      EXPECT_NO_THROW(validate_surfaces(std::vector{jittered}, unit_box)) << surface.name << " seed " << seed;
    }
  }
}

TEST(GeometryChecks, SheetPassingThroughItselfIntersects) {
  // A figure-eight profile (x, z) = (sin t, sin t cos t), t in [-0.3, pi + 0.3], extruded along y:
  // a topological disk crossing itself along the line x = z = 0.5.
  TriangleSurface surface =
      testing::graph_patch([](double, double) { return 0.0; }, {0, 1}, {0, 1}, 24, "figure_eight");
  for (Vector3d& p : surface.points) {
    const double t = -0.3 + p.x() * (std::numbers::pi + 0.6);
    p = Vector3d(0.5 + 0.3 * std::sin(t), 0.2 + 0.6 * p.y(), 0.5 + 0.3 * std::sin(t) * std::cos(t));
  }
  EXPECT_NO_THROW(require_surface_topology(surface));
  const std::string message = error_of([&] { validate_surfaces(std::vector{surface}, unit_box); });
  EXPECT_MESSAGE_HAS(message, "figure_eight: triangles ");
  EXPECT_MESSAGE_HAS(message, " intersect");
}

TEST(GeometryChecks, FoldedOverTrianglesIntersect) {
  // A flat grid with one interior vertex dragged across its neighbour: triangles fold onto their
  // neighbours in the same plane.
  TriangleSurface surface = testing::graph_patch([](double, double) { return 0.5; }, {0.2, 0.8}, {0.2, 0.8}, 4, "fold");
  const int centre = 2 * 5 + 2;
  surface.points[centre].x() += 0.15 * 1.5;
  const std::string message = error_of([&] { require_no_self_intersection(surface); });
  EXPECT_MESSAGE_HAS(message, "fold: triangles ");
  EXPECT_MESSAGE_HAS(message, " intersect");
  // Dragged only part of the way, nothing folds.
  surface.points[centre].x() -= 0.15;
  EXPECT_NO_THROW(require_no_self_intersection(surface));
}

TEST(GeometryChecks, SelfIntersectionNamesTrianglesOneBased) {
  TriangleSurface soup;
  soup.source = "soup.obj";
  soup.points = {Vector3d(0, 0, 0),      Vector3d(1, 0, 0),     Vector3d(0, 1, 0),   // triangle 1
                 Vector3d(5, 5, 5),      Vector3d(6, 5, 5),     Vector3d(5, 6, 5),   // triangle 2, far away
                 Vector3d(0.2, 0.2, -1), Vector3d(0.2, 0.2, 1), Vector3d(2, 2, 0)};  // triangle 3 crosses 1
  soup.triangles = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}};
  EXPECT_EQ(error_of([&] { require_no_self_intersection(soup); }), "soup.obj: triangles 1 and 3 intersect");
}

TEST(GeometryChecks, SurfaceOutsideTheBox) {
  TriangleSurface surface = testing::paper_like_patch(6);
  surface.source = "bump.stl";
  surface.points[10].z() = 1.2;
  const std::string message = error_of([&] { require_strictly_inside_box(surface, unit_box); });
  EXPECT_MESSAGE_HAS(message, "bump.stl: vertex 11 (");
  EXPECT_MESSAGE_HAS(message, "is outside the box [0, 1] x [0, 1] x [0, 1]");
  EXPECT_MESSAGE_HAS(error_of([&] { validate_surfaces(std::vector{surface}, unit_box); }), "outside the box");
}

TEST(GeometryChecks, VertexOnTheBoxBoundary) {
  TriangleSurface surface = testing::tilted_plane(4);  // vertex 1 is the rim corner (0.1, 0.1, z)
  surface.points[0].x() = 0.0;
  std::string message = error_of([&] { require_strictly_inside_box(surface, unit_box); });
  EXPECT_MESSAGE_HAS(message, "tilted_plane: vertex 1 (0, 0.1, ");
  EXPECT_MESSAGE_HAS(message, "lies on the box boundary");
  // Within the margin (1e-9 of the diagonal) of the boundary counts as on it, beyond as inside/outside.
  surface.points[0].x() = 1e-12;
  EXPECT_MESSAGE_HAS(error_of([&] { require_strictly_inside_box(surface, unit_box); }), "lies on the box boundary");
  surface.points[0].x() = -1e-12;
  EXPECT_MESSAGE_HAS(error_of([&] { require_strictly_inside_box(surface, unit_box); }), "lies on the box boundary");
  surface.points[0].x() = -1e-6;
  EXPECT_MESSAGE_HAS(error_of([&] { require_strictly_inside_box(surface, unit_box); }), "is outside the box");
  surface.points[0].x() = 1e-6;
  EXPECT_NO_THROW(require_strictly_inside_box(surface, unit_box));
}

TEST(GeometryChecks, CrossingSurfacesIntersect) {
  TriangleSurface bump = testing::paper_like_patch(10);
  TriangleSurface plane = testing::graph_patch([](double, double) { return 0.45; }, {0.1, 0.9}, {0.1, 0.9}, 7, "plane");
  plane.source = "plane.off";
  const std::string message = error_of([&] { validate_surfaces(std::vector{bump, plane}, unit_box); });
  EXPECT_MESSAGE_HAS(message, "paper_like and plane.off intersect (triangle ");
  EXPECT_MESSAGE_HAS(message, " of paper_like, triangle ");
  // Crossing at right angles.
  const TriangleSurface wall = testing::near_vertical_patch(5);
  EXPECT_MESSAGE_HAS(error_of([&] { require_surfaces_disjoint(wall, plane); }),
                     "near_vertical and plane.off intersect");
}

TEST(GeometryChecks, TouchingSurfacesTouch) {
  const TriangleSurface floor =
      testing::graph_patch([](double, double) { return 0.5; }, {0.2, 0.8}, {0.2, 0.8}, 5, "floor");
  // Parallel, 1e-11 above the floor.
  const TriangleSurface lid =
      testing::graph_patch([](double, double) { return 0.5 + 1e-11; }, {0.3, 0.6}, {0.3, 0.6}, 3, "lid");
  std::string message = error_of([&] { validate_surfaces(std::vector{floor, lid}, unit_box); });
  EXPECT_MESSAGE_HAS(message, "floor and lid touch (triangle ");
  // A wall standing on the floor: its bottom edge lies in the floor (exact contact, no crossing).
  TriangleSurface wall = testing::graph_patch([](double, double) { return 0.0; }, {0, 1}, {0, 1}, 4, "wall");
  for (Vector3d& p : wall.points) p = Vector3d(0.45, 0.3 + 0.3 * p.x(), 0.5 + 0.3 * p.y());
  message = error_of([&] { require_surfaces_disjoint(floor, wall); });
  EXPECT_MESSAGE_HAS(message, "floor and wall touch");
  // Lifted by 1e-6 they are apart.
  for (Vector3d& p : wall.points) p.z() += 1e-6;
  EXPECT_NO_THROW(require_surfaces_disjoint(floor, wall));
  EXPECT_NO_THROW(validate_surfaces(std::vector{floor, wall}, unit_box));
}

}  // namespace
}  // namespace meccano
