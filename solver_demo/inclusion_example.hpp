// The inclusion example: the classic elliptic interface problem, diffusion with a coefficient jump across a
// closed surface S, with a manufactured solution (derived in doc/solver.md, "The inclusion problem").
//
//   −∇·(β ∇u) = f in Ω = (0,1)³ \ S,   u = g_D on ∂Ω,   [u] = 0 and [β ∂u/∂n] = 0 on S,
//
// β = β_in inside S, β_out outside. The weak form ∫ β ∇u·∇v = ∫ f v has no term on S: the flux is
// continuous, and the gradient jumps by the ratio of the coefficients. The mesh must have S as faces so
// that β is constant on each cell (the module's `inside_NAME` cells carry material id 2 + k).
//
// S       the sphere of centre c = (0.5, 0.5, 0.5) and radius R = 0.3; φ = |x − c|² − R² (< 0 inside).
// u       g + A φ / β on each side, with g = b − φ (∇b·(x − c)) / (2R²) and b = e^z sin(2x + y):
//         continuous (φ = 0 on S); ∂g/∂n = 0 on S, so β ∂u/∂n = 2 A R on both sides; each side's formula
//         is smooth in all of R³, which lets quadrature points between S and the flat faces of S_h take
//         the formula of their cell's side.
// f       −β Δg − 6A on each side (Δb = −4b makes Δg closed-form with b's Hessian only).
#pragma once

#include "cube_example.hpp"

#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>

namespace solver_demo {

struct Inclusion {
  Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.5);
  double radius = 0.3;
  double beta_inside = 10.0;
  double beta_outside = 1.0;
  double kink = 2.0;  // A
};
inline const Inclusion inclusion{};

// u and ∇u, and f = −β Δu, by the formula of one side (inside or not) at any point.
ValueAndGradient inclusion_solution(const Eigen::Vector3d& p, bool inside);
double inclusion_right_hand_side(const Eigen::Vector3d& p, bool inside);

Eigen::Vector3d inclusion_normal(const Eigen::Vector3d& p);        // outward unit normal of the sphere through p
Eigen::Vector3d project_onto_inclusion(const Eigen::Vector3d& p);  // the closest point of S

// S triangulated from the octahedron with n² triangles per face (meccano::triangulate_star_shaped),
// normals out, named "sphere".
meccano::TriangleSurface triangulate_inclusion(int n);

}  // namespace solver_demo
