#include "cube_example.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

struct Height {
  double s, s_x, s_y, laplacian;
};

Height height(double x, double y) {
  const double p = (x - origin) / side, q = (y - origin) / side;
  const double sp = std::sin(pi * p), cp = std::cos(pi * p), sq = std::sin(pi * q), cq = std::cos(pi * q);
  return {base + tilt * p * q + bump * sp * sq, (tilt * q + bump * pi * cp * sq) / side,
          (tilt * p + bump * pi * sp * cq) / side, -2.0 * bump * pi * pi * sp * sq / (side * side)};
}

// The cutoff w = B⁴, B = 16 p(1−p) q(1−q) on Q and 0 outside. B vanishes linearly at the rim, so w
// vanishes there with three derivatives: u's kink term is C³ across the walls of the rim's column and
// f = −Δu is C¹ there. (With B³, f was only C⁰ across those walls, which are no mesh faces; its
// quadrature on the cells they cut cost O(h²) and capped P2's L2 rate at 2: doc/solver.md.)
struct Cutoff {
  double w, w_x, w_y, laplacian;
};

Cutoff cutoff(double x, double y) {
  const double p = (x - origin) / side, q = (y - origin) / side;
  if (p <= 0.0 || p >= 1.0 || q <= 0.0 || q >= 1.0) return {0.0, 0.0, 0.0, 0.0};
  const double bp = 4.0 * p * (1.0 - p), bq = 4.0 * q * (1.0 - q);
  const double B = bp * bq;
  const double B_x = 4.0 * (1.0 - 2.0 * p) * bq / side, B_y = 4.0 * (1.0 - 2.0 * q) * bp / side;
  const double B_laplacian = -8.0 * (bq + bp) / (side * side);
  return {B * B * B * B, 4.0 * B * B * B * B_x, 4.0 * B * B * B * B_y,
          12.0 * B * B * (B_x * B_x + B_y * B_y) + 4.0 * B * B * B * B_laplacian};
}

// The smooth part e^z sin(2x + y): nonzero on the box sides, −Δ of it is 4 times itself.
ValueAndGradient smooth_part(const Eigen::Vector3d& p) {
  const double e = std::exp(p.z()), s = std::sin(2.0 * p.x() + p.y()), c = std::cos(2.0 * p.x() + p.y());
  return {e * s, {2.0 * e * c, e * c, e * s}};
}

}  // namespace

double cube_example_height(double x, double y) { return height(x, y).s; }

Eigen::Vector3d cube_example_normal(double x, double y) {
  const Height h = height(x, y);
  return Eigen::Vector3d(-h.s_x, -h.s_y, 1.0).normalized();
}

Eigen::Vector3d project_onto_cube_example(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), cube_example_height(p.x(), p.y())};
}

ValueAndGradient manufactured_solution(const Eigen::Vector3d& p) {
  ValueAndGradient u = smooth_part(p);
  const Cutoff c = cutoff(p.x(), p.y());
  if (c.w == 0.0) return u;
  // Kink term k = −w |d|, d = z − s: ∇k = −σ (d ∇w + w ∇d) with ∇d = (−s_x, −s_y, 1).
  const Height h = height(p.x(), p.y());
  const double d = p.z() - h.s, sigma = d >= 0.0 ? 1.0 : -1.0;
  u.value -= c.w * std::abs(d);
  u.gradient -= sigma * (d * Eigen::Vector3d(c.w_x, c.w_y, 0.0) + c.w * Eigen::Vector3d(-h.s_x, -h.s_y, 1.0));
  return u;
}

double manufactured_right_hand_side(const Eigen::Vector3d& p) {
  const double smooth = 4.0 * smooth_part(p).value;
  const Cutoff c = cutoff(p.x(), p.y());
  if (c.w == 0.0) return smooth;
  // −Δk = σ Δ(w d) = σ (d Δw + 2 ∇w·∇d + w Δd), with ∇w·∇d = −∇w·∇s and Δd = −Δs.
  const Height h = height(p.x(), p.y());
  const double d = p.z() - h.s, sigma = d >= 0.0 ? 1.0 : -1.0;
  return smooth + sigma * (d * c.laplacian - 2.0 * (c.w_x * h.s_x + c.w_y * h.s_y) - c.w * h.laplacian);
}

double manufactured_interface_source(const Eigen::Vector3d& p) {
  // On S, ∇k = ∓ w ∇d from above and below and ∇d = |∇d| n, so the jump ∂u/∂n|⁻ − ∂u/∂n|⁺ is 2 w |∇d|.
  const Height h = height(p.x(), p.y());
  return 2.0 * cutoff(p.x(), p.y()).w * std::sqrt(1.0 + h.s_x * h.s_x + h.s_y * h.s_y);
}

meccano::TriangleSurface triangulate_cube_example(int n) {
  meccano::TriangleSurface surface;
  surface.name = "patch";
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = origin + side * i / n, y = origin + side * j / n;
      surface.points.emplace_back(x, y, cube_example_height(x, y));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      if ((i + j) % 2 == 0) {
        surface.triangles.push_back({a, b, c});
        surface.triangles.push_back({a, c, d});
      } else {
        surface.triangles.push_back({a, b, d});
        surface.triangles.push_back({b, c, d});
      }
    }
  return surface;
}

SurfaceMatch match_cube_example_surface(const meccano::DealiiInterface& interface) {
  SurfaceMatch match = match_surface(interface, project_onto_cube_example);
  const auto over_q = [&](const dealii::Point<3>& p) {
    return p[0] >= origin - match.tolerance && p[0] <= origin + side + match.tolerance &&
           p[1] >= origin - match.tolerance && p[1] <= origin + side + match.tolerance;
  };
  if (!std::all_of(interface.corners.begin(), interface.corners.end(), over_q))
    match.max_deviation = std::numeric_limits<double>::infinity();
  return match;
}

}  // namespace solver_demo
