// The whole insertion (all four steps, SUS over the whole mesh) on every test case of the stage tests:
// each test surface in the unit cube at l_r = 1/16 and 1/32, in a 2x1x1 box at 1/16, in a flat
// 1 x 1.5 x 0.5 box at 1/40, and randomly perturbed at 1/24 (tests/support, surface_cases). Prints one
// Markdown row per case: mesh size, inverted tets before SUS, sweeps (all; until untangled; the first
// towards the equilateral fallback target, if any), the quality after it (both
// measures and the dihedral range) and the seconds; a case whose insertion fails prints its error.
// This is where the robustness and quality tables of doc/results.md come from.
//
// Usage: bench_cases [--grid N]   (surfaces on an N x N grid, default 16, as in the tests)

#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/pipeline.hpp>

#include <test_surfaces.hpp>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  int grid = 16;
  for (int i = 1; i + 1 < argc; i += 2)
    if (!std::strcmp(argv[i], "--grid")) grid = std::atoi(argv[i + 1]);

  std::printf("| %-36s | %8s | %8s | %6s | %9s | %8s | %9s | %9s | %7s | %7s | %8s | %8s | %7s |\n", "case", "tets",
              "inverted", "sweeps", "untangled", "fallback", "mec. min", "mec. mean", "η min", "η mean", "min dih.",
              "max dih.", "seconds");
  std::printf("|--------------------------------------|----------|----------|--------|-----------|----------|----------"
              "-|-----------|---------|"
              "---------|----------|----------|---------|\n");
  int failed = 0, cases = 0;
  for (const meccano::testing::SurfaceCase& c : meccano::testing::surface_cases(grid, true)) {
    ++cases;
    meccano::InsertionOptions options;
    options.resolution = c.resolution;
    try {
      const meccano::InsertionResult r =
          meccano::insert_surfaces(meccano::make_cube_meccano(c.box, 0), c.surfaces, options);
      const meccano::QualitySummary& q = r.quality_after_smoothing;
      const std::string fallback = r.smoothing.fallback_sweep > 0 ? std::to_string(r.smoothing.fallback_sweep) : "-";
      std::printf(
          "| %-36s | %8d | %8lld | %6zu | %9d | %8s | %9.3f | %9.3f | %7.3f | %7.3f | %7.1f° | %7.1f° | %7.2f |\n",
          c.name.c_str(), r.mesh.num_tets(), static_cast<long long>(r.smoothing.inverted_before),
          r.smoothing.sweeps.size(), r.smoothing.untangling_sweeps, fallback.c_str(), q.meccano.min, q.meccano.mean,
          q.equilateral.min, q.equilateral.mean, q.min_dihedral_deg, q.max_dihedral_deg, r.seconds);
    } catch (const std::exception& failure) {
      ++failed;
      std::printf("| %-36s | failed: %s |\n", c.name.c_str(), failure.what());
    }
    std::fflush(stdout);
  }
  std::printf("\n%d of %d cases inserted\n", cases - failed, cases);
  return 0;
}
