// The demo solver: an elliptic problem with a surface S immersed in a tet mesh, across which the solution's
// gradient jumps, by a flux source on S or by a jump of the coefficient:
//
//   −∇·(β∇u) = f in Ω,   u = g_D on Γ_D,   β∂u/∂n = g_N on Γ_N,   β∂u/∂n|⁻ − β∂u/∂n|⁺ = g_S on S,
//
// Γ_N the box sides the problem names (none, or the top of the fault example), Γ_D the rest of ∂Ω; whose
// weak form is: find u ∈ H¹(Ω), u = g_D on Γ_D, with ∫_Ω β ∇u·∇v = ∫_Ω f v + ∫_Γ_N g_N v + ∫_S g_S v for
// all v ∈ H¹(Ω) vanishing on Γ_D. S enters through that surface integral and through β, constant on
// each cell and set by its material id (the cells a closed S encloses have their own), so the mesh must
// have S as a set of faces (the module's output); u is continuous across S and its gradient jumps there.
//
// Input    the mesh as the deal.II adapter gives it (meccano::DealiiMesh, from an insertion or an MSH
//          file; only MPI rank 0's copy is read), the name of its interface S (DealiiMesh::interface:
//          empty for the only one), the degree 1 or 2 of the continuous Lagrange elements
//          (FE_SimplexP), and the problem's data.
// Method   deal.II 9.4 on parallel::fullydistributed::Triangulation (any number of MPI ranks, one
//          included), built from meccano::fullydistributed_description: rank 0 builds the coarse mesh
//          with S's faces marked by their manifold id, METIS partitions it; each rank takes the S faces
//          of the cells it owns on S's negative side (meccano::interface_cell_faces). u = g_D on every
//          boundary face whose boundary id (box sides 1-6, other faces 0) is not one of the problem's
//          flux sides. CG with Trilinos ML AMG, relative residual 1e-12.
//          Geometry: affine tets, S_h's faces flat; for P2 when the problem knows S exactly
//          (InterfaceProblem::exact_surface), the cells are curved onto S instead: S_h's vertices are
//          moved onto S and a degree-2 MappingFE puts the midpoints of S_h's edges on S
//          (InterfaceEdgeManifold), so that S is represented to O(h³), as P2's L2 rate needs.
// Output   a SolveReport: sizes, CG iterations, the flux balance, the solution's norms, and the errors
//          in L2 and in the H1 seminorm when the exact solution is known; optionally VTU files.
#pragma once

#include "cube_example.hpp"
#include "fault_example.hpp"
#include "inclusion_example.hpp"
#include "interface_triangles.hpp"

#include <deal.II/base/mpi.h>

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace solver_demo {

// S as a formula, where the problem knows it.
struct ExactSurface {
  SurfaceProjection project;
  std::function<Eigen::Vector3d(const Eigen::Vector3d&)> normal;  // S's unit normal at project(p)
};

// The data are functions of the point and, where they differ on the two sides of a closed S, of the cell's
// material id (meccano::domain_tag outside every inclusion, 2 + k inside the closed surface k): each side's
// formula is smooth across S, and a quadrature point of a cell between S and S_h takes its cell's side.
struct InterfaceProblem {
  using material_id = dealii::types::material_id;
  std::string description;
  std::function<double(material_id)> coefficient;                                       // β
  std::function<double(const Eigen::Vector3d&, material_id)> right_hand_side;           // f
  std::function<double(const Eigen::Vector3d&)> boundary_values;                        // g_D
  std::function<double(const Eigen::Vector3d&)> interface_source;                       // g_S
  std::function<ValueAndGradient(const Eigen::Vector3d&, material_id)> exact_solution;  // empty when unknown
  std::optional<ExactSurface> exact_surface;                                            // empty when unknown
  // Γ_N: the boundary ids (box sides, meccano::box_side_tag) where β∂u/∂n = g_N is given instead of u;
  // g_N at a point with the outward unit normal there. Empty: u = g_D on all of ∂Ω.
  std::vector<dealii::types::boundary_id> flux_sides = {};
  std::function<double(const Eigen::Vector3d& point, const Eigen::Vector3d& outward_normal)> boundary_flux = {};
};

// The cube example's manufactured solution (cube_example.hpp); S must be the cube example's surface.
InterfaceProblem manufactured_problem();
// The inclusion example's coefficient jump (inclusion_example.hpp); S must be its sphere, and the cells
// inside it must carry `inside` as material id (2 for the mesh's first surface).
InterfaceProblem inclusion_problem(dealii::types::material_id inside = 2);
// The fault example's flux jump with a flux condition on the box top (fault_example.hpp); S must be its fault.
InterfaceProblem fault_problem();
// Any surface: β = 1, f = 0, g_D = 0, g_S = 1. u is the potential of a uniform source on S.
InterfaceProblem unit_source_problem();

struct SolveReport {
  unsigned long long cells = 0;
  unsigned long long dofs = 0;
  unsigned long long interface_faces = 0;
  unsigned long long flux_faces = 0;  // boundary faces on Γ_N (InterfaceProblem::flux_sides)
  double h = 0.0;                     // longest edge
  bool curved = false;                // cells curved onto S (InterfaceProblem::exact_surface, P2)
  unsigned int cg_iterations = 0;
  // Flux balance: what the sources put in, ∫_Ω f + ∫_S g_S, against what leaves through the box sides
  // by the discrete gradient, −∫_∂Ω β∇u_h·n (Γ_N included). Equal for the exact solution; they agree
  // as h → 0.
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
