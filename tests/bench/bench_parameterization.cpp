// Floater parameterization benchmark (paper §4.3): the paper-like patch with about 1e4, 1e5 and 1e6
// triangles, both weight kinds. Prints a Markdown table: seconds to choose the corners and to
// parameterize (connectivity, weights, sparse LU factorisation and solve, checks), seconds to build the
// point-location grid, and point-location throughput on one thread, for uniformly random points without
// a hint and for a random walk of small steps (a quarter of a triangle's size, as smoothing moves a node),
// each query hinted with the previous answer.
//
// Usage: bench_parameterization [--largest N] [--queries Q]
//        (default: surfaces up to 1e6 triangles, 1e6 queries of each kind)

#include <meccano/stages/parameterization.hpp>

#include <test_surfaces.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double uniform(std::mt19937_64& generator) { return double(generator() >> 11) * 0x1.0p-53; }

}  // namespace

int main(int argc, char** argv) {
  long largest = 1000000;
  long queries = 1000000;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--largest")) largest = std::atol(argv[i + 1]);
    if (!std::strcmp(argv[i], "--queries")) queries = std::atol(argv[i + 1]);
  }
  std::printf("| %9s | %16s | %9s | %13s | %8s | %14s | %14s |\n", "triangles", "weights", "corners s",
              "parameterize s", "grid s", "random M q/s", "walking M q/s");
  std::printf("|-----------|------------------|-----------|---------------|----------|----------------|"
              "----------------|\n");
  for (long target : {10000L, 100000L, 1000000L}) {
    if (target > largest) break;
    const int n = static_cast<int>(std::lround(std::sqrt(static_cast<double>(target) / 2.0)));
    const meccano::TriangleSurface surface = meccano::testing::paper_like_patch(n);
    for (meccano::FloaterWeights weights :
         {meccano::FloaterWeights::mean_value, meccano::FloaterWeights::shape_preserving}) {
      auto start = Clock::now();
      const std::array<int, 4> corners = meccano::corners_by_arc_length(surface);
      const double corner_seconds = seconds_since(start);
      start = Clock::now();
      meccano::SquareParameterization parameterization = meccano::parameterize_to_square(surface, corners, weights);
      const double parameterize_seconds = seconds_since(start);
      start = Clock::now();
      const meccano::ParametricSurface phi(surface, std::move(parameterization));
      const double grid_seconds = seconds_since(start);

      std::mt19937_64 generator(1);
      double checksum = 0.0;  // keeps the queries from being optimised away
      start = Clock::now();
      for (long q = 0; q < queries; ++q) {
        const Eigen::Vector2d uv(uniform(generator), uniform(generator));
        checksum += phi.evaluate(phi.locate(uv)).z();
      }
      const double random_rate = double(queries) / seconds_since(start) / 1e6;

      const double step = 0.25 / n;
      Eigen::Vector2d uv(0.5, 0.5);
      int hint = phi.locate(uv).triangle;
      start = Clock::now();
      for (long q = 0; q < queries; ++q) {
        const double angle = 2.0 * std::numbers::pi * uniform(generator);
        uv += step * Eigen::Vector2d(std::cos(angle), std::sin(angle));
        uv = uv.cwiseMax(0.0).cwiseMin(1.0);
        const meccano::ParametricSurface::Location location = phi.locate(uv, hint);
        hint = location.triangle;
        checksum += phi.evaluate(location).z();
      }
      const double walking_rate = double(queries) / seconds_since(start) / 1e6;

      std::printf("| %9zu | %16s | %9.3f | %13.3f | %8.3f | %14.2f | %14.2f |\n", surface.triangles.size(),
                  weights == meccano::FloaterWeights::mean_value ? "mean value" : "shape preserving", corner_seconds,
                  parameterize_seconds, grid_seconds, random_rate, walking_rate);
      std::fflush(stdout);
      if (!std::isfinite(checksum)) return 1;
    }
  }
  return 0;
}
