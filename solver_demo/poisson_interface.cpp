// poisson_interface: the demo solver on one mesh with an immersed surface, from any mesher.
// Exit status: 0 success, 1 failure (bad input, cannot write), 2 usage error.

#include "command_line.hpp"
#include "cube_example.hpp"
#include "interface_poisson.hpp"

#include <meccano/error.hpp>
#include <meccano/io/atomic_file.hpp>
#include <meccano/mesh/tet_mesh.hpp>
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

If S is a surface of doc/solver.md's manufactured problems (every interface node on its formula, to
5 % of the mean interface edge), that problem is solved, and the errors in L2 and in the H1 seminorm
and the angles between the faces' normals and S's are printed:
  the cube example's surface (meshes/cube_example.obj): the flux jump above;
  the fault example's fault through the box top (x = s(y, z), solver_demo/fault_example.hpp): the
  flux jump above with du/dn = g_N on the top (boundary id 6, zmax) instead of u = g_D;
  the inclusion's sphere (radius 0.3 about (0.5, 0.5, 0.5), with its cells in inside_NAME: the
  mesh's only volume group, every cell of it inside the sphere): -div(beta grad u) = f with
  beta = 10 inside, 1 outside, no flux jump.
With P2 the cells at S are then curved onto S (S_h's vertices and edge midpoints on S).
Otherwise f = 0, g_D = 0 and g_S = 1, and the solution's norms are printed. All print the flux
balance: int_Omega f + int_S g_S against the outflow -int_boundary beta grad u_h . n.

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
                      cg_iterations, problem (cube, fault, inclusion or unit_source), flux_faces (on the
                      sides where the problem gives the flux), manufactured
                      (true or false), curved (true or false), errors {l2, h1} and
                      normal_angle_deg {max, mean} for a manufactured problem, norms {l2,
                      h1_seminorm}, flux {source, outflow, relative_difference}, seconds {read, setup,
                      assembly, solve, postprocess, total} and ranks

Runs under MPI as well: mpirun -np 2 poisson_interface --mesh FILE.msh
)";

double relative_flux_difference(const SolveReport& report) {
  return std::abs(report.outflow - report.source) / std::abs(report.source);
}

// The run as JSON: the numbers the text output prints, at full precision.
void write_report(const std::string& path, const Options& options, const meccano::DealiiInterface& interface,
                  const std::string& problem, unsigned int degree, const SolveReport& report,
                  const std::optional<NormalError>& normals, double read_seconds, double total_seconds,
                  unsigned int ranks) {
  meccano::JsonWriter json;
  json.begin_object().key("mesh").value(options.at("--mesh"));
  json.key("interface").value("interface_" + interface.name);
  json.key("degree").value(degree).key("cells").value(report.cells).key("dofs").value(report.dofs);
  json.key("h").value(report.h).key("cg_iterations").value(report.cg_iterations);
  json.key("problem").value(problem).key("flux_faces").value(report.flux_faces);
  json.key("manufactured").value(normals.has_value());  // the normals are measured against the known S
  json.key("curved").value(report.curved);
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

// Which manufactured problem the file's S belongs to, decided on rank 0 by S's nodes and, for the
// inclusion, by the cells it encloses.
struct Recognised {
  std::string problem = "unit_source";  // or "cube", "fault", "inclusion"
  SurfaceMatch cube, fault, inclusion;
  dealii::types::material_id inside = 0;  // the inclusion's cells
};

// The material id of the cells the inclusion encloses: the mesh's only one besides the domain's, with
// every cell's centroid inside the sphere; none if there is no such material.
std::optional<dealii::types::material_id> inclusion_material(const meccano::DealiiMesh& mesh) {
  std::optional<dealii::types::material_id> inside;
  for (const dealii::CellData<3>& cell : mesh.cells) {
    if (cell.material_id == meccano::domain_tag) continue;
    if (inside && *inside != cell.material_id) return std::nullopt;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const unsigned int v : cell.vertices) centroid += to_eigen(mesh.vertices[v]) / 4.0;
    if ((centroid - inclusion.centre).norm() >= inclusion.radius) return std::nullopt;
    inside = cell.material_id;
  }
  return inside;
}

Recognised recognise(const meccano::DealiiMesh& mesh, const meccano::DealiiInterface& interface) {
  Recognised recognised;
  recognised.cube = match_cube_example_surface(interface);
  recognised.fault = match_fault_example_surface(interface);
  recognised.inclusion = match_surface(interface, project_onto_inclusion);
  if (recognised.cube.matches()) {
    recognised.problem = "cube";
  } else if (recognised.fault.matches()) {
    recognised.problem = "fault";
  } else if (const auto inside = inclusion_material(mesh); recognised.inclusion.matches() && inside) {
    recognised.problem = "inclusion";
    recognised.inside = *inside;
  }
  return recognised;
}

InterfaceProblem problem_named(const std::string& name, dealii::types::material_id inside) {
  if (name == "cube") return manufactured_problem();
  if (name == "fault") return fault_problem();
  if (name == "inclusion") return inclusion_problem(inside);
  return unit_source_problem();
}

// Where the flux is given and where the values, as the solver found the box sides in the mesh.
std::string boundary_conditions(const InterfaceProblem& problem, const SolveReport& report) {
  std::string sides;
  for (const dealii::types::boundary_id id : problem.flux_sides)
    sides += (sides.empty() ? "" : ", ") + std::string(meccano::box_side_name(static_cast<meccano::BoxSide>(id - 1)));
  if (sides.empty()) return "u = g_D on every boundary face";
  if (report.flux_faces == 0) return "u = g_D on every boundary face (the mesh has no faces in " + sides + ")";
  return "flux given on " + sides + " (" + std::to_string(report.flux_faces) +
         " faces), u = g_D on the other boundary faces";
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
  Recognised recognised;
  if (root) {
    mesh = meccano::read_dealii_mesh(options.at("--mesh"));
    interface = &file_interface(mesh, interface_name);
    recognised = recognise(mesh, *interface);
  }
  const double read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto [problem_name, inside] =
      dealii::Utilities::MPI::broadcast(communicator, std::make_pair(recognised.problem, recognised.inside), 0);
  const InterfaceProblem problem = problem_named(problem_name, inside);

  const SolveReport report = solve_interface_problem(communicator, mesh, interface_name, degree, problem, vtu);
  const double total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!root) return;

  const meccano::DealiiInterface& surface = *interface;
  std::vector<TriangleField> fields;
  std::optional<NormalError> normals;
  std::cout << std::setprecision(4) << "mesh        " << options.at("--mesh") << ": " << report.cells
            << " tets, h = " << report.h << " (longest edge); interface_" << surface.name << ": " << surface.triangles()
            << " triangles, area " << interface_area(surface) << '\n';
  if (problem_name == "cube")
    std::cout << "surface     the cube example's (nodes within " << recognised.cube.max_deviation
              << " of its formula, tolerance " << recognised.cube.tolerance << "): the manufactured flux jump\n";
  else if (problem_name == "fault")
    std::cout << "surface     the fault example's (nodes within " << recognised.fault.max_deviation
              << " of its formula, tolerance " << recognised.fault.tolerance
              << "): the manufactured flux jump across a fault through the top\n";
  else if (problem_name == "inclusion")
    std::cout << "surface     the inclusion's sphere (nodes within " << recognised.inclusion.max_deviation
              << " of it, tolerance " << recognised.inclusion.tolerance << "; the cells of material " << inside
              << " inside it): the manufactured coefficient jump\n";
  else
    std::cout << "surface     not the cube example's (nodes up to " << recognised.cube.max_deviation
              << " off its formula, tolerance " << recognised.cube.tolerance << "), the fault example's (up to "
              << recognised.fault.max_deviation << ") nor the inclusion's with its cells: f = 0, g_D = 0, g_S = 1\n";
  if (problem.exact_surface) {
    normals = normal_error(surface, problem.exact_surface->normal);
    fields.emplace_back("normal_angle_deg", normals->per_triangle_deg);
    std::cout << "normals     angle to S's normal: max " << normals->max_deg << " deg, mean " << normals->mean_deg
              << " deg (area-weighted)\n";
  }
  if (report.curved) std::cout << "geometry    the cells at S curved onto S (degree-2 mapping)\n";
  std::cout << "boundary    " << boundary_conditions(problem, report) << '\n';
  std::cout << "system      P" << degree << ", " << report.dofs << " dofs, " << report.interface_faces
            << " faces on S, CG + AMG: " << report.cg_iterations << " iterations\n"
            << std::setprecision(12) << std::scientific;
  if (report.l2_error)
    std::cout << "L2 error    " << *report.l2_error << '\n' << "H1 error    " << *report.h1_error << '\n';
  std::cout << "norms       L2 " << report.l2_norm << ", H1 seminorm " << report.h1_seminorm << '\n'
            << "source      " << report.source << "  (int_Omega f + int_S g_S)\n"
            << "outflow     " << report.outflow << "  (-int_boundary beta grad u_h . n)\n"
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
    write_report(options.at("--report"), options, surface, problem_name, degree, report, normals, read_seconds,
                 total_seconds, dealii::Utilities::MPI::n_mpi_processes(communicator));
}

}  // namespace

int main(int argc, char** argv) {
  return run_program(argc, argv, "poisson_interface", usage, solve,
                     {"--mesh", "--interface", "--degree", "--vtu", "--report"}, {"--mesh"});
}
