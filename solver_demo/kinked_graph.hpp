// The pieces the flux-jump examples share (the cube example's open S, the fault example's S through the
// box top): a surface S that is a graph over a rectangle of two coordinate axes, and a manufactured
// solution with a kink across S,
//
//   u = b − w |d|,   d = x_t − s(x_a, x_b),
//
// (a, b, t) a cyclic permutation of (x, y, z), so that e_a × e_b = e_t and S's normal ∇d/|∇d| points
// towards +t; s the height of S, w a cutoff that fades the kink out at the rim of S where the rim is
// inside the box; b = e^z sin(2x + y), smooth, with −Δb = 4b. Derived in doc/solver.md.
//
// Off S (2D gradients and Laplacians in (x_a, x_b), σ = sign d):
//   ∇u = ∇b − σ (d ∇w + w ∇d),   ∇d = e_t − s_a e_a − s_b e_b,
//   f = −Δu = 4b + σ (d Δw − 2 ∇w·∇s − w Δs),
//   g_S = ∂u/∂n|⁻ − ∂u/∂n|⁺ = 2 w |∇d| on S.
// Every function takes physical coordinates, is defined in all of R³, and takes the side of a point by
// the sign of d there.
#pragma once

#include "interface_triangles.hpp"

#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>

#include <string>

namespace solver_demo {

struct ValueAndGradient {
  double value = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
};

// A function of (x_a, x_b) with its gradient and Laplacian in physical coordinates.
struct PlanarValue {
  double value = 0.0;
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  double laplacian = 0.0;
};

struct KinkedGraph {
  int height_axis;                                   // t: 2 for z = s(x, y), 0 for x = s(y, z)
  PlanarValue (*height)(const Eigen::Vector2d& ab);  // s
  PlanarValue (*cutoff)(const Eigen::Vector2d& ab);  // w, 0 wherever S has no kink
};

// (x_a, x_b) of p.
Eigen::Vector2d planar_coordinates(const KinkedGraph& graph, const Eigen::Vector3d& p);
// The point of S on the line through p along e_t, and S's unit normal there (towards +t).
Eigen::Vector3d graph_point(const KinkedGraph& graph, const Eigen::Vector3d& p);
Eigen::Vector3d graph_normal(const KinkedGraph& graph, const Eigen::Vector3d& p);

ValueAndGradient kinked_solution(const KinkedGraph& graph, const Eigen::Vector3d& p);  // u, ∇u
double kinked_right_hand_side(const KinkedGraph& graph, const Eigen::Vector3d& p);     // f
double kinked_interface_source(const KinkedGraph& graph, const Eigen::Vector3d& p);    // g_S at S's point over p

// B⁴ with its derivatives: the cutoffs are B⁴ for a B that vanishes linearly at S's rim inside the box, so
// that w vanishes there with three derivatives: u's kink term is C³ across the walls of that rim (no mesh
// faces) and f is C¹ there. (With B³, f was only C⁰ across them; its quadrature on the cells they cut cost
// O(h²) and capped P2's L2 rate at 2: doc/solver.md.)
PlanarValue fourth_power(const PlanarValue& B);

// S over the rectangle [origin, origin + extent] of (x_a, x_b), triangulated on its grid of n_a × n_b cells, each cut
// along alternating diagonals; vertices on S, normals towards +t.
meccano::TriangleSurface triangulate_graph(const KinkedGraph& graph, const Eigen::Vector2d& origin,
                                           const Eigen::Vector2d& extent, int n_a, int n_b, const std::string& name);

// Whether `interface` is S (match_surface, interface_triangles.hpp) with every corner over that rectangle.
SurfaceMatch match_graph(const meccano::DealiiInterface& interface, const KinkedGraph& graph,
                         const Eigen::Vector2d& origin, const Eigen::Vector2d& extent);

}  // namespace solver_demo
