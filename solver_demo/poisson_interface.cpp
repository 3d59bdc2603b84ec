// poisson_interface: the demo solver on one mesh with an immersed surface, from any mesher.
// Exit status: 0 success, 1 failure (bad input, cannot write), 2 usage error.

#include "command_line.hpp"
#include "cube_example.hpp"
#include "interface_mesh.hpp"
#include "interface_poisson.hpp"

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>

namespace {

using namespace solver_demo;

constexpr const char* usage = R"(Usage: poisson_interface --mesh FILE.msh [--interface NAME] [--degree 1|2] [--vtu PREFIX]

Solves -Δu = f in the mesh's domain, u = g_D on its boundary, with the flux jump
du/dn|below - du/dn|above = g_S on the immersed surface S (the triangles of the 2D physical group
interface_NAME), with continuous P1 or P2 elements on the tets (deal.II, CG + Trilinos ML AMG).

If S is the cube example's surface (meshes/cube_example.obj: every interface node on its formula, to
5 % of the mean interface edge), the problem is the manufactured one of doc/solver.md, and the errors
in L2 and in the H1 seminorm and the angles between the faces' normals and S's are printed.
Otherwise f = 0, g_D = 0 and g_S = 1, and the solution's norms are printed. Both print the flux
balance: int_Omega f + int_S g_S against the outflow -int_boundary grad u_h . n.

Options:
  --mesh FILE.msh     Gmsh MSH (2.2 or 4.1, ASCII or binary) with linear tets and the group
                      interface_NAME (from meccano-immerse, reference-gmsh, Gmsh, ...) (required)
  --interface NAME    which interface_NAME group is S (default: the file's only one)
  --degree 1|2        polynomial degree (default 1)
  --vtu PREFIX        write PREFIX.vtu (u_h, and u_h - I_h u where u is known; PREFIX.pvtu and
                      PREFIX.RANK.vtu under MPI) and PREFIX_interface.vtu (S's triangles)

Runs under MPI as well: mpirun -np 2 poisson_interface --mesh FILE.msh
)";

void solve(MPI_Comm communicator, const Options& options) {
  const unsigned int degree = options.count("--degree") ? parse_degree(options.at("--degree")) : 1;
  const std::string vtu = options.count("--vtu") ? options.at("--vtu") : "";
  const bool root = dealii::Utilities::MPI::this_mpi_process(communicator) == 0;

  // Rank 0 reads the mesh and decides which problem to solve; the solver distributes the mesh.
  const auto start = std::chrono::steady_clock::now();
  InterfaceMesh mesh;
  SurfaceMatch match;
  if (root) {
    mesh = read_interface_mesh(options.at("--mesh"), options.count("--interface") ? options.at("--interface") : "");
    match = match_cube_example_surface(mesh);
  }
  const double read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const bool manufactured = dealii::Utilities::MPI::broadcast(communicator, match.matches(), 0);
  const InterfaceProblem problem = manufactured ? manufactured_problem() : unit_source_problem();

  const SolveReport report = solve_interface_problem(communicator, mesh, degree, problem, vtu);
  if (!root) return;

  std::vector<TriangleField> fields;
  std::cout << std::setprecision(4) << "mesh        " << options.at("--mesh") << ": " << report.cells << " tets, h = "
            << report.h << " (longest edge); interface_" << mesh.interface_name << ": " << mesh.interface.size()
            << " triangles, area " << interface_area(mesh) << '\n';
  if (manufactured) {
    const NormalError normals = cube_example_normal_error(mesh);
    fields.emplace_back("normal_angle_deg", normals.per_triangle_deg);
    std::cout << "surface     the cube example's (nodes within " << match.max_deviation << " of its formula, tolerance "
              << match.tolerance << "): the manufactured solution\n"
              << "normals     angle to S's normal: max " << normals.max_deg << " deg, mean " << normals.mean_deg
              << " deg (area-weighted)\n";
  } else {
    std::cout << "surface     not the cube example's (nodes up to " << match.max_deviation << " off its formula, tolerance "
              << match.tolerance << "): f = 0, g_D = 0, g_S = 1\n";
  }
  std::cout << "system      P" << degree << ", " << report.dofs << " dofs, " << report.interface_faces
            << " faces on S, CG + AMG: " << report.cg_iterations << " iterations\n"
            << std::setprecision(12) << std::scientific;
  if (report.l2_error) std::cout << "L2 error    " << *report.l2_error << '\n' << "H1 error    " << *report.h1_error << '\n';
  std::cout << "norms       L2 " << report.l2_norm << ", H1 seminorm " << report.h1_seminorm << '\n'
            << "source      " << report.source << "  (int_Omega f + int_S g_S)\n"
            << "outflow     " << report.outflow << "  (-int_boundary grad u_h . n)\n"
            << std::setprecision(3) << "balance     relative difference "
            << std::abs(report.outflow - report.source) / std::abs(report.source) << '\n'
            << std::fixed << "seconds     read " << read_seconds << ", setup " << report.setup_seconds << ", assembly "
            << report.assembly_seconds << ", solve " << report.solve_seconds << ", evaluation and output "
            << report.postprocess_seconds << '\n';

  if (!vtu.empty()) {
    std::vector<double> source;
    for (const auto& t : mesh.interface) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (const unsigned int v : t) centroid += Eigen::Vector3d(mesh.points[v].data()) / 3.0;
      source.push_back(problem.interface_source(centroid));
    }
    fields.emplace_back("g_S", std::move(source));
    write_interface_vtu(mesh, fields, vtu + "_interface.vtu");
  }
}

}  // namespace

int main(int argc, char** argv) {
  return run_program(argc, argv, "poisson_interface", usage, solve, {"--mesh", "--interface", "--degree", "--vtu"},
                     {"--mesh"});
}
