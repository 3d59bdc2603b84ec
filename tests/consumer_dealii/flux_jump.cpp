// A complete deal.II program on a mesh with an inserted surface, built against the installed
// meccano-immerse (target meccano::dealii). It solves
//
//   -Δu = 0 in the box,   u = 0 on the box sides (boundary ids 1-6),   [∂u/∂n] = 1 on S,
//
// whose weak form ∫ ∇u·∇v = ∫_S v puts S in the right-hand side only: a face integral over the faces of
// S, which the adapter lists with the cells on both sides. Whatever enters through S leaves through the
// box sides, so the outflow -∫_∂Ω ∇u_h·n approaches the area of S as the mesh is refined.
//
//   flux_jump                     inserts a curved patch into the unit cube with the library
//   flux_jump MESH.msh [NAME]     reads a mesh file with the group interface_NAME (NAME optional if
//                                 the file has one interface)
//
// It prints the sizes, the area of S and the outflow, and exits 1 if S's faces do not add up to S's
// triangles or the outflow is off by more than 25 % (the far field of these small meshes is coarse).

#include <meccano/dealii_mesh.hpp>
#include <meccano/mesh/cube_meccano.hpp>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/numerics/vector_tools.h>

#include <cmath>
#include <iostream>
#include <numbers>

using namespace dealii;

namespace {

// z = 0.5 + 0.1 sin(πu) sin(πv) over (x, y) = (0.25 + 0.5u, 0.25 + 0.5v): n x n cells of two triangles.
meccano::TriangleSurface curved_patch(int n) {
  meccano::TriangleSurface patch;
  patch.name = "patch";
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double u = double(i) / n, v = double(j) / n;
      patch.points.emplace_back(0.25 + 0.5 * u, 0.25 + 0.5 * v,
                                0.5 + 0.1 * std::sin(std::numbers::pi * u) * std::sin(std::numbers::pi * v));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      patch.triangles.push_back({a, a + 1, a + n + 2});
      patch.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  return patch;
}

class FluxJump {
 public:
  explicit FluxJump(const meccano::DealiiMesh& mesh, const meccano::DealiiInterface& interface)
      : mesh(mesh), interface(interface), mapping(FE_SimplexP<3>(1)), fe(1), dof_handler(triangulation) {}
  bool run();

 private:
  void make_grid();
  void setup_system();
  void assemble_system();
  void solve();
  bool check() const;

  const meccano::DealiiMesh& mesh;
  const meccano::DealiiInterface& interface;
  Triangulation<3> triangulation;
  std::vector<meccano::InterfaceCellFace> interface_faces;
  const MappingFE<3> mapping;
  const FE_SimplexP<3> fe;
  DoFHandler<3> dof_handler;
  AffineConstraints<double> constraints;
  SparsityPattern sparsity;
  SparseMatrix<double> system_matrix;
  Vector<double> solution, system_rhs;
};

// S's faces carry its manifold id until they are harvested; then every id goes back to flat, since
// MappingFE wants a cell and its faces on one manifold.
void FluxJump::make_grid() {
  meccano::create_triangulation(mesh, triangulation);
  interface_faces = meccano::interface_cell_faces(triangulation, interface);
  triangulation.set_all_manifold_ids(numbers::flat_manifold_id);
}

// u = 0 on every box side: boundary ids 1-6 (xmin ... zmax).
void FluxJump::setup_system() {
  dof_handler.distribute_dofs(fe);
  constraints.clear();
  for (types::boundary_id side = 1; side <= 6; ++side)
    VectorTools::interpolate_boundary_values(mapping, dof_handler, side, Functions::ZeroFunction<3>(), constraints);
  constraints.close();
  DynamicSparsityPattern dsp(dof_handler.n_dofs());
  DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
  sparsity.copy_from(dsp);
  system_matrix.reinit(sparsity);
  solution.reinit(dof_handler.n_dofs());
  system_rhs.reinit(dof_handler.n_dofs());
}

// A_ij = ∫ ∇φ_i·∇φ_j cell by cell; F_i = ∫_S φ_i face by face, from the negative side of each face
// (either side gives the same values: u_h is continuous).
void FluxJump::assemble_system() {
  FEValues<3> fe_values(mapping, fe, QGaussSimplex<3>(2), update_gradients | update_JxW_values);
  FEFaceValues<3> fe_face_values(mapping, fe, QGaussSimplex<2>(2), update_values | update_JxW_values);
  FullMatrix<double> cell_matrix(fe.n_dofs_per_cell(), fe.n_dofs_per_cell());
  Vector<double> cell_rhs(fe.n_dofs_per_cell());
  std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    fe_values.reinit(cell);
    cell_matrix = 0;
    for (const unsigned int q : fe_values.quadrature_point_indices())
      for (const unsigned int i : fe_values.dof_indices())
        for (const unsigned int j : fe_values.dof_indices())
          cell_matrix(i, j) += fe_values.shape_grad(i, q) * fe_values.shape_grad(j, q) * fe_values.JxW(q);
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(cell_matrix, dofs, system_matrix);
  }
  for (const meccano::InterfaceCellFace& face : interface_faces) {
    const DoFHandler<3>::active_cell_iterator cell(&triangulation, face.negative->level(), face.negative->index(),
                                                   &dof_handler);
    fe_face_values.reinit(cell, face.negative_face);
    cell_rhs = 0;
    for (const unsigned int q : fe_face_values.quadrature_point_indices())
      for (const unsigned int i : fe_face_values.dof_indices())
        cell_rhs(i) += fe_face_values.shape_value(i, q) * fe_face_values.JxW(q);
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(cell_rhs, dofs, system_rhs);
  }
}

void FluxJump::solve() {
  SolverControl control(10 * dof_handler.n_dofs(), 1e-12 * system_rhs.l2_norm());
  PreconditionSSOR<SparseMatrix<double>> ssor;
  ssor.initialize(system_matrix, 1.2);
  SolverCG<Vector<double>>(control).solve(system_matrix, solution, system_rhs, ssor);
  constraints.distribute(solution);
  std::cout << "CG: " << control.last_step() << " iterations\n";
}

bool FluxJump::check() const {
  double area = 0.0;
  for (std::size_t t = 0; t < interface.triangles(); ++t) {
    const Point<3>* p = &interface.corners[3 * t];
    area += 0.5 * cross_product_3d(p[1] - p[0], p[2] - p[0]).norm();
  }
  FEFaceValues<3> fe_face_values(mapping, fe, QGaussSimplex<2>(2),
                                 update_gradients | update_normal_vectors | update_JxW_values);
  std::vector<Tensor<1, 3>> gradients(fe_face_values.n_quadrature_points);
  double outflow = 0.0;
  for (const auto& cell : dof_handler.active_cell_iterators())
    for (const unsigned int f : cell->face_indices())
      if (cell->at_boundary(f)) {
        fe_face_values.reinit(cell, f);
        fe_face_values.get_function_gradients(solution, gradients);
        for (const unsigned int q : fe_face_values.quadrature_point_indices())
          outflow -= gradients[q] * fe_face_values.normal_vector(q) * fe_face_values.JxW(q);
      }
  std::cout << triangulation.n_active_cells() << " cells, " << dof_handler.n_dofs() << " dofs; interface_"
            << interface.name << " (manifold id " << interface.tag << "): " << interface_faces.size() << " of "
            << interface.triangles() << " triangles found, area " << area << "; outflow " << outflow << '\n';
  return interface_faces.size() == interface.triangles() && std::abs(outflow - area) < 0.25 * area;
}

bool FluxJump::run() {
  make_grid();
  setup_system();
  assemble_system();
  solve();
  return check();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
    meccano::DealiiMesh mesh;
    if (argc > 1) {
      mesh = meccano::read_dealii_mesh(argv[1]);
    } else {
      const meccano::Box unit_cube{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
      const std::vector<meccano::TriangleSurface> surfaces{curved_patch(8)};
      meccano::InsertionOptions options;
      options.resolution = 0.0625;
      mesh =
          meccano::dealii_mesh(meccano::insert_surfaces(meccano::make_cube_meccano(unit_cube, 1), surfaces, options));
    }
    FluxJump problem(mesh, mesh.interface(argc > 2 ? argv[2] : ""));
    const bool passed = problem.run();
    std::cout << (passed ? "ok" : "FAILED") << '\n';
    return passed ? 0 : 1;
  } catch (const std::exception& error) {
    std::cerr << "flux_jump: " << error.what() << '\n';
    return 1;
  }
}
