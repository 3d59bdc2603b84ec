#include "cube_example.hpp"

#include <cmath>
#include <numbers>

namespace solver_demo {
namespace {

using std::numbers::pi;

// Q = [origin, origin + side]² in (x, y); p, q are its unit coordinates.
constexpr double origin = 0.2;
constexpr double side = 0.6;

// s = base + tilt p q + bump sin(πp) sin(πq), with its derivatives in physical coordinates.
constexpr double base = 0.42;
constexpr double tilt = 0.12;
constexpr double bump = 0.10;

PlanarValue height(const Eigen::Vector2d& xy) {
  const double p = (xy.x() - origin) / side, q = (xy.y() - origin) / side;
  const double sp = std::sin(pi * p), cp = std::cos(pi * p), sq = std::sin(pi * q), cq = std::cos(pi * q);
  return {base + tilt * p * q + bump * sp * sq,
          {(tilt * q + bump * pi * cp * sq) / side, (tilt * p + bump * pi * sp * cq) / side},
          -2.0 * bump * pi * pi * sp * sq / (side * side)};
}

// The cutoff w = B⁴ (fourth_power), B = 16 p(1−p) q(1−q) on Q and 0 outside.
PlanarValue cutoff(const Eigen::Vector2d& xy) {
  const double p = (xy.x() - origin) / side, q = (xy.y() - origin) / side;
  if (p <= 0.0 || p >= 1.0 || q <= 0.0 || q >= 1.0) return {};
  const double bp = 4.0 * p * (1.0 - p), bq = 4.0 * q * (1.0 - q);
  return fourth_power({bp * bq,
                       {4.0 * (1.0 - 2.0 * p) * bq / side, 4.0 * (1.0 - 2.0 * q) * bp / side},
                       -8.0 * (bq + bp) / (side * side)});
}

}  // namespace

const KinkedGraph cube_example{2, height, cutoff};

double cube_example_height(double x, double y) { return height({x, y}).value; }

Eigen::Vector3d cube_example_normal(double x, double y) { return graph_normal(cube_example, {x, y, 0.0}); }

Eigen::Vector3d project_onto_cube_example(const Eigen::Vector3d& p) { return graph_point(cube_example, p); }

ValueAndGradient manufactured_solution(const Eigen::Vector3d& p) { return kinked_solution(cube_example, p); }

double manufactured_right_hand_side(const Eigen::Vector3d& p) { return kinked_right_hand_side(cube_example, p); }

double manufactured_interface_source(const Eigen::Vector3d& p) { return kinked_interface_source(cube_example, p); }

meccano::TriangleSurface triangulate_cube_example(int n) {
  return triangulate_graph(cube_example, {origin, origin}, {side, side}, n, n, "patch");
}

SurfaceMatch match_cube_example_surface(const meccano::DealiiInterface& interface) {
  return match_graph(interface, cube_example, {origin, origin}, {side, side});
}

}  // namespace solver_demo
