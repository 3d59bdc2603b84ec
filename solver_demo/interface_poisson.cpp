// The solver class, in the style of deal.II's tutorial programs (step-6, step-40): run() sets up the
// distributed mesh and the linear system, assembles, solves, evaluates and writes output.

#include "interface_poisson.hpp"

#include "curved_interface.hpp"

#include <meccano/io/atomic_file.hpp>
#include <meccano/mesh/tet_mesh.hpp>

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

namespace solver_demo {

using namespace dealii;

namespace {

// The flux jump of kinked_graph.hpp across the graph's S, with β = 1 and u given on the box sides.
InterfaceProblem flux_jump_problem(const KinkedGraph& graph, std::string description) {
  using material_id = InterfaceProblem::material_id;
  const KinkedGraph* g = &graph;
  return {.description = std::move(description),
          .coefficient = [](material_id) { return 1.0; },
          .right_hand_side = [g](const Eigen::Vector3d& p, material_id) { return kinked_right_hand_side(*g, p); },
          .boundary_values = [g](const Eigen::Vector3d& p) { return kinked_solution(*g, p).value; },
          .interface_source = [g](const Eigen::Vector3d& p) { return kinked_interface_source(*g, p); },
          .exact_solution = [g](const Eigen::Vector3d& p, material_id) { return kinked_solution(*g, p); },
          .exact_surface = ExactSurface{[g](const Eigen::Vector3d& p) { return graph_point(*g, p); },
                                        [g](const Eigen::Vector3d& p) { return graph_normal(*g, p); }}};
}

}  // namespace

InterfaceProblem manufactured_problem() {
  return flux_jump_problem(cube_example, "manufactured solution of the cube example (doc/solver.md)");
}

InterfaceProblem fault_problem() {
  InterfaceProblem problem = flux_jump_problem(
      fault_example, "flux jump across the fault example's fault, flux given on the top (doc/solver.md)");
  problem.flux_sides = {meccano::box_side_tag(meccano::BoxSide::zmax)};
  problem.boundary_flux = [](const Eigen::Vector3d& p, const Eigen::Vector3d& outward_normal) {
    return kinked_solution(fault_example, p).gradient.dot(outward_normal);
  };
  return problem;
}

InterfaceProblem inclusion_problem(dealii::types::material_id inside) {
  using material_id = InterfaceProblem::material_id;
  return {
      .description = "coefficient jump across the inclusion example's sphere (doc/solver.md)",
      .coefficient = [inside](material_id m) { return m == inside ? inclusion.beta_inside : inclusion.beta_outside; },
      .right_hand_side = [inside](const Eigen::Vector3d& p,
                                  material_id m) { return inclusion_right_hand_side(p, m == inside); },
      .boundary_values = [](const Eigen::Vector3d& p) { return inclusion_solution(p, false).value; },
      .interface_source = [](const Eigen::Vector3d&) { return 0.0; },
      .exact_solution = [inside](const Eigen::Vector3d& p,
                                 material_id m) { return inclusion_solution(p, m == inside); },
      .exact_surface = ExactSurface{project_onto_inclusion, inclusion_normal}};
}

InterfaceProblem unit_source_problem() {
  return {.description = "-Δu = 0, u = 0 on the box sides, unit flux jump on S",
          .coefficient = [](InterfaceProblem::material_id) { return 1.0; },
          .right_hand_side = [](const Eigen::Vector3d&, InterfaceProblem::material_id) { return 0.0; },
          .boundary_values = [](const Eigen::Vector3d&) { return 0.0; },
          .interface_source = [](const Eigen::Vector3d&) { return 1.0; },
          .exact_solution = {},
          .exact_surface = {}};
}

namespace {

Tensor<1, 3> to_tensor(const Eigen::Vector3d& v) { return Point<3>(v.x(), v.y(), v.z()); }

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

class InterfacePoisson {
 public:
  InterfacePoisson(MPI_Comm communicator, unsigned int degree, const InterfaceProblem& problem);
  SolveReport run(const meccano::DealiiMesh& mesh, const std::string& interface_name, const std::string& vtu_prefix);

 private:
  void make_grid(const meccano::DealiiMesh& mesh, const std::string& interface_name);
  void setup_system();
  void assemble_system();
  void solve();
  void evaluate();
  void output_results(const std::string& prefix) const;
  bool is_flux_side(types::boundary_id id) const;

  MPI_Comm communicator;
  const InterfaceProblem& problem;
  // Cells curved onto S (see the header): P2 with S known exactly.
  const bool curved;

  parallel::fullydistributed::Triangulation<3> triangulation;
  // The S faces this rank integrates over: each face once, from its negative side.
  std::vector<meccano::InterfaceCellFace> interface_faces;

  // Affine tets, or degree-2 ones whose edges on S_h are curved onto S.
  const MappingFE<3> mapping;
  const FE_SimplexP<3> fe;
  DoFHandler<3> dof_handler;
  IndexSet locally_owned_dofs;
  IndexSet locally_relevant_dofs;

  AffineConstraints<double> constraints;  // the Dirichlet values
  TrilinosWrappers::SparseMatrix system_matrix;
  TrilinosWrappers::MPI::Vector locally_relevant_solution;
  TrilinosWrappers::MPI::Vector system_rhs;

  SolveReport report;
};

InterfacePoisson::InterfacePoisson(MPI_Comm communicator_, unsigned int degree, const InterfaceProblem& problem_)
    : communicator(communicator_),
      problem(problem_),
      curved(degree > 1 && problem_.exact_surface.has_value()),
      triangulation(communicator_),
      mapping(FE_SimplexP<3>(curved ? degree : 1)),
      fe(degree),
      dof_handler(triangulation) {}

// Rank 0 builds the whole coarse mesh and METIS cuts it into one part per rank; each rank receives its
// cells and one layer of ghosts. The manifold id of S's faces survives the distribution. Each rank
// then harvests the S faces of the cells it owns, by their corners in rank 0's interfaces, and gives
// every cell, face and line one manifold id, as MappingFE insists (in Debug): flat, or for a curved
// geometry the InterfaceEdgeManifold, after S_h's vertices have been moved onto S.
void InterfacePoisson::make_grid(const meccano::DealiiMesh& input, const std::string& interface_name) {
  std::optional<meccano::DealiiMesh> moved;
  if (curved && Utilities::MPI::this_mpi_process(communicator) == 0)
    moved = with_interface_on_surface(input, interface_name, problem.exact_surface->project);
  const meccano::DealiiMesh& mesh = moved ? *moved : input;
  triangulation.create_triangulation(meccano::fullydistributed_description(mesh, communicator));
  meccano::DealiiMesh every_rank;  // rank 0's interfaces only
  every_rank.interfaces = Utilities::MPI::broadcast(communicator, mesh.interfaces, 0);
  const meccano::DealiiInterface& interface = every_rank.interface(interface_name);
  interface_faces = meccano::interface_cell_faces(triangulation, interface);
  if (curved) curve_cells_onto_surface(triangulation, interface, problem.exact_surface->project);
  else triangulation.set_all_manifold_ids(numbers::flat_manifold_id);
  report.curved = curved;

  double h = 0.0;
  for (const auto& cell : triangulation.active_cell_iterators())
    if (cell->is_locally_owned())
      for (const unsigned int l : cell->line_indices()) h = std::max(h, cell->line(l)->diameter());
  report.cells = triangulation.n_global_active_cells();
  report.h = Utilities::MPI::max(h, communicator);
  report.interface_faces = Utilities::MPI::sum<unsigned long long>(interface_faces.size(), communicator);
  if (report.interface_faces != interface.triangles())
    throw std::logic_error("the distributed mesh has " + std::to_string(report.interface_faces) +
                           " faces on S, the input " + std::to_string(interface.triangles()));
}

// Degrees of freedom, the Dirichlet constraints u = g_D on every boundary face (S's faces are interior)
// outside Γ_N, whatever its boundary id: 1-6 on the box sides, 0 on the faces a foreign mesh puts in no
// side group; and the sparsity of the distributed matrix.
void InterfacePoisson::setup_system() {
  dof_handler.distribute_dofs(fe);
  report.dofs = dof_handler.n_dofs();
  locally_owned_dofs = dof_handler.locally_owned_dofs();
  locally_relevant_dofs = DoFTools::extract_locally_relevant_dofs(dof_handler);
  locally_relevant_solution.reinit(locally_owned_dofs, locally_relevant_dofs, communicator);
  system_rhs.reinit(locally_owned_dofs, communicator);

  constraints.clear();
  constraints.reinit(locally_relevant_dofs);
  const ScalarFunctionFromFunctionObject<3> boundary_values(
      [this](const Point<3>& p) { return problem.boundary_values(to_eigen(p)); });
  std::map<types::boundary_id, const Function<3>*> dirichlet;
  for (const types::boundary_id id : triangulation.get_boundary_ids())
    if (!is_flux_side(id)) dirichlet.emplace(id, &boundary_values);
  VectorTools::interpolate_boundary_values(mapping, dof_handler, dirichlet, constraints);
  constraints.close();

  DynamicSparsityPattern dsp(locally_relevant_dofs);
  DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
  SparsityTools::distribute_sparsity_pattern(dsp, locally_owned_dofs, communicator, locally_relevant_dofs);
  system_matrix.reinit(locally_owned_dofs, locally_owned_dofs, dsp, communicator);
}

bool InterfacePoisson::is_flux_side(types::boundary_id id) const {
  return std::find(problem.flux_sides.begin(), problem.flux_sides.end(), id) != problem.flux_sides.end();
}

// A_ij = ∫_Ω β ∇φ_i·∇φ_j and F_i = ∫_Ω f φ_i + ∫_Γ_N g_N φ_i cell by cell, then F_i += ∫_S g_S φ_i face by
// face. The surface terms have no matrix part, so the constraints only drop their constrained rows; the
// one on S is what makes the gradient of u_h jump across S.
void InterfacePoisson::assemble_system() {
  const QGaussSimplex<3> quadrature(fe.degree + 1);
  FEValues<3> fe_values(mapping, fe, quadrature,
                        update_values | update_gradients | update_quadrature_points | update_JxW_values);
  const QGaussSimplex<2> face_quadrature(fe.degree + 2);
  FEFaceValues<3> fe_face_values(mapping, fe, face_quadrature,
                                 update_values | update_normal_vectors | update_quadrature_points | update_JxW_values);
  const unsigned int dofs_per_cell = fe.n_dofs_per_cell();
  FullMatrix<double> cell_matrix(dofs_per_cell, dofs_per_cell);
  Vector<double> cell_rhs(dofs_per_cell);
  std::vector<types::global_dof_index> dof_indices(dofs_per_cell);

  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fe_values.reinit(cell);
    cell_matrix = 0;
    cell_rhs = 0;
    const types::material_id material = cell->material_id();
    const double beta = problem.coefficient(material);
    for (const unsigned int q : fe_values.quadrature_point_indices()) {
      const double f = problem.right_hand_side(to_eigen(fe_values.quadrature_point(q)), material);
      for (const unsigned int i : fe_values.dof_indices()) {
        for (const unsigned int j : fe_values.dof_indices())
          cell_matrix(i, j) += beta * fe_values.shape_grad(i, q) * fe_values.shape_grad(j, q) * fe_values.JxW(q);
        cell_rhs(i) += f * fe_values.shape_value(i, q) * fe_values.JxW(q);
      }
    }
    for (const unsigned int f : cell->face_indices()) {
      if (!cell->at_boundary(f) || !is_flux_side(cell->face(f)->boundary_id())) continue;
      ++report.flux_faces;
      fe_face_values.reinit(cell, f);
      for (const unsigned int q : fe_face_values.quadrature_point_indices()) {
        const double g = problem.boundary_flux(to_eigen(fe_face_values.quadrature_point(q)),
                                               to_eigen(Point<3>(fe_face_values.normal_vector(q))));
        for (const unsigned int i : fe_face_values.dof_indices())
          cell_rhs(i) += g * fe_face_values.shape_value(i, q) * fe_face_values.JxW(q);
      }
    }
    cell->get_dof_indices(dof_indices);
    constraints.distribute_local_to_global(cell_matrix, cell_rhs, dof_indices, system_matrix, system_rhs);
  }

  for (const meccano::InterfaceCellFace& face : interface_faces) {
    const DoFHandler<3>::active_cell_iterator cell(&triangulation, face.negative->level(), face.negative->index(),
                                                   &dof_handler);
    fe_face_values.reinit(cell, face.negative_face);
    cell_rhs = 0;
    for (const unsigned int q : fe_face_values.quadrature_point_indices()) {
      const double g = problem.interface_source(to_eigen(fe_face_values.quadrature_point(q)));
      for (const unsigned int i : fe_face_values.dof_indices())
        cell_rhs(i) += g * fe_face_values.shape_value(i, q) * fe_face_values.JxW(q);
    }
    cell->get_dof_indices(dof_indices);
    constraints.distribute_local_to_global(cell_rhs, dof_indices, system_rhs);
  }
  system_matrix.compress(VectorOperation::add);
  system_rhs.compress(VectorOperation::add);
  report.flux_faces = Utilities::MPI::sum(report.flux_faces, communicator);
}

// The matrix is symmetric positive definite: CG, preconditioned by one V-cycle of ML's smoothed
// aggregation AMG, whose iteration count stays flat as the mesh is refined.
void InterfacePoisson::solve() {
  TrilinosWrappers::MPI::Vector solution(locally_owned_dofs, communicator);
  SolverControl control(dof_handler.n_dofs(), 1e-12 * system_rhs.l2_norm());
  SolverCG<TrilinosWrappers::MPI::Vector> cg(control);
  TrilinosWrappers::PreconditionAMG amg;
  TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
  amg_data.elliptic = true;
  amg_data.higher_order_elements = fe.degree > 1;
  amg.initialize(system_matrix, amg_data);
  cg.solve(system_matrix, solution, system_rhs, amg);
  report.cg_iterations = control.last_step();
  constraints.distribute(solution);
  locally_relevant_solution = solution;
}

// Norms, errors and the flux balance, each rank over its own cells and faces, then summed. The error
// quadrature is one order above the assembly's: the exact u has its kink on the true S, which cuts
// through the cells next to the flat faces of S_h.
void InterfacePoisson::evaluate() {
  const QGaussSimplex<3> quadrature(std::min(fe.degree + 2, 4u));
  FEValues<3> fe_values(mapping, fe, quadrature,
                        update_values | update_gradients | update_quadrature_points | update_JxW_values);
  const QGaussSimplex<2> face_quadrature(fe.degree + 2);
  FEFaceValues<3> fe_face_values(
      mapping, fe, face_quadrature,
      update_gradients | update_normal_vectors | update_quadrature_points | update_JxW_values);
  std::vector<double> values(quadrature.size());
  std::vector<Tensor<1, 3>> gradients(quadrature.size()), face_gradients(face_quadrature.size());

  // l2², h1², l2_error², h1_error², source, outflow
  std::array<double, 6> sums{};
  auto& [l2, h1, l2_error, h1_error, source, outflow] = sums;
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fe_values.reinit(cell);
    fe_values.get_function_values(locally_relevant_solution, values);
    fe_values.get_function_gradients(locally_relevant_solution, gradients);
    const types::material_id material = cell->material_id();
    for (const unsigned int q : fe_values.quadrature_point_indices()) {
      const Eigen::Vector3d x = to_eigen(fe_values.quadrature_point(q));
      const double dx = fe_values.JxW(q);
      l2 += values[q] * values[q] * dx;
      h1 += gradients[q] * gradients[q] * dx;
      source += problem.right_hand_side(x, material) * dx;
      if (problem.exact_solution) {
        const ValueAndGradient u = problem.exact_solution(x, material);
        l2_error += (u.value - values[q]) * (u.value - values[q]) * dx;
        h1_error += (to_tensor(u.gradient) - gradients[q]).norm_square() * dx;
      }
    }
    for (const unsigned int f : cell->face_indices()) {
      if (!cell->at_boundary(f)) continue;
      fe_face_values.reinit(cell, f);
      fe_face_values.get_function_gradients(locally_relevant_solution, face_gradients);
      for (const unsigned int q : fe_face_values.quadrature_point_indices())
        outflow -=
            problem.coefficient(material) * face_gradients[q] * fe_face_values.normal_vector(q) * fe_face_values.JxW(q);
    }
  }
  for (const meccano::InterfaceCellFace& face : interface_faces) {
    fe_face_values.reinit(face.negative, face.negative_face);
    for (const unsigned int q : fe_face_values.quadrature_point_indices())
      source += problem.interface_source(to_eigen(fe_face_values.quadrature_point(q))) * fe_face_values.JxW(q);
  }
  Utilities::MPI::sum(ArrayView<const double>(sums.data(), sums.size()), communicator,
                      ArrayView<double>(sums.data(), sums.size()));

  report.l2_norm = std::sqrt(l2);
  report.h1_seminorm = std::sqrt(h1);
  report.source = source;
  report.outflow = outflow;
  if (problem.exact_solution) {
    report.l2_error = std::sqrt(l2_error);
    report.h1_error = std::sqrt(h1_error);
  }
}

void InterfacePoisson::output_results(const std::string& prefix) const {
  DataOut<3> data_out;
  data_out.attach_dof_handler(dof_handler);
  data_out.add_data_vector(locally_relevant_solution, "u");

  TrilinosWrappers::MPI::Vector error;  // u_h − I_h u, where u is known
  if (problem.exact_solution) {
    // Each cell's side formula; the two agree on S.
    std::map<types::material_id, ScalarFunctionFromFunctionObject<3>> exact;
    std::map<types::material_id, const Function<3>*> exact_by_material;
    for (const auto& cell : triangulation.active_cell_iterators()) {
      const types::material_id m = cell->material_id();
      const auto [function, added] =
          exact.try_emplace(m, [this, m](const Point<3>& p) { return problem.exact_solution(to_eigen(p), m).value; });
      if (added) exact_by_material.emplace(m, &function->second);
    }
    TrilinosWrappers::MPI::Vector interpolant(locally_owned_dofs, communicator);
    VectorTools::interpolate_based_on_material_id(mapping, dof_handler, exact_by_material, interpolant);
    TrilinosWrappers::MPI::Vector difference(locally_owned_dofs, communicator);
    difference = locally_relevant_solution;
    difference -= interpolant;
    error.reinit(locally_owned_dofs, locally_relevant_dofs, communicator);
    error = difference;
    data_out.add_data_vector(error, "error");
  }
  Vector<float> subdomain(triangulation.n_active_cells());
  subdomain = static_cast<float>(triangulation.locally_owned_subdomain());
  data_out.add_data_vector(subdomain, "subdomain");
  data_out.build_patches(mapping, fe.degree);

  const unsigned int ranks = Utilities::MPI::n_mpi_processes(communicator);
  const unsigned int rank = Utilities::MPI::this_mpi_process(communicator);
  const std::string piece = ranks == 1 ? prefix + ".vtu" : prefix + "." + std::to_string(rank) + ".vtu";
  meccano::write_file_atomically(piece, [&](std::ostream& out) { data_out.write_vtu(out); });
  if (ranks > 1 && rank == 0) {
    std::vector<std::string> pieces;
    const std::string stem = prefix.substr(prefix.find_last_of('/') + 1);
    for (unsigned int r = 0; r < ranks; ++r) pieces.push_back(stem + "." + std::to_string(r) + ".vtu");
    meccano::write_file_atomically(prefix + ".pvtu",
                                   [&](std::ostream& out) { data_out.write_pvtu_record(out, pieces); });
  }
}

SolveReport InterfacePoisson::run(const meccano::DealiiMesh& mesh, const std::string& interface_name,
                                  const std::string& vtu_prefix) {
  auto start = std::chrono::steady_clock::now();
  make_grid(mesh, interface_name);
  setup_system();
  report.setup_seconds = seconds_since(start);

  start = std::chrono::steady_clock::now();
  assemble_system();
  report.assembly_seconds = seconds_since(start);

  start = std::chrono::steady_clock::now();
  solve();
  report.solve_seconds = seconds_since(start);

  start = std::chrono::steady_clock::now();
  evaluate();
  if (!vtu_prefix.empty()) output_results(vtu_prefix);
  report.postprocess_seconds = seconds_since(start);
  return report;
}

}  // namespace

SolveReport solve_interface_problem(MPI_Comm communicator, const meccano::DealiiMesh& mesh,
                                    const std::string& interface_name, unsigned int degree,
                                    const InterfaceProblem& problem, const std::string& vtu_prefix) {
  if (degree != 1 && degree != 2)
    throw std::invalid_argument("the degree must be 1 or 2, not " + std::to_string(degree));
  InterfacePoisson solver(communicator, degree, problem);
  return solver.run(mesh, interface_name, vtu_prefix);
}

}  // namespace solver_demo
