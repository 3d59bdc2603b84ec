// The demo solver: a Poisson problem with a flux jump on a surface S immersed in a tet mesh.
//
//   −Δu = f in Ω,   u = g_D on ∂Ω,   ∂u/∂n|⁻ − ∂u/∂n|⁺ = g_S on S,
//
// whose weak form is: find u ∈ H¹(Ω), u = g_D on ∂Ω, with ∫_Ω ∇u·∇v = ∫_Ω f v + ∫_S g_S v for all
// v ∈ H¹₀(Ω). S enters only through that surface integral, so the mesh must have S as a set of faces
// (the module's output); u is continuous across S and its gradient jumps there.
//
// Input    the mesh as the deal.II adapter gives it (meccano::DealiiMesh, from an insertion or an MSH
//          file; only MPI rank 0's copy is read), the name of its interface S (DealiiMesh::interface:
//          empty for the only one), the degree 1 or 2 of the continuous Lagrange elements
//          (FE_SimplexP), and the problem's data.
// Method   deal.II 9.4 on parallel::fullydistributed::Triangulation (any number of MPI ranks, one
//          included), built from meccano::fullydistributed_description: rank 0 builds the coarse mesh
//          with S's faces marked by their manifold id, METIS partitions it; each rank takes the S faces
//          of the cells it owns on S's negative side (meccano::interface_cell_faces) and the manifold
//          ids are reset to flat before any FEValues. u = g_D on every boundary face, whatever its
//          boundary id (box sides 1-6, other faces 0). CG with Trilinos ML AMG, relative residual 1e-12.
// Output   a SolveReport: sizes, CG iterations, the flux balance, the solution's norms, and the errors
//          in L2 and in the H1 seminorm when the exact solution is known; optionally VTU files.
#pragma once

#include "cube_example.hpp"
#include "interface_triangles.hpp"

#include <deal.II/base/mpi.h>

#include <functional>
#include <limits>
#include <optional>
#include <string>

namespace solver_demo {

struct InterfaceProblem {
  std::string description;
  std::function<double(const Eigen::Vector3d&)> right_hand_side;           // f
  std::function<double(const Eigen::Vector3d&)> boundary_values;           // g_D
  std::function<double(const Eigen::Vector3d&)> interface_source;          // g_S
  std::function<ValueAndGradient(const Eigen::Vector3d&)> exact_solution;  // empty when unknown
};

// The cube example's manufactured solution (cube_example.hpp); S must be the cube example's surface.
InterfaceProblem manufactured_problem();
// Any surface: f = 0, g_D = 0, g_S = 1. u is the potential of a uniform source on S.
InterfaceProblem unit_source_problem();

struct SolveReport {
  unsigned long long cells = 0;
  unsigned long long dofs = 0;
  unsigned long long interface_faces = 0;
  double h = 0.0;  // longest edge
  unsigned int cg_iterations = 0;
  // Flux balance: what the sources put in, ∫_Ω f + ∫_S g_S, against what leaves through the box sides
  // by the discrete gradient, −∫_∂Ω ∇u_h·n. Equal for the exact solution; they agree as h → 0.
  double source = 0.0;
  double outflow = 0.0;
  double l2_norm = 0.0;            // ‖u_h‖_L2
  double h1_seminorm = 0.0;        // ‖∇u_h‖_L2
  std::optional<double> l2_error;  // ‖u − u_h‖_L2
  std::optional<double> h1_error;  // ‖∇(u − u_h)‖_L2
  double setup_seconds = 0.0;      // distributed mesh, dofs, constraints, sparsity
  double assembly_seconds = 0.0;
  double solve_seconds = 0.0;  // AMG setup and CG
  double postprocess_seconds = 0.0;
};

// Solves `problem` on `mesh` with S its interface `interface_name`, elements of `degree`; writes PREFIX.vtu (PREFIX.pvtu and one
// PREFIX.RANK.vtu per rank under MPI) with u_h, the subdomains, and u_h − I_h u when u is known,
// unless `vtu_prefix` is empty. Collective over `communicator`.
SolveReport solve_interface_problem(MPI_Comm communicator, const meccano::DealiiMesh& mesh,
                                    const std::string& interface_name, unsigned int degree,
                                    const InterfaceProblem& problem, const std::string& vtu_prefix = "");

}  // namespace solver_demo
