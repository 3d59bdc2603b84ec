// The cube example's immersed surface S and the manufactured solution of the demo problem
//
//   −Δu = f in Ω = (0,1)³ \ S,   u = g_D on ∂Ω,   ∂u/∂n|⁻ − ∂u/∂n|⁺ = g_S on S,
//
// (n the unit normal of S towards +z; ⁻ and ⁺ the limits from below and above), whose weak form is
// ∫ ∇u·∇v = ∫ f v + ∫_S g_S v. The formulas are derived in doc/solver.md.
//
// S       the graph z = s(x, y) over Q = [0.2, 0.8]²: with p = (x − 0.2)/0.6, q = (y − 0.2)/0.6,
//         s = 0.42 + 0.12 p q + 0.10 sin(πp) sin(πq), normal (−s_x, −s_y, 1)/|·| (meshes/cube_example.obj).
// u       e^z sin(2x + y) − w(x, y) |z − s(x, y)| with the cutoff w = (16 p(1−p) q(1−q))⁴ on Q, 0 outside:
//         continuous, smooth off S, with a kink across S whose size w fades out at the rim of S together
//         with three derivatives, so that u has no kink anywhere but on S and f is C¹ off S.
// f       4 e^z sin(2x + y) + σ (d Δw − 2 ∇w·∇s − w Δs), d = z − s, σ = sign d (2D gradients).
// g_S     2 w √(1 + |∇s|²) ≥ 0: S is a source, u has a ridge along it.
//
// All functions take physical coordinates and are defined everywhere in R³ (u's kink term vanishes
// outside the column Q × R). The algebra is kinked_graph.hpp's, which the fault example shares.
#pragma once

#include "interface_triangles.hpp"
#include "kinked_graph.hpp"

#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>

namespace solver_demo {

// S as a graph over (x, y) with u's kink across it (kinked_graph.hpp).
extern const KinkedGraph cube_example;

double cube_example_height(double x, double y);                       // s(x, y)
Eigen::Vector3d cube_example_normal(double x, double y);              // unit, towards +z
Eigen::Vector3d project_onto_cube_example(const Eigen::Vector3d& p);  // the point of S's formula over p

ValueAndGradient manufactured_solution(const Eigen::Vector3d& p);  // u and ∇u (one-sided on S)
double manufactured_right_hand_side(const Eigen::Vector3d& p);     // f = −Δu off S
double manufactured_interface_source(const Eigen::Vector3d& p);    // g_S at (x, y) of p

// S triangulated on an n × n grid of Q with alternating diagonals, normals towards +z: the same
// triangulation as meshes/generate_surfaces.py writes, named "patch".
meccano::TriangleSurface triangulate_cube_example(int n);

// Whether `interface` is S (match_surface, interface_triangles.hpp), and every corner of it over Q.
SurfaceMatch match_cube_example_surface(const meccano::DealiiInterface& interface);

}  // namespace solver_demo
