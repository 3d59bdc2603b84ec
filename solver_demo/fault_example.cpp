#include "fault_example.hpp"

#include <cmath>
#include <numbers>

namespace solver_demo {
namespace {

using std::numbers::pi;

// p = (y − y0) / width, q = (z − z0) / depth; the triangulation reaches q = (top − z0) / depth.
constexpr double y0 = 0.2;
constexpr double width = 0.6;
constexpr double z0 = 0.35;
constexpr double depth = 0.65;
constexpr double top = 1.1;

// s = base + dip q − listric q² + bend sin(πp) + twist p q.
constexpr double base = 0.38;
constexpr double dip = 0.25;
constexpr double listric = 0.06;
constexpr double bend = 0.06;
constexpr double twist = 0.04;

PlanarValue height(const Eigen::Vector2d& yz) {
  const double p = (yz.x() - y0) / width, q = (yz.y() - z0) / depth;
  const double sp = std::sin(pi * p), cp = std::cos(pi * p);
  return {base + dip * q - listric * q * q + bend * sp + twist * p * q,
          {(bend * pi * cp + twist * q) / width, (dip - 2.0 * listric * q + twist * p) / depth},
          -bend * pi * pi * sp / (width * width) - 2.0 * listric / (depth * depth)};
}

// w = B⁴ (fourth_power), B = 4 p(1−p) q: zero on the rim inside the box, not at the top.
PlanarValue cutoff(const Eigen::Vector2d& yz) {
  const double p = (yz.x() - y0) / width, q = (yz.y() - z0) / depth;
  if (p <= 0.0 || p >= 1.0 || q <= 0.0) return {};
  const double bp = 4.0 * p * (1.0 - p);
  return fourth_power({bp * q, {4.0 * (1.0 - 2.0 * p) * q / width, bp / depth}, -8.0 * q / (width * width)});
}

}  // namespace

const KinkedGraph fault_example{0, height, cutoff};

Eigen::Vector3d fault_normal(const Eigen::Vector3d& p) { return graph_normal(fault_example, p); }

Eigen::Vector3d project_onto_fault(const Eigen::Vector3d& p) { return graph_point(fault_example, p); }

meccano::TriangleSurface triangulate_fault_example(int n) {
  const int rows = static_cast<int>(std::ceil(n * (top - z0) / width));
  return triangulate_graph(fault_example, {y0, z0}, {width, top - z0}, n, rows, "fault");
}

SurfaceMatch match_fault_example_surface(const meccano::DealiiInterface& interface) {
  return match_graph(interface, fault_example, {y0, z0}, {width, 1.0 - z0});
}

}  // namespace solver_demo
