// Stress test: random smooth open surfaces through the whole pipeline (not a unit test; run by hand,
// results in doc/robustness.md).
//
// Each case puts 1-3 random height fields in the unit cube, each over a disk or a rectangle in a random
// local frame (random centre, size, orientation, quadratic curvature and a sine bump), triangulated
// finer than the mesh. The set goes through validate_surfaces (it may intersect itself or touch the
// box: a rejection with a reason), then insert_surfaces at a random l_r in [1/40, 1/16]. An accepted
// result must be valid: verify_mesh clean, no inverted tet, every interface node on its surface
// (within 1e-9 of the box diagonal), and every S_M a disk. A valid mesh for which the pipeline had to
// refine some surface beyond the l_r asked (InsertionOptions::finer_retries) is counted apart. Output:
// one line per case, then a Markdown table of outcomes and reasons.
//
// Usage: stress_surfaces [--seed S] [--cases K] [--first I] [--threads T] [--dump DIR]
// Case i depends only on (S, i): `--first i --cases 1` reruns it alone; --dump writes each case's surfaces
// to DIR/case<i>_<name>.obj with the meccano-immerse command that inserts them, to reproduce it there.
#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/io/atomic_file.hpp>
#include <meccano/mesh/box.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/stages/surface_approximation.hpp>
#include <meccano/surface/validation.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <numbers>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using meccano::TriangleSurface;

struct Options {
  std::uint64_t seed = 1;
  int cases = 100;
  int first = 0;
  int threads = 0;
  std::string dump_directory;  // empty: no dump
};

Options parse_options(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) {
      std::cerr << "stress_surfaces: " << arg << " needs a value\n";
      std::exit(2);
    }
    const std::string value = argv[++i];
    if (arg == "--seed") options.seed = std::stoull(value);
    else if (arg == "--cases") options.cases = std::stoi(value);
    else if (arg == "--first") options.first = std::stoi(value);
    else if (arg == "--threads") options.threads = std::stoi(value);
    else if (arg == "--dump") options.dump_directory = value;
    else {
      std::cerr << "stress_surfaces: unknown option " << arg << " (--seed, --cases, --first, --threads, --dump)\n";
      std::exit(2);
    }
  }
  return options;
}

// The shape of one surface in its local frame (u, v, height), lengths relative to its size R.
struct HeightField {
  bool disk = true;
  double size = 0.2;                    // radius, or half-width along u
  double aspect = 1.0;                  // rectangle half-width along v, over `size`
  double a_uu = 0, a_vv = 0, a_uv = 0;  // quadratic curvature terms
  double bump = 0, frequency = 1, phase_u = 0, phase_v = 0;

  double height(double u, double v) const {
    const double s = u / size;
    const double t = v / size;
    return size * (a_uu * s * s + a_vv * t * t + a_uv * s * t +
                   bump * std::sin(std::numbers::pi * frequency * s + phase_u) *
                       std::sin(std::numbers::pi * frequency * t + phase_v));
  }
};

// Planar triangulations of the parameter domain, counter-clockwise (normals towards +height).
struct PlanarMesh {
  std::vector<Eigen::Vector2d> points;
  std::vector<std::array<int, 3>> triangles;
};

// Concentric rings: ring i has 6 i points; each of the 6 sectors between rings i-1 and i holds 2 i - 1
// triangles, so the triangles stay close to equilateral.
PlanarMesh disk_mesh(double radius, int rings) {
  PlanarMesh mesh;
  mesh.points.emplace_back(0.0, 0.0);
  const auto ring_start = [](int i) { return i == 0 ? 0 : 1 + 3 * i * (i - 1); };
  const auto on_ring = [&](int i, int j) { return i == 0 ? 0 : ring_start(i) + j % (6 * i); };
  for (int i = 1; i <= rings; ++i)
    for (int j = 0; j < 6 * i; ++j) {
      const double angle = 2.0 * std::numbers::pi * j / (6 * i);
      mesh.points.emplace_back(radius * i / rings * std::cos(angle), radius * i / rings * std::sin(angle));
    }
  for (int i = 1; i <= rings; ++i)
    for (int sector = 0; sector < 6; ++sector)
      for (int j = 0; j < i; ++j) {
        const int inner = sector * (i - 1) + j;
        const int outer = sector * i + j;
        mesh.triangles.push_back({on_ring(i, outer), on_ring(i, outer + 1), on_ring(i - 1, inner)});
        if (j + 1 < i)
          mesh.triangles.push_back({on_ring(i - 1, inner), on_ring(i, outer + 1), on_ring(i - 1, inner + 1)});
      }
  return mesh;
}

PlanarMesh rectangle_mesh(double half_u, double half_v, int cells_u, int cells_v) {
  PlanarMesh mesh;
  for (int j = 0; j <= cells_v; ++j)
    for (int i = 0; i <= cells_u; ++i)
      mesh.points.emplace_back(half_u * (2.0 * i / cells_u - 1.0), half_v * (2.0 * j / cells_v - 1.0));
  const auto index = [cells_u](int i, int j) { return j * (cells_u + 1) + i; };
  for (int j = 0; j < cells_v; ++j)
    for (int i = 0; i < cells_u; ++i) {
      mesh.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      mesh.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  return mesh;
}

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// A surface whose triangles are about `edge` long (at most 40 per radius: enough for the projection).
TriangleSurface random_surface(std::mt19937_64& rng, double edge, const std::string& name) {
  HeightField field;
  field.disk = uniform(rng, 0, 1) < 0.5;
  field.size = uniform(rng, 0.08, 0.3);
  field.aspect = field.disk ? 1.0 : uniform(rng, 0.4, 1.0);
  const double curvature = uniform(rng, 0.0, 0.6);
  field.a_uu = uniform(rng, -curvature, curvature);
  field.a_vv = uniform(rng, -curvature, curvature);
  field.a_uv = uniform(rng, -curvature, curvature);
  field.bump = uniform(rng, 0.0, 0.15);
  field.frequency = uniform(rng, 0.5, 2.0);
  field.phase_u = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  field.phase_v = uniform(rng, 0.0, 2.0 * std::numbers::pi);

  const Eigen::Vector3d centre(uniform(rng, 0.3, 0.7), uniform(rng, 0.3, 0.7), uniform(rng, 0.3, 0.7));
  std::normal_distribution<double> normal;  // a normalised Gaussian 4-vector is a uniform rotation
  const Eigen::Matrix3d frame =
      Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();

  const int divisions = std::clamp(static_cast<int>(std::ceil(field.size / edge)), 4, 40);
  const PlanarMesh planar = field.disk
                                ? disk_mesh(field.size, divisions)
                                : rectangle_mesh(field.size, field.size * field.aspect, divisions,
                                                 std::max(2, static_cast<int>(std::ceil(divisions * field.aspect))));
  TriangleSurface surface;
  surface.name = name;
  for (const Eigen::Vector2d& q : planar.points)
    surface.points.push_back(centre + frame * Eigen::Vector3d(q.x(), q.y(), field.height(q.x(), q.y())));
  surface.triangles = planar.triangles;
  return surface;
}

// A message without the surface names, numbers and parenthesised details, so that equal defects count
// together: "s2: vertex 17 (0.98, ...) is outside the box ..." -> "S: vertex N is outside the box ...".
std::string reason_of(const std::string& message) {
  std::string reason = std::regex_replace(message, std::regex(R"(\bs[123]\b)"), "S");
  reason = std::regex_replace(reason, std::regex(R"(\([^()]*\))"), "");
  reason = std::regex_replace(reason, std::regex(R"(-?[0-9]+(\.[0-9]+)?(e[-+]?[0-9]+)?)"), "N");
  reason = std::regex_replace(reason, std::regex(R"(\s+)"), " ");
  reason = std::regex_replace(reason, std::regex(R"(^ | $)"), "");
  if (reason.size() > 110) reason = reason.substr(0, 107) + "...";
  return reason;
}

// Empty when the result meets every invariant; otherwise what is wrong.
std::string defects_of(const meccano::InsertionResult& result, const std::vector<TriangleSurface>& surfaces) {
  std::ostringstream out;
  const meccano::MeshInvariantReport check = meccano::verify_mesh(result.mesh);
  if (!check.ok()) out << "verify_mesh: " << check.summary() << "; ";
  if (check.inverted_physical != 0) out << check.inverted_physical << " inverted tets; ";
  const double tolerance = 1e-9 * std::sqrt(3.0);  // the unit cube's diagonal
  const std::vector<meccano::SurfaceInterface> interfaces = meccano::surface_interfaces(result);
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const meccano::TriangleBVH bvh(surfaces[s]);
    double worst = 0.0;
    for (const meccano::InterfaceFace& face : interfaces[s].faces)
      for (const meccano::VertexId v : face.vertices)
        worst = std::max(
            worst, std::sqrt(bvh.closest_point(result.mesh.points[static_cast<std::size_t>(v)]).squared_distance));
    if (worst > tolerance) out << surfaces[s].name << ": an interface node is " << worst << " from S; ";
    const meccano::SurfaceApproximationCheck disk =
        meccano::check_surface_approximation(result.mesh, result.surfaces[s].volumetric, static_cast<int>(s));
    if (!disk.is_disk()) out << surfaces[s].name << ": S_M is not a disk (" << disk.describe() << "); ";
  }
  return out.str();
}

// The surfaces inserted at a finer l_r than `asked`, with theirs.
std::string finer_resolutions(const meccano::InsertionResult& result, double asked) {
  std::ostringstream out;
  for (const auto& inserted : result.surfaces)
    if (inserted.resolution < asked)
      out << inserted.name << " at l_r = 1/" << std::lround(1.0 / inserted.resolution) << ' ';
  return out.str();
}

// Writes the case's surfaces as OBJ files and prints the meccano-immerse command that inserts them.
// ", 73712 tets, 16 sweeps, fallback at sweep 21, 12 band tets, side retry": what an insertion cost.
std::string cost_of(const meccano::InsertionResult& result) {
  std::ostringstream out;
  out << ", " << result.mesh.num_tets() << " tets, " << result.smoothing.sweeps.size() << " sweeps";
  if (result.smoothing.fallback_sweep > 0) out << ", fallback at sweep " << result.smoothing.fallback_sweep;
  std::int64_t band = 0;
  for (const auto& inserted : result.surfaces) band += inserted.volumetric_stats.band_tets;
  if (band > 0) out << ", " << band << " band tets";
  if (!result.side_retry.empty()) out << ", side retry";
  return out.str();
}

void dump_case(const std::string& directory, int c, const std::vector<TriangleSurface>& surfaces, double resolution) {
  std::ostringstream command;
  command << std::setprecision(17) << "meccano-immerse --box 0,0,0,1,1,1 --resolution " << resolution;
  for (const TriangleSurface& surface : surfaces) {
    const std::string path = directory + "/case" + std::to_string(c) + "_" + surface.name + ".obj";
    meccano::write_file_atomically(path, [&](std::ostream& out) {
      out << std::setprecision(17);
      for (const Eigen::Vector3d& p : surface.points) out << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
      for (const auto& t : surface.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    });
    command << " --surface " << path << ':' << surface.name;
  }
  std::cout << "case " << c << ": " << command.str() << " --output case" << c << ".msh" << std::endl;
}

std::string one_decimal(double value) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(1) << value;
  return out.str();
}

enum class Outcome { accepted_ok, accepted_ok_finer, accepted_invalid, rejected, failed };
const char* outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::accepted_ok: return "accepted, valid mesh";
    case Outcome::accepted_ok_finer: return "accepted, valid mesh at a finer l_r";
    case Outcome::accepted_invalid: return "accepted, INVALID mesh";
    case Outcome::rejected: return "rejected by validation";
    case Outcome::failed: return "failed by the method";
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse_options(argc, argv);
  if (!options.dump_directory.empty()) {
    std::error_code error;
    std::filesystem::create_directories(options.dump_directory, error);
    if (error) {
      std::cerr << "stress_surfaces: cannot create " << options.dump_directory << ": " << error.message() << '\n';
      return 2;
    }
  }
  const meccano::Box box{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
  std::map<std::pair<Outcome, std::string>, int> counts;  // (outcome, reason) -> cases
  int accepted_cases = 0;
  double accepted_seconds = 0.0;

  for (int c = options.first; c < options.first + options.cases; ++c) {
    std::mt19937_64 rng(options.seed * 1000003 + static_cast<std::uint64_t>(c));
    const double resolution = 1.0 / uniform(rng, 16.0, 40.0);
    const int surface_count = 1 + static_cast<int>(rng() % 3);
    std::vector<TriangleSurface> surfaces;
    for (int s = 0; s < surface_count; ++s)
      surfaces.push_back(random_surface(rng, 0.5 * resolution, "s" + std::to_string(s + 1)));
    if (!options.dump_directory.empty()) dump_case(options.dump_directory, c, surfaces, resolution);

    Outcome outcome = Outcome::accepted_ok;
    std::string detail;
    double seconds = 0.0;
    std::string cost;  // of an insertion that returned: tets, sweeps, and the rescues it needed
    try {
      meccano::validate_surfaces(surfaces, box);
    } catch (const meccano::InputError& error) {
      outcome = Outcome::rejected;
      detail = error.what();
    }
    if (outcome != Outcome::rejected) {
      meccano::InsertionOptions insertion;
      insertion.resolution = resolution;
      insertion.threads = options.threads;
      const auto start = std::chrono::steady_clock::now();
      try {
        const meccano::InsertionResult result =
            meccano::insert_surfaces(meccano::make_cube_meccano(box, 0), surfaces, insertion);
        detail = defects_of(result, surfaces);
        cost = cost_of(result);
        if (!detail.empty()) {
          outcome = Outcome::accepted_invalid;
        } else if (!result.finer_retries.empty()) {
          outcome = Outcome::accepted_ok_finer;
          detail = finer_resolutions(result, resolution) + "after: " + result.finer_retries.front();
        }
      } catch (const std::exception& error) {  // MeshingError, or anything the method should not throw
        outcome = Outcome::failed;
        detail = error.what();
      }
      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      ++accepted_cases;
      accepted_seconds += seconds;
    }
    ++counts[{outcome, outcome == Outcome::accepted_ok ? std::string() : reason_of(detail)}];
    std::cout << "case " << c << ": " << surface_count << " surface(s), l_r = 1/" << std::lround(1.0 / resolution)
              << ", " << outcome_name(outcome);
    if (outcome != Outcome::rejected) std::cout << " (" << one_decimal(seconds) << " s" << cost << ")";
    if (!detail.empty()) std::cout << ": " << detail;
    std::cout << std::endl;
  }

  std::cout << "\nseed " << options.seed << ", cases " << options.first << ".." << options.first + options.cases - 1
            << ", " << accepted_cases << " accepted by validation, " << accepted_seconds << " s in insert_surfaces\n\n";
  std::cout << "| outcome | reason | cases | share |\n|---|---|---:|---:|\n";
  for (const auto& [key, count] : counts)
    std::cout << "| " << outcome_name(key.first) << " | " << (key.second.empty() ? "-" : key.second) << " | " << count
              << " | " << one_decimal(100.0 * count / options.cases) << " % |\n";
  const bool any_invalid =
      std::ranges::any_of(counts, [](const auto& entry) { return entry.first.first == Outcome::accepted_invalid; });
  return any_invalid ? 1 : 0;
}
