// Whole-insertion benchmark (issue 6): meshes/cube_example.obj inserted into the unit-cube meccano by
// insert_surfaces, all four steps, for l_r = 1/32 ... 1/2^K, with SUS over the whole mesh and over a band
// of 3 rings. Prints two Markdown tables, one row per l_r and mode: seconds of each stage and the total,
// then what smoothing did and the quality after it. OpenMP uses all cores.
//
// "checks" is the total minus the four stages: verify_mesh after every stage and the quality summaries
// before and after smoothing, which insert_surfaces always runs. Times are of the repetition with the
// smallest total (the results do not depend on the run). A row whose insertion fails prints the error.
//
// Usage: bench_smoothing [--finest K] [--repeat N] [--surface FILE]
//        (l_r down to 1/2^K, default K = 8; best of N runs, default 1; FILE defaults to
//        meshes/cube_example.obj, relative to the repository root where tests/bench/run.sh runs)

#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/surface/validation.hpp>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <vector>

namespace {

// What a row prints, copied out of an InsertionResult so that its mesh can be freed.
struct Measurement {
  meccano::TetId tets = 0;
  meccano::VertexId nodes = 0;
  double volumetric_seconds = 0, approximation_seconds = 0, projection_seconds = 0, smoothing_seconds = 0;
  double total_seconds = 0;
  meccano::SmoothingStats smoothing;
  meccano::QualitySummary quality_after;
};

struct Row {
  int inverse_resolution = 0;
  meccano::SmoothingMode mode = meccano::SmoothingMode::whole_mesh;
  std::optional<Measurement> best;  // empty when the insertion failed
  std::string error;
};

const char* mode_name(meccano::SmoothingMode mode) {
  return mode == meccano::SmoothingMode::whole_mesh ? "whole" : "band 3";
}

Measurement measure(const meccano::InsertionResult& result) {
  const meccano::SurfaceInsertion& surface = result.surfaces.front();
  return {result.mesh.num_tets(),
          result.mesh.num_vertices(),
          surface.volumetric_seconds,
          surface.approximation_seconds,
          surface.projection_seconds,
          result.smoothing_seconds,
          result.seconds,
          result.smoothing,
          result.quality_after_smoothing};
}

// The repetition with the smallest total; the first failure ends the row.
Row insert(const meccano::TriangleSurface& surface, int inverse_resolution, meccano::SmoothingMode mode, int repeat) {
  Row row{inverse_resolution, mode, std::nullopt, {}};
  meccano::InsertionOptions options;
  options.resolution = 1.0 / inverse_resolution;
  options.smoothing.mode = mode;
  options.smoothing.band_rings = 3;
  for (int r = 0; r < repeat; ++r) {
    try {
      const Measurement run = measure(
          meccano::insert_surfaces(meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&surface, 1}, options));
      if (!row.best || run.total_seconds < row.best->total_seconds) row.best = run;
    } catch (const std::exception& failure) {
      row.best.reset();
      row.error = failure.what();
      return row;
    }
  }
  return row;
}

void print_timings(const std::vector<Row>& rows) {
  std::printf("| %8s | %6s | %10s | %9s | %7s | %7s | %7s | %8s | %7s | %8s |\n", "l_r", "mode", "tets", "nodes",
              "step 1", "step 2", "step 3", "smoothing", "checks", "total s");
  std::printf(
      "|----------|--------|------------|-----------|---------|---------|---------|----------|---------|----------|\n");
  for (const Row& row : rows) {
    if (!row.best) {
      std::printf("| 1/%-6d | %6s | failed: %s |\n", row.inverse_resolution, mode_name(row.mode), row.error.c_str());
      continue;
    }
    const Measurement& m = *row.best;
    const double stages = m.volumetric_seconds + m.approximation_seconds + m.projection_seconds + m.smoothing_seconds;
    std::printf("| 1/%-6d | %6s | %10d | %9d | %7.2f | %7.2f | %7.2f | %8.2f | %7.2f | %8.2f |\n",
                row.inverse_resolution, mode_name(row.mode), m.tets, m.nodes, m.volumetric_seconds,
                m.approximation_seconds, m.projection_seconds, m.smoothing_seconds, m.total_seconds - stages,
                m.total_seconds);
  }
}

void print_smoothing(const std::vector<Row>& rows) {
  std::printf("\n| %8s | %6s | %10s | %10s | %6s | %10s | %10s | %9s | %9s | %9s | %9s | %8s |\n", "l_r", "mode",
              "free nodes", "inverted", "sweeps", "untangling", "s/sweep", "mec. min", "mec. mean", "η min", "η mean",
              "min dih.");
  std::printf(
      "|----------|--------|------------|------------|--------|------------|------------|-----------|-----------|"
      "-----------|-----------|----------|\n");
  for (const Row& row : rows) {
    if (!row.best) continue;
    const meccano::SmoothingStats& s = row.best->smoothing;
    const meccano::QualitySummary& q = row.best->quality_after;
    const auto sweeps = static_cast<int>(s.sweeps.size());
    std::printf("| 1/%-6d | %6s | %10lld | %10lld | %6d | %10d | %10.3f | %9.3f | %9.3f | %9.3f | %9.3f | %7.1f° |\n",
                row.inverse_resolution, mode_name(row.mode),
                static_cast<long long>(s.inner_nodes + s.box_nodes + s.surface_nodes + s.rim_nodes),
                static_cast<long long>(s.inverted_before), sweeps, s.untangling_sweeps,
                sweeps > 0 ? row.best->smoothing_seconds / sweeps : 0.0, q.meccano.min, q.meccano.mean,
                q.equilateral.min, q.equilateral.mean, q.min_dihedral_deg);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int finest = 8;
  int repeat = 1;
  std::string surface_file = "meshes/cube_example.obj";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--finest")) finest = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--repeat")) repeat = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--surface")) surface_file = argv[i + 1];
  }
  meccano::TriangleSurface surface;
  try {
    surface = meccano::read_surface(surface_file);
    surface.name = "patch";
    meccano::validate_surfaces({&surface, 1}, {{0, 0, 0}, {1, 1, 1}});
  } catch (const std::exception& failure) {
    std::fprintf(stderr, "bench_smoothing: %s (run from the repository root or pass --surface)\n", failure.what());
    return 1;
  }
  std::printf("%s: %zu triangles\n\n", surface_file.c_str(), surface.triangles.size());

  std::vector<Row> rows;
  for (int k = 5; k <= finest; ++k)
    for (meccano::SmoothingMode mode : {meccano::SmoothingMode::whole_mesh, meccano::SmoothingMode::band}) {
      rows.push_back(insert(surface, 1 << k, mode, repeat));
      std::fprintf(stderr, "1/%d %s done\n", 1 << k, mode_name(mode));
    }
  print_timings(rows);
  print_smoothing(rows);
  return 0;
}
