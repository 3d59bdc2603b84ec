#include "inclusion_example.hpp"

#include <meccano/surface/closed_surface.hpp>

#include <cmath>

namespace solver_demo {
namespace {

// b = e^z sin(2x + y) with its gradient and Hessian; Δb = (1 − 5) b = −4b.
struct Smooth {
  double value;
  Eigen::Vector3d gradient;
  Eigen::Matrix3d hessian;
};

Smooth smooth_part(const Eigen::Vector3d& p) {
  const double e = std::exp(p.z()), s = e * std::sin(2.0 * p.x() + p.y()), c = e * std::cos(2.0 * p.x() + p.y());
  Eigen::Matrix3d hessian;
  hessian << -4.0 * s, -2.0 * s, 2.0 * c,  //
      -2.0 * s, -s, c,                     //
      2.0 * c, c, s;
  return {s, {2.0 * c, c, s}, hessian};
}

double coefficient(bool inside) { return inside ? inclusion.beta_inside : inclusion.beta_outside; }

// g = b − φ h / (2R²), h = ∇b·y, y = x − c, φ = |y|² − R²: equal to b on S with ∂g/∂n = 0 there, since
// ∇g·y = h − (2h|y|² + φ ∇h·y) / (2R²) vanishes where |y| = R.
struct Continuous {
  double value;
  Eigen::Vector3d gradient;
  double laplacian;
};

Continuous continuous_part(const Eigen::Vector3d& p) {
  const Smooth b = smooth_part(p);
  const Eigen::Vector3d y = p - inclusion.centre;
  const double r2 = inclusion.radius * inclusion.radius;
  const double phi = y.squaredNorm() - r2, h = b.gradient.dot(y);
  const Eigen::Vector3d grad_h = b.hessian * y + b.gradient;
  // Δ(φ h) = h Δφ + 2 ∇φ·∇h + φ Δh with Δφ = 6, ∇φ = 2y and Δh = y·∇(Δb) + 2 Δb = −4 (h + 2b).
  const double laplacian_phi_h = 6.0 * h + 4.0 * y.dot(grad_h) - 4.0 * phi * (h + 2.0 * b.value);
  return {b.value - phi * h / (2.0 * r2), b.gradient - (2.0 * h * y + phi * grad_h) / (2.0 * r2),
          -4.0 * b.value - laplacian_phi_h / (2.0 * r2)};
}

}  // namespace

ValueAndGradient inclusion_solution(const Eigen::Vector3d& p, bool inside) {
  const Continuous g = continuous_part(p);
  const Eigen::Vector3d y = p - inclusion.centre;
  const double a = inclusion.kink / coefficient(inside);
  return {g.value + a * (y.squaredNorm() - inclusion.radius * inclusion.radius), g.gradient + 2.0 * a * y};
}

double inclusion_right_hand_side(const Eigen::Vector3d& p, bool inside) {
  return -coefficient(inside) * continuous_part(p).laplacian - 6.0 * inclusion.kink;
}

Eigen::Vector3d inclusion_normal(const Eigen::Vector3d& p) { return (p - inclusion.centre).normalized(); }

Eigen::Vector3d project_onto_inclusion(const Eigen::Vector3d& p) {
  return inclusion.centre + inclusion.radius * inclusion_normal(p);
}

meccano::TriangleSurface triangulate_inclusion(int n) {
  return meccano::triangulate_star_shaped(
      [](const Eigen::Vector3d& direction) -> Eigen::Vector3d {
        return inclusion.centre + inclusion.radius * direction;
      },
      n, "sphere");
}

}  // namespace solver_demo
