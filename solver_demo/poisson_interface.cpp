// poisson_interface: the demo solver on one mesh with an immersed surface, from any mesher.
// Exit status: 0 success, 1 failure (bad input, cannot write), 2 usage error.

#include "command_line.hpp"
#include "cube_example.hpp"
#include "interface_poisson.hpp"

#include <meccano/error.hpp>
#include <meccano/io/atomic_file.hpp>
#include <meccano/report/json_writer.hpp>

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>

namespace {

using namespace solver_demo;

constexpr const char* usage =
    R"(Usage: poisson_interface --mesh FILE.msh [--interface NAME] [--degree 1|2] [--vtu PREFIX]
                         [--report FILE.json]

Solves -Δu = f in the mesh's domain, u = g_D on its boundary, with the flux jump
du/dn|below - du/dn|above = g_S on the immersed surface S (the triangles of the 2D physical group
interface_NAME), with continuous P1 or P2 elements on the tets (deal.II, CG + Trilinos ML AMG).

If S is the cube example's surface (meshes/cube_example.obj: every interface node on its formula, to
5 % of the mean interface edge), the problem is the manufactured one of doc/solver.md, and the errors
in L2 and in the H1 seminorm and the angles between the faces' normals and S's are printed.
Otherwise f = 0, g_D = 0 and g_S = 1, and the solution's norms are printed. Both print the flux
balance: int_Omega f + int_S g_S against the outflow -int_boundary grad u_h . n.

Options:
  --mesh FILE.msh     Gmsh MSH (2.2 or 4.1, ASCII or binary) with linear tets and 2D groups
                      interface_NAME of interior faces (from meccano-immerse, reference-gmsh,
                      Gmsh, ...), read by meccano::read_dealii_mesh; the groups xmin ... zmax,
                      where present, must be boundary faces (required)
  --interface NAME    which interface_NAME group is S (default: the file's only one)
  --degree 1|2        polynomial degree (default 1)
  --vtu PREFIX        write PREFIX.vtu (u_h, and u_h - I_h u where u is known; PREFIX.pvtu and
                      PREFIX.RANK.vtu under MPI) and PREFIX_interface.vtu (S's triangles)
  --report FILE.json  the run as JSON (rank 0 writes it): mesh, interface, degree, cells, dofs, h,
                      cg_iterations, manufactured (true or false), errors {l2, h1} and
                      normal_angle_deg {max, mean} for the manufactured problem, norms {l2,
                      h1_seminorm}, flux {source, outflow, relative_difference}, seconds {read, setup,
                      assembly, solve, postprocess, total} and ranks

Runs under MPI as well: mpirun -np 2 poisson_interface --mesh FILE.msh
)";

double relative_flux_difference(const SolveReport& report) {
  return std::abs(report.outflow - report.source) / std::abs(report.source);
}

// The run as JSON: the numbers the text output prints, at full precision.
void write_report(const std::string& path, const Options& options, const meccano::DealiiInterface& interface,
                  unsigned int degree, const SolveReport& report, const std::optional<NormalError>& normals,
                  double read_seconds, double total_seconds, unsigned int ranks) {
  meccano::JsonWriter json;
  json.begin_object().key("mesh").value(options.at("--mesh"));
  json.key("interface").value("interface_" + interface.name);
  json.key("degree").value(degree).key("cells").value(report.cells).key("dofs").value(report.dofs);
  json.key("h").value(report.h).key("cg_iterations").value(report.cg_iterations);
  json.key("manufactured").value(normals.has_value());  // the normals are measured against the cube example's S
  if (normals) {
    json.key("errors").begin_object().key("l2").value(*report.l2_error).key("h1").value(*report.h1_error).end_object();
    json.key("normal_angle_deg").begin_object().key("max").value(normals->max_deg);
    json.key("mean").value(normals->mean_deg).end_object();
  }
  json.key("norms").begin_object().key("l2").value(report.l2_norm);
  json.key("h1_seminorm").value(report.h1_seminorm).end_object();
  json.key("flux").begin_object().key("source").value(report.source).key("outflow").value(report.outflow);
  json.key("relative_difference").value(relative_flux_difference(report)).end_object();
  json.key("seconds").begin_object().key("read").value(read_seconds).key("setup").value(report.setup_seconds);
  json.key("assembly").value(report.assembly_seconds).key("solve").value(report.solve_seconds);
  json.key("postprocess").value(report.postprocess_seconds).key("total").value(total_seconds).end_object();
  json.key("ranks").value(ranks).end_object();
  const std::string text = json.str();
  meccano::write_file_atomically(path, [&text](std::ostream& out) { out << text; });
}

// The interface `name` of the file's mesh (empty: its only one); where the file has several, the error
// says which option names one.
const meccano::DealiiInterface& file_interface(const meccano::DealiiMesh& mesh, const std::string& name) {
  try {
    return mesh.interface(name);
  } catch (const meccano::InputError& error) {
    throw meccano::InputError(error.what() + std::string(name.empty() ? " with --interface" : ""));
  }
}

void solve(MPI_Comm communicator, const Options& options) {
  const unsigned int degree = options.count("--degree") ? parse_degree(options.at("--degree")) : 1;
  const std::string vtu = options.count("--vtu") ? options.at("--vtu") : "";
  const std::string interface_name = options.count("--interface") ? options.at("--interface") : "";
  const bool root = dealii::Utilities::MPI::this_mpi_process(communicator) == 0;

  // Rank 0 reads the mesh and decides which problem to solve; the solver distributes the mesh.
  const auto start = std::chrono::steady_clock::now();
  meccano::DealiiMesh mesh;
  const meccano::DealiiInterface* interface = nullptr;  // S, on rank 0
  SurfaceMatch match;
  if (root) {
    mesh = meccano::read_dealii_mesh(options.at("--mesh"));
    interface = &file_interface(mesh, interface_name);
    match = match_cube_example_surface(*interface);
  }
  const double read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const bool manufactured = dealii::Utilities::MPI::broadcast(communicator, match.matches(), 0);
  const InterfaceProblem problem = manufactured ? manufactured_problem() : unit_source_problem();

  const SolveReport report = solve_interface_problem(communicator, mesh, interface_name, degree, problem, vtu);
  const double total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!root) return;

  const meccano::DealiiInterface& surface = *interface;
  std::vector<TriangleField> fields;
  std::optional<NormalError> normals;
  std::cout << std::setprecision(4) << "mesh        " << options.at("--mesh") << ": " << report.cells
            << " tets, h = " << report.h << " (longest edge); interface_" << surface.name << ": " << surface.triangles()
            << " triangles, area " << interface_area(surface) << '\n';
  if (manufactured) {
    normals = cube_example_normal_error(surface);
    fields.emplace_back("normal_angle_deg", normals->per_triangle_deg);
    std::cout << "surface     the cube example's (nodes within " << match.max_deviation << " of its formula, tolerance "
              << match.tolerance << "): the manufactured solution\n"
              << "normals     angle to S's normal: max " << normals->max_deg << " deg, mean " << normals->mean_deg
              << " deg (area-weighted)\n";
  } else {
    std::cout << "surface     not the cube example's (nodes up to " << match.max_deviation
              << " off its formula, tolerance " << match.tolerance << "): f = 0, g_D = 0, g_S = 1\n";
  }
  std::cout << "system      P" << degree << ", " << report.dofs << " dofs, " << report.interface_faces
            << " faces on S, CG + AMG: " << report.cg_iterations << " iterations\n"
            << std::setprecision(12) << std::scientific;
  if (report.l2_error)
    std::cout << "L2 error    " << *report.l2_error << '\n' << "H1 error    " << *report.h1_error << '\n';
  std::cout << "norms       L2 " << report.l2_norm << ", H1 seminorm " << report.h1_seminorm << '\n'
            << "source      " << report.source << "  (int_Omega f + int_S g_S)\n"
            << "outflow     " << report.outflow << "  (-int_boundary grad u_h . n)\n"
            << std::setprecision(3) << "balance     relative difference " << relative_flux_difference(report) << '\n'
            << std::fixed << "seconds     read " << read_seconds << ", setup " << report.setup_seconds << ", assembly "
            << report.assembly_seconds << ", solve " << report.solve_seconds << ", evaluation and output "
            << report.postprocess_seconds << ", total " << total_seconds << '\n';

  if (!vtu.empty()) {
    std::vector<double> source;
    for (std::size_t t = 0; t < surface.triangles(); ++t)
      source.push_back(problem.interface_source(centroid(surface, t)));
    fields.emplace_back("g_S", std::move(source));
    write_interface_vtu(surface, fields, vtu + "_interface.vtu");
  }
  if (options.count("--report"))
    write_report(options.at("--report"), options, surface, degree, report, normals, read_seconds, total_seconds,
                 dealii::Utilities::MPI::n_mpi_processes(communicator));
}

}  // namespace

int main(int argc, char** argv) {
  return run_program(argc, argv, "poisson_interface", usage, solve,
                     {"--mesh", "--interface", "--degree", "--vtu", "--report"}, {"--mesh"});
}
