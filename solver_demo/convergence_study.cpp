// convergence_study: a manufactured problem (the cube example's flux jump, the fault example's flux jump
// with a flux condition where the fault reaches the box top, or the inclusion's coefficient jump) on
// meshes made by the module, in this process, one per level with h halving, and the errors per
// level as CSV.
// Exit status: 0 success, 1 failure (meshing failed, cannot write), 2 usage error.

#include "command_line.hpp"
#include "cube_example.hpp"
#include "interface_poisson.hpp"

#include <meccano/io/atomic_file.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/validation.hpp>

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <numbers>
#include <string>

namespace {

using namespace solver_demo;

constexpr const char* usage =
    R"(Usage: convergence_study --levels N --degree 1|2 --csv FILE.csv [--problem cube|fault|inclusion]
                         [--geometry curved|flat]

Solves a manufactured problem of doc/solver.md on N meshes made by the module in this process:
  cube       a flux jump across the cube example's surface S (an open disk),
  fault      a flux jump across a curved fault S that leaves through the box top, where the flux is
             given (the ground), u on the other sides; S is clipped by the box,
  inclusion  a coefficient jump (10 inside, 1 outside) across a sphere S of radius 0.3 about the
             box centre, the cells inside it told apart by their material id (inside_sphere);
and writes one CSV row per level:
  h,tets,dofs,l2_error,h1_error,normal_error_deg,seconds
h is the longest edge, the errors are ||u - u_h|| in L2 and in the H1 seminorm, normal_error_deg the
largest angle between a face of S_h and S's normal, seconds the level's wall time (meshing and solving).

Level l (0-based) meshes the unit cube's meccano at uniform level K = 9 + 3 l (6 * 2^K tets, longest
edge sqrt(3) 2^(-K/3)) and inserts S at l_r = a quarter of that edge, so that the mesh size halves
from one level to the next all over the mesh (near S, projection and smoothing stretch the longest
edges to about 1.1 times the far field's). S is triangulated from its formula with edges of at most
about l_r / 2, so that its own sag stays below that of the faces of S_h. With P2, the cells at S are
curved onto S (S_h's vertices on S, a degree-2 mapping with S_h's edge midpoints on S).

Options:
  --levels N      1 to 5 (the fourth has 2.6 million tets, the fifth would have about 15 million)
                  (required)
  --degree 1|2    polynomial degree (required)
  --csv FILE.csv  the table; rewritten after every level (required)
  --problem NAME  cube (default), fault or inclusion
  --geometry G    curved (default): with P2, the cells at S curved onto S; flat: S_h's faces flat
)";

// A manufactured problem with its surface S, triangulated from its formula with edges of about l_r / 2
// at most: the n x n grid of the cube example's Q = [0.2, 0.8]² with 0.6 / n <= l_r / 2, the fault's grid
// with n cells across its width 0.6; the sphere's octahedral triangulation with n cells per octant edge,
// whose edges are at most about π R / (2n).
struct Example {
  std::string title;
  InterfaceProblem problem;
  std::function<meccano::TriangleSurface(double resolution)> surface;
};

Example example(const std::string& name) {
  if (name == "cube")
    return {"the cube example", manufactured_problem(), [](double resolution) {
              return triangulate_cube_example(static_cast<int>(std::ceil(2.0 * 0.6 / resolution)));
            }};
  if (name == "fault")
    return {"the fault example", fault_problem(), [](double resolution) {
              return triangulate_fault_example(static_cast<int>(std::ceil(2.0 * 0.6 / resolution)));
            }};
  if (name == "inclusion")
    return {"the inclusion", inclusion_problem(),
            [](double resolution) {
      return triangulate_inclusion(static_cast<int>(std::ceil(std::numbers::pi * inclusion.radius / resolution)));
            }};
  throw UsageError("--problem " + name + ": cube, fault or inclusion");
}

struct Level {
  int base_level;     // K
  double resolution;  // l_r
};

Level level_parameters(int level) {
  const int base_level = 9 + 3 * level;
  return {base_level, 0.25 * std::sqrt(3.0) * std::pow(2.0, -base_level / 3.0)};
}

meccano::DealiiMesh module_mesh(const Level& level, const meccano::TriangleSurface& surface, double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  const meccano::Box box{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
  // The part of S inside the box (the fault's triangulation runs above the top), as the CLI inserts it.
  const std::vector<meccano::TriangleSurface> surfaces = meccano::clip_to_box(surface, box);
  meccano::validate_surfaces(surfaces, box);
  meccano::InsertionOptions options;
  options.resolution = level.resolution;
  const meccano::InsertionResult result =
      meccano::insert_surfaces(meccano::make_cube_meccano(box, level.base_level), surfaces, options);
  meccano::DealiiMesh mesh = meccano::dealii_mesh(result);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mesh;
}

struct Row {
  double h;
  unsigned long long tets, dofs;
  double l2_error, h1_error, normal_error_deg, seconds;
};

void write_csv(const std::string& path, const std::vector<Row>& rows) {
  meccano::write_file_atomically(path, [&](std::ostream& out) {
    out << "h,tets,dofs,l2_error,h1_error,normal_error_deg,seconds\n" << std::setprecision(10);
    for (const Row& r : rows)
      out << r.h << ',' << r.tets << ',' << r.dofs << ',' << r.l2_error << ',' << r.h1_error << ','
          << r.normal_error_deg << ',' << r.seconds << '\n';
  });
}

// The observed order between two levels, as text ("" on the first level).
std::string rate_text(double error, double h, const Row* previous, double Row::*column) {
  if (!previous) return "";
  char text[16];
  std::snprintf(text, sizeof text, "%.2f", std::log(previous->*column / error) / std::log(previous->h / h));
  return text;
}

void study(MPI_Comm communicator, const Options& options) {
  const int levels = meccano::tools::parse_positive_integer("--levels", options.at("--levels"));
  if (levels > 5) throw UsageError("--levels " + options.at("--levels") + ": at most 5");
  const unsigned int degree = parse_degree(options.at("--degree"));
  const bool root = dealii::Utilities::MPI::this_mpi_process(communicator) == 0;
  const Example chosen = example(options.count("--problem") ? options.at("--problem") : "cube");
  const std::string geometry = options.count("--geometry") ? options.at("--geometry") : "curved";
  if (geometry != "curved" && geometry != "flat") throw UsageError("--geometry " + geometry + ": curved or flat");
  InterfaceProblem solved = chosen.problem;
  if (geometry == "flat") solved.exact_surface.reset();  // the solver curves the cells onto a known S only

  std::vector<Row> rows;
  if (root)
    std::printf("P%u on %s%s, %d levels (S tris: S's input triangles; normal: max/mean angle in degrees; times"
                " in seconds)\n K    l_r  S tris      h     tets     dofs its  L2 error  rate  H1 error  rate normal"
                "     mesh  setup assemb  solve   eval\n",
                degree, chosen.title.c_str(), degree > 1 && solved.exact_surface ? " (cells at S curved onto S)" : "",
                levels);
  for (int l = 0; l < levels; ++l) {
    const auto start = std::chrono::steady_clock::now();
    const Level level = level_parameters(l);
    meccano::DealiiMesh mesh;  // rank 0 meshes; the solver distributes
    double mesh_seconds = 0.0;
    NormalError normals;
    std::size_t surface_triangles = 0;
    if (root) {
      const meccano::TriangleSurface surface = chosen.surface(level.resolution);
      surface_triangles = surface.triangles.size();
      mesh = module_mesh(level, surface, mesh_seconds);
      normals = normal_error(mesh.interface(), chosen.problem.exact_surface->normal);
    }
    const SolveReport report = solve_interface_problem(communicator, mesh, "", degree, solved);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!root) continue;

    const Row* previous = rows.empty() ? nullptr : &rows.back();
    const Row row{report.h, report.cells, report.dofs, *report.l2_error, *report.h1_error, normals.max_deg, seconds};
    std::printf("%2d %6.4f %6zu %6.4f %8llu %8llu %3u %.3e %5s %.3e %5s %4.1f/%3.1f %6.1f %6.1f %6.1f %6.1f %6.1f\n",
                level.base_level, level.resolution, surface_triangles, row.h, row.tets, row.dofs, report.cg_iterations,
                row.l2_error, rate_text(row.l2_error, row.h, previous, &Row::l2_error).c_str(), row.h1_error,
                rate_text(row.h1_error, row.h, previous, &Row::h1_error).c_str(), normals.max_deg, normals.mean_deg,
                mesh_seconds, report.setup_seconds, report.assembly_seconds, report.solve_seconds,
                report.postprocess_seconds);
    std::fflush(stdout);
    rows.push_back(row);
    write_csv(options.at("--csv"), rows);
  }
}

}  // namespace

int main(int argc, char** argv) {
  return run_program(argc, argv, "convergence_study", usage, study,
                     {"--levels", "--degree", "--csv", "--problem", "--geometry"}, {"--levels", "--degree", "--csv"});
}
