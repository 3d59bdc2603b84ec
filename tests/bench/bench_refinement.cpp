// Refinement benchmark: uniform Kossaczky refinement of the cube meccano to several sizes, and local
// refinement toward a surface-like band, one core. Prints a Markdown table: seconds (best of the
// repetitions), new tets per second, and bytes per tet (the mesh's arrays, by capacity, and the growth
// of the process's resident memory).
//
// Usage: bench_refinement [--max-level K] [--repeat N]

#include <meccano/mesh/bisection.hpp>
#include <meccano/mesh/cube_meccano.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Resident memory now; large arrays are mmapped and returned to the system when freed, so the growth
// of this figure while a mesh is alive is what that mesh costs.
long resident_kib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

template <class T>
double capacity_bytes(const std::vector<T>& v) {
  return static_cast<double>(v.capacity() * sizeof(T));
}

double mesh_bytes(const meccano::TetMesh& mesh) {
  return capacity_bytes(mesh.points) + capacity_bytes(mesh.grid) + capacity_bytes(mesh.tets) +
         capacity_bytes(mesh.kinds) + capacity_bytes(mesh.neighbours) + capacity_bytes(mesh.face_tags);
}

struct Row {
  std::string what;
  std::int64_t tets = 0;
  std::int64_t new_tets = 0;
  double seconds = std::numeric_limits<double>::infinity();
  double bytes_per_tet = 0;
  double rss_bytes_per_tet = 0;
};

void print(const Row& row) {
  std::printf("| %-44s | %10lld | %10lld | %8.3f | %8.2f | %9.1f | %9.1f |\n", row.what.c_str(),
              static_cast<long long>(row.tets), static_cast<long long>(row.new_tets), row.seconds,
              static_cast<double>(row.new_tets) / row.seconds / 1e6, row.bytes_per_tet, row.rss_bytes_per_tet);
  std::fflush(stdout);
}

// Runs `refine` on the level-3 unit-cube mesh `repeat` times; the timed part excludes building it.
template <class Refine>
Row measure(std::string what, int repeat, Refine refine) {
  Row row;
  row.what = std::move(what);
  for (int r = 0; r < repeat; ++r) {
    meccano::TetMesh mesh = meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 3);
    const auto before = mesh.num_tets();
    const long rss_before = resident_kib();
    const auto start = Clock::now();
    refine(mesh);
    row.seconds = std::min(row.seconds, seconds_since(start));
    row.tets = mesh.num_tets();
    row.new_tets = mesh.num_tets() - before;
    row.bytes_per_tet = mesh_bytes(mesh) / static_cast<double>(mesh.num_tets());
    if (r == 0)
      row.rss_bytes_per_tet =
          static_cast<double>(resident_kib() - rss_before) * 1024.0 / static_cast<double>(mesh.num_tets());
  }
  return row;
}

Row uniform(int level, int repeat) {
  return measure("uniform, unit cube, level 3 -> " + std::to_string(level), repeat,
                 [&](meccano::TetMesh& mesh) { meccano::refine_uniformly(mesh, level - 3); });
}

// Refines every tet whose vertices straddle the surface z = 0.5 + 0.15 sin(2πx) sin(2πy), or lie
// within its longest edge of it, until the longest edge is below `resolution`.
Row band(double resolution, int repeat) {
  char label[96];
  std::snprintf(label, sizeof label, "band toward a curved surface, l_r = 1/%.0f", 1.0 / resolution);
  auto height = [](const Eigen::Vector3d& p) {
    return p.z() - 0.5 - 0.15 * std::sin(2 * std::numbers::pi * p.x()) * std::sin(2 * std::numbers::pi * p.y());
  };
  return measure(label, repeat, [&](meccano::TetMesh& mesh) {
    std::vector<meccano::TetId> marked;
    for (;;) {
      marked.clear();
      for (meccano::TetId t = 0; t < mesh.num_tets(); ++t) {
        const double edge = mesh.longest_edge(t);
        if (edge < resolution) continue;
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const auto& p : mesh.tet_points(t)) {
          lo = std::min(lo, height(p));
          hi = std::max(hi, height(p));
        }
        if (lo <= edge && hi >= -edge) marked.push_back(t);
      }
      if (marked.empty()) break;
      meccano::refine_marked(mesh, marked);
    }
  });
}

}  // namespace

int main(int argc, char** argv) {
  int max_level = 21;
  int repeat = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--max-level")) max_level = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--repeat")) repeat = std::atoi(argv[i + 1]);
  }
  std::printf("| %-44s | %10s | %10s | %8s | %8s | %9s | %9s |\n", "refinement", "tets", "new tets", "seconds",
              "M new/s", "B/tet", "RSS B/tet");
  std::printf("|%s|%s|%s|%s|%s|%s|%s|\n", std::string(46, '-').c_str(), std::string(12, '-').c_str(),
              std::string(12, '-').c_str(), std::string(10, '-').c_str(), std::string(10, '-').c_str(),
              std::string(11, '-').c_str(), std::string(11, '-').c_str());
  for (int level = 15; level <= max_level; ++level) print(uniform(level, repeat));
  for (double resolution : {1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128}) print(band(resolution, repeat));
  return 0;
}
