// The fault example: a flux jump across a curved fault S that reaches the box top, the ground, where the
// condition is on the flux, as for a free surface (doc/solver.md, "The fault problem"):
//
//   −Δu = f in Ω = (0,1)³ \ S,   ∂u/∂n = g_N on the top z = 1,   u = g_D on the other five sides,
//   ∂u/∂n|⁻ − ∂u/∂n|⁺ = g_S on S,
//
// (n the unit normal of S towards +x). The kink of u runs into the top face along the trace of S there,
// which the mesh resolves only because S_M's rim lies on that trace (issue 19).
//
// S       the graph x = s(y, z) over y ∈ [0.2, 0.8], z ≥ 0.35: with p = (y − 0.2)/0.6, q = (z − 0.35)/0.65,
//         s = 0.38 + 0.25 q − 0.06 q² + 0.06 sin(πp) + 0.04 p q, dipping about 70° towards −x. Its
//         triangulation runs up to z = 1.1, above the box: the module clips it at the top.
// u       e^z sin(2x + y) − w(y, z) |x − s(y, z)|, w = B⁴, B = 4 p(1−p) q for 0 < p < 1, q > 0, and 0
//         elsewhere: the kink fades out with three derivatives at the rim inside the box (p = 0, p = 1,
//         q = 0) and not at the top, where B = 4 p(1−p).
// f, g_S  kinked_graph.hpp's formulas, with (a, b, t) = (y, z, x).
// g_N     ∇u·e_z on the top, each side of S's trace by its own formula.
#pragma once

#include "interface_triangles.hpp"
#include "kinked_graph.hpp"

#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>

namespace solver_demo {

extern const KinkedGraph fault_example;

Eigen::Vector3d fault_normal(const Eigen::Vector3d& p);        // S's unit normal at project_onto_fault(p)
Eigen::Vector3d project_onto_fault(const Eigen::Vector3d& p);  // the point of S at p's (y, z)

// S triangulated on a grid of n cells across y and about as wide rows in z up to z = 1.1, normals
// towards +x, named "fault".
meccano::TriangleSurface triangulate_fault_example(int n);

// Whether `interface` is S inside the box (match_surface, interface_triangles.hpp), every corner of it
// over y ∈ [0.2, 0.8], z ∈ [0.35, 1].
SurfaceMatch match_fault_example_surface(const meccano::DealiiInterface& interface);

}  // namespace solver_demo
