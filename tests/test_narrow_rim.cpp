// S's width at its rim (surface/narrow_rim.hpp): a strip's width along its long sides, a wedge's near its
// sharp tip; none at right-angled corners, at a tip's own vertex, or on a closed surface.
#include <meccano/surface/narrow_rim.hpp>

#include "test_surfaces.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace meccano {
namespace {

constexpr double none = std::numeric_limits<double>::infinity();

bool on_rim(const TriangleSurface& surface, int v) {
  for (const auto& [a, b] : testing::rim_edges(surface))
    if (a == v || b == v) return true;
  return false;
}

TEST(RimWidths, AStripHasItsWidthAlongItsLongSidesAndNoneBelowIt) {
  const TriangleSurface strip = testing::graph_patch([](double, double) { return 0.3; }, {0.0, 1.0}, {0.0, 0.1}, 20);
  const std::vector<double> widths = rim_widths(strip, 0.15);
  int long_side_vertices = 0;
  for (int v = 0; v < static_cast<int>(strip.points.size()); ++v) {
    if (!on_rim(strip, v)) {
      EXPECT_EQ(widths[v], none) << "interior vertex " << v;
      continue;
    }
    const double x = strip.points[v].x();
    if (x > 0.22 && x < 0.78) {
      EXPECT_NEAR(widths[v], 0.1, 1e-12) << "long-side vertex at x = " << x;
      ++long_side_vertices;
    }
  }
  EXPECT_EQ(long_side_vertices, 2 * 11);
  for (double width : rim_widths(strip, 0.09)) EXPECT_EQ(width, none);
}

TEST(RimWidths, AWedgeNarrowsTowardsItsTipButItsTipVertexHasNoWidth) {
  // Half-angle 15 degrees, blunted at x = 0.02 so that no triangle is degenerate.
  const double half_angle = std::numbers::pi / 12;
  TriangleSurface wedge = testing::graph_patch([](double, double) { return 0.0; }, {0.02, 1.0}, {-1.0, 1.0}, 24);
  for (auto& p : wedge.points) p.y() *= p.x() * std::tan(half_angle);
  const std::vector<double> widths = rim_widths(wedge, 0.2);
  int near_tip = 0;
  for (int v = 0; v < static_cast<int>(wedge.points.size()); ++v) {
    if (!on_rim(wedge, v)) continue;
    const double x = wedge.points[v].x();
    // On a side at x, the other side is 2 x sin(15°) away (its foot at 0.87 x, inside the wedge).
    if (x > 0.05 && x < 0.3) {
      EXPECT_NEAR(widths[v], 2 * x * std::sin(half_angle), 1e-12) << "x = " << x;
      ++near_tip;
    } else if (x > 0.45) {
      EXPECT_EQ(widths[v], none) << "x = " << x;
    }
  }
  EXPECT_GT(near_tip, 10);
}

TEST(RimWidths, ASquaresRightAnglesHaveNoWidth) {
  const TriangleSurface square = testing::graph_patch([](double, double) { return 0.5; }, {0.0, 1.0}, {0.0, 1.0}, 16);
  for (double width : rim_widths(square, 0.9)) EXPECT_EQ(width, none);
}

TEST(RimWidths, AClosedSurfaceHasNoRim) {
  for (double width : rim_widths(testing::sphere(8), 10.0)) EXPECT_EQ(width, none);
}

}  // namespace
}  // namespace meccano
