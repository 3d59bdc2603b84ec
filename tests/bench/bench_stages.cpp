// Benchmark and measurements of the first two stages. Volumetric approximation (paper §4.1): the cube example's surface (the paper-like patch,
// 96 x 96 grid, 18 432 triangles) inserted into the unit-cube meccano for l_r from 1/16 to 1/256 of the
// box size. Prints a Markdown table: seconds of the stage (best of the repetitions), tets tested for
// intersection per second, refinement passes, final mesh size and V_M size.
//
// A second table measures, for every test surface at l_r = 1/32, what the growth into a ball did and
// how far the boundary nodes of V_M are from S, in units of l_r. A third heals S_M on each and counts
// what every rule did, S_M's size against S, and the time. A fourth projects S_M onto S for the cube
// example at l_r = 1/8 ... 1/64 and gives the Hausdorff distance between S and the projected S_M (on
// vertices and centroids) with its rate per halving, the largest node move and the inverted tets.
//
// Usage: bench_stages [--repeat N] [--finest K]   (l_r down to 1/2^K, default K = 8)

#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/projection.hpp>
#include <meccano/stages/surface_approximation.hpp>
#include <meccano/stages/volumetric_approximation.hpp>

#include <test_surfaces.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

namespace {

// The first table: the volumetric approximation of the cube example for l_r = 1/16 ... 1/2^finest, best of
// `repeat` runs.
void time_volumetric_approximation(const meccano::TriangleBVH& tree, int repeat, int finest) {
  std::printf("| %8s | %6s | %10s | %8s | %8s | %10s | %8s |\n", "l_r", "passes", "tets", "V_M tets", "seconds",
              "tests", "M tests/s");
  std::printf("|----------|--------|------------|----------|----------|------------|----------|\n");
  for (int k = 4; k <= finest; ++k) {
    const double resolution = 1.0 / (1 << k);
    double best = std::numeric_limits<double>::infinity();
    meccano::VolumetricStats stats;
    std::int64_t tets = 0;
    for (int r = 0; r < repeat; ++r) {
      meccano::TetMesh mesh = meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
      stats = {};
      const auto start = std::chrono::steady_clock::now();
      meccano::approximate_volume(mesh, tree, {resolution}, stats);
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      tets = mesh.num_tets();
    }
    std::printf("| 1/%-6d | %6d | %10lld | %8lld | %8.3f | %10lld | %8.2f |\n", 1 << k, stats.refinement_passes,
                static_cast<long long>(tets), static_cast<long long>(stats.tets), best,
                static_cast<long long>(stats.intersection_tests),
                static_cast<double>(stats.intersection_tests) / best / 1e6);
    std::fflush(stdout);
  }
}

// The largest and the mean distance of V_M's boundary nodes to S, in units of l_r.
std::pair<double, double> boundary_distances(const meccano::TetMesh& mesh, const meccano::TetRegion& region,
                                             const meccano::TriangleBVH& tree, double resolution) {
  std::vector<std::uint8_t> on_boundary(mesh.points.size(), 0);
  for (meccano::TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4 && region[t]; ++f) {
      const meccano::TetId across = mesh.neighbours[t][f];
      if (across == meccano::no_tet || !region[across])
        for (int local : meccano::face_vertices[f]) on_boundary[mesh.tets[t][local]] = 1;
    }
  double largest = 0, sum = 0;
  int count = 0;
  for (meccano::VertexId v = 0; v < mesh.num_vertices(); ++v)
    if (on_boundary[v]) {
      const double d = std::sqrt(tree.closest_point(mesh.points[v]).squared_distance) / resolution;
      largest = std::max(largest, d);
      sum += d;
      ++count;
    }
  return {largest, sum / count};
}

// The second table: the growth into a ball on every test surface.
void measure_growth(double resolution) {
  std::printf("\n| %-22s | %8s | %8s | %9s | %8s | %10s | %8s | %8s |\n", "surface (l_r = 1/32)", "tets", "V_M",
              "meet S", "axis", "node stars", "max d/l_r", "mean d/l_r");
  std::printf(
      "|------------------------|----------|----------|-----------|----------|------------|----------|----------|\n");
  for (const auto& named : meccano::testing::named_test_surfaces(24)) {
    meccano::TetMesh mesh = meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
    const meccano::TriangleBVH first(named.surfaces.front());
    meccano::VolumetricStats stats;
    const meccano::TetRegion region = meccano::approximate_volume(mesh, first, {resolution}, stats);
    const auto [largest, mean] = boundary_distances(mesh, region, first, resolution);
    std::printf("| %-22s | %8d | %8lld | %9lld | %8lld | %10lld | %8.2f | %8.2f |\n", named.name.c_str(),
                mesh.num_tets(), static_cast<long long>(stats.tets), static_cast<long long>(stats.tets_intersecting),
                static_cast<long long>(stats.axis_tets), static_cast<long long>(stats.euler_node_stars), largest, mean);
  }
}

template <class Points, class Triangles>
double area_of(const Points& points, const Triangles& triangles) {
  double area = 0;
  for (const auto& t : triangles) area += 0.5 * (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).norm();
  return area;
}

// The third table: S_M healed on every test surface.
void measure_healing(double resolution) {
  std::printf("\n| %-22s | %6s | %6s | %5s | %6s | %5s | %5s | %5s | %6s | %5s | %5s | %5s | %5s | %7s | %6s |\n",
              "S_M (l_r = 1/32)", "faces", "passes", "ext", "corbel", "fill", "left", "2face", "2rim", "div", "chord",
              "cross", "max d", "S_M/S", "ms");
  std::printf("|------------------------|--------|--------|-------|--------|-------|-------|-------|--------|-------|--"
              "-----|-------|-------|---------|--------|\n");
  for (const auto& named : meccano::testing::named_test_surfaces(24)) {
    meccano::TetMesh mesh = meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
    const meccano::TriangleSurface& patch = named.surfaces.front();
    const meccano::TriangleBVH patch_tree(patch);
    meccano::VolumetricStats stats;
    meccano::TetRegion region = meccano::approximate_volume(mesh, patch_tree, {resolution}, stats);
    const auto start = std::chrono::steady_clock::now();
    const meccano::HealingStats h = meccano::approximate_surface(mesh, region, patch, patch_tree, 0);
    const double ms = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() * 1e3;
    const auto faces = meccano::approximation_faces(mesh, region, 0, h.side);
    double largest = 0;
    for (const auto& t : faces.triangles)
      for (meccano::VertexId v : t)
        largest = std::max(largest, std::sqrt(patch_tree.closest_point(mesh.points[v]).squared_distance));
    std::printf("| %-22s | %6lld | %6d | %5lld | %6lld | %5lld | %5lld | %5lld | %6lld | %5lld | %5lld | %5lld | %5.2f "
                "| %7.2f | %6.1f |\n",
                named.name.c_str(), static_cast<long long>(h.faces), h.passes,
                static_cast<long long>(h.extension_faces), static_cast<long long>(h.corbels),
                static_cast<long long>(h.reflex_corners_filled), static_cast<long long>(h.reflex_corners_left),
                static_cast<long long>(h.tets_with_two_faces), static_cast<long long>(h.triangles_with_two_rim_edges),
                static_cast<long long>(h.dividing_edges), static_cast<long long>(h.chord_edges),
                static_cast<long long>(h.cross_surface_edges), largest / resolution,
                area_of(mesh.points, faces.triangles) / area_of(patch.points, patch.triangles), ms);
  }
}

// The Hausdorff distance between two surfaces, measured at the vertices and centroids of each one's
// triangles.
double hausdorff_distance(const meccano::TriangleSurface& a, const meccano::TriangleBVH& a_tree,
                          const meccano::TriangleSurface& b, const meccano::TriangleBVH& b_tree) {
  double hausdorff = 0;
  auto one_way = [&](const meccano::TriangleSurface& from, const meccano::TriangleBVH& to) {
    for (const auto& t : from.triangles) {
      for (int c = 0; c < 3; ++c)
        hausdorff = std::max(hausdorff, std::sqrt(to.closest_point(from.points[t[c]]).squared_distance));
      const Eigen::Vector3d centroid = (from.points[t[0]] + from.points[t[1]] + from.points[t[2]]) / 3;
      hausdorff = std::max(hausdorff, std::sqrt(to.closest_point(centroid).squared_distance));
    }
  };
  one_way(a, b_tree);
  one_way(b, a_tree);
  return hausdorff;
}

// The fourth table: S_M projected onto the cube example for l_r = 1/8 ... 1/64.
void measure_projection(const meccano::TriangleSurface& example, const meccano::TriangleBVH& tree) {
  std::printf("\n| %8s | %8s | %10s | %6s | %12s | %14s | %10s |\n", "l_r", "S_M faces", "Hausdorff", "rate",
              "largest move", "inverted tets", "ms");
  std::printf("|----------|----------|------------|--------|--------------|----------------|------------|\n");
  double previous = 0;
  for (int k = 3; k <= 6; ++k) {
    const double l_r = 1.0 / (1 << k);
    meccano::TetMesh mesh = meccano::make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
    meccano::VolumetricStats stats;
    meccano::TetRegion region = meccano::approximate_volume(mesh, tree, {l_r}, stats);
    const meccano::HealingStats h = meccano::approximate_surface(mesh, region, example, tree, 0);
    const auto start = std::chrono::steady_clock::now();
    const auto projection = meccano::project_onto_surface(mesh, region, 0, h.side, example, tree);
    const double ms = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() * 1e3;
    meccano::TriangleSurface projected;
    projected.points = mesh.points;
    for (const auto& t : meccano::approximation_faces(mesh, region, 0, h.side).triangles)
      projected.triangles.push_back({t[0], t[1], t[2]});
    const meccano::TriangleBVH projected_tree(projected);
    const double hausdorff = hausdorff_distance(example, tree, projected, projected_tree);
    const double rate = previous > 0 ? std::log2(previous / hausdorff) : 0.0;
    std::printf("| 1/%-6d | %8zu | %10.3e | %6s | %12.4f | %14lld | %10.1f |\n", 1 << k, projected.triangles.size(),
                hausdorff, previous > 0 ? std::to_string(rate).substr(0, 4).c_str() : "", projection.stats.largest_move,
                static_cast<long long>(projection.stats.inverted_tets), ms);
    previous = hausdorff;
  }
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  int finest = 8;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--repeat")) repeat = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--finest")) finest = std::atoi(argv[i + 1]);
  }
  const meccano::TriangleSurface surface = meccano::testing::paper_like_patch(96);
  const meccano::TriangleBVH tree(surface);
  time_volumetric_approximation(tree, repeat, finest);
  const double resolution = 1.0 / 32;
  measure_growth(resolution);
  measure_healing(resolution);
  measure_projection(surface, tree);
  return 0;
}
