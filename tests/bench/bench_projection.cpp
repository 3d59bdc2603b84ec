// Projection benchmark (paper §4.3): the cube example's surface (the paper-like patch, cells of l_r / 2)
// inserted into the unit-cube meccano for l_r = 1/64 ... 1/2^K, about 1.8e4 to 1.1e6 S_M triangles (4x per
// halving of l_r: the counts follow the dyadic cube levels, so a larger surface would jump from 7e5 to 3e6).
// Prints a Markdown table per l_r: mesh, S and S_M sizes; seconds of steps 1 and 2; seconds of the
// projection and of its two parameterizations; the largest distance from a moved node to S.
//
// project_onto_surface does not report its parts, so the parameterizations (corners and Floater solve) of S
// and of S_M are timed by repeating those calls before it, on the same disks: S_M as built, where the
// projection uses its nodes pulled towards S (same system, other weights). "rest" is the projection minus
// both: closest points for the pull and the distance check, point location and move, the inverted-tet count.
//
// Usage: bench_projection [--finest K]   (l_r down to 1/2^K, default K = 9; K = 8 stops near 3e5)

#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/projection.hpp>
#include <meccano/stages/surface_approximation.hpp>
#include <meccano/stages/volumetric_approximation.hpp>

#include <test_surfaces.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The cube example's surface (meshes/cube_example.obj is the same patch on a 96 x 96 grid) with cells of
// l_r / 2, so that S is finer than S_M at every row.
meccano::TriangleSurface cube_example(double resolution) {
  return meccano::testing::paper_like_patch(static_cast<int>(std::ceil(2.0 * 0.6 / resolution)));
}

double parameterization_seconds(meccano::DiskView disk) {
  const auto start = Clock::now();
  meccano::parameterize_to_square(disk, meccano::corners_by_arc_length(disk));
  return seconds_since(start);
}

}  // namespace

int main(int argc, char** argv) {
  int finest = 9;
  for (int i = 1; i + 1 < argc; i += 2)
    if (!std::strcmp(argv[i], "--finest")) finest = std::atoi(argv[i + 1]);

  std::printf("| %8s | %10s | %9s | %9s | %9s | %7s | %7s | %8s | %8s | %7s | %9s | %10s |\n", "l_r", "mesh tets",
              "S tri", "S_M tri", "S_M nodes", "step 1", "step 2", "param S", "param S_M", "rest", "projection",
              "max dist");
  std::printf("|----------|------------|-----------|-----------|-----------|---------|---------|----------|----------|"
              "---------|-----------|------------|\n");
  for (int k = 6; k <= finest; ++k) {
    const double resolution = 1.0 / (1 << k);
    const meccano::TriangleSurface surface = cube_example(resolution);
    // The stages are called one by one: insert_surfaces would also verify the whole mesh after each.
    meccano::TetMesh mesh = meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
    const meccano::TriangleBVH tree(surface);
    auto start = Clock::now();
    meccano::VolumetricStats volumetric_stats;
    meccano::TetRegion region = meccano::approximate_volume(mesh, tree, {resolution}, volumetric_stats);
    const double volumetric_seconds = seconds_since(start);
    start = Clock::now();
    const int side = meccano::approximate_surface(mesh, region, surface, tree, 0).side;
    const double approximation_seconds = seconds_since(start);

    const meccano::ApproximationFaces faces = meccano::approximation_faces(mesh, region, 0, side);
    const std::vector<std::array<int, 3>> triangles(faces.triangles.begin(), faces.triangles.end());
    const double surface_parameterization_seconds = parameterization_seconds(surface);
    const double approximation_parameterization_seconds = parameterization_seconds({mesh.points, triangles});
    start = Clock::now();
    const meccano::SurfaceProjection projection = meccano::project_onto_surface(mesh, region, 0, side, surface, tree);
    const double projection_seconds = seconds_since(start);

    std::printf("| 1/%-6d | %10d | %9zu | %9zu | %9lld | %7.2f | %7.2f | %8.2f | %8.2f | %7.2f | %9.2f | %10.1e |\n",
                1 << k, mesh.num_tets(), surface.triangles.size(), triangles.size(),
                static_cast<long long>(projection.stats.nodes), volumetric_seconds, approximation_seconds,
                surface_parameterization_seconds, approximation_parameterization_seconds,
                projection_seconds - surface_parameterization_seconds - approximation_parameterization_seconds,
                projection_seconds, projection.stats.largest_distance_after);
    std::fflush(stdout);
  }
  return 0;
}
