// Projection of S_M onto S (paper §4.3) on every test surface: every S_M node lands on S, rim nodes on
// the rim of S, the mesh stays conforming; and the Hausdorff distance between S and the projected S_M
// shrinks as l_r halves.

#include <meccano/cube_meccano.hpp>
#include <meccano/mesh_check.hpp>
#include <meccano/projection.hpp>
#include <meccano/surface_approximation.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace meccano {
namespace {

struct Inserted {
  TetMesh mesh;
  TetRegion region;
  HealingStats healing;
  SurfaceProjection projection;
};

Inserted insert_until_projection(const TriangleSurface& surface, const Box& box, double resolution) {
  Inserted in{make_cube_meccano(box, 0), {}, {}, {}};
  const TriangleBVH tree(surface);
  VolumetricStats stats;
  in.region = approximate_volume(in.mesh, tree, {resolution}, stats);
  in.healing = approximate_surface(in.mesh, in.region, surface, tree, 0);
  in.projection = project_onto_surface(in.mesh, in.region, 0, in.healing.side, surface, tree);
  return in;
}

// The projected S_M as a surface of its own.
TriangleSurface projected_interface(const Inserted& in) {
  TriangleSurface s;
  const InterfaceFaces faces = interface_faces(in.mesh, in.region, 0, in.healing.side);
  std::vector<int> local(in.mesh.points.size(), -1);
  for (const auto& t : faces.triangles) {
    std::array<int, 3> triangle{};
    for (int k = 0; k < 3; ++k) {
      if (local[t[k]] < 0) {
        local[t[k]] = static_cast<int>(s.points.size());
        s.points.push_back(in.mesh.points[t[k]]);
      }
      triangle[k] = local[t[k]];
    }
    s.triangles.push_back(triangle);
  }
  return s;
}

// Distance from x to the rim polyline of a surface.
double distance_to_rim(const TriangleSurface& surface, const Eigen::Vector3d& x) {
  std::vector<std::pair<int, int>> edges;
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) edges.push_back(std::minmax(t[k], t[(k + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      const Eigen::Vector3d a = surface.points[edges[i].first], b = surface.points[edges[i].second];
      const double s = std::clamp((x - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + s * (b - a) - x).norm());
    }
    i = j;
  }
  return best;
}

class ProjectionOn : public ::testing::TestWithParam<testing::NamedSurfaces> {};

TEST_P(ProjectionOn, PutsEveryNodeOnSAndTheRimOnTheRim) {
  const TriangleSurface& surface = GetParam().surfaces.front();
  const Box unit{{0, 0, 0}, {1, 1, 1}};
  for (double resolution : {1.0 / 16, 1.0 / 32}) {
    SCOPED_TRACE("l_r " + std::to_string(resolution));
    const Inserted in = insert_until_projection(surface, unit, resolution);
    const TriangleBVH tree(surface);
    const double tolerance = 1e-12 * unit.diagonal();
    ASSERT_GT(in.projection.stats.nodes, 0);
    for (std::size_t i = 0; i < in.projection.nodes.size(); ++i) {
      const Eigen::Vector3d& x = in.mesh.points[in.projection.nodes[i]];
      ASSERT_LE(std::sqrt(tree.closest_point(x).squared_distance), tolerance) << "node off S";
      if (in.projection.on_rim[i]) {
        ASSERT_LE(distance_to_rim(surface, x), tolerance) << "rim node off the rim of S";
      }
    }
    EXPECT_LE(in.projection.stats.largest_distance_after, tolerance);
    const auto check = verify_mesh(in.mesh, {.physical = false});
    EXPECT_TRUE(check.ok()) << check.summary();
  }
}

INSTANTIATE_TEST_SUITE_P(AllSurfaces, ProjectionOn, ::testing::ValuesIn(testing::named_test_surfaces(24)),
                         [](const ::testing::TestParamInfo<testing::NamedSurfaces>& param) { return param.param.name; });

// Hausdorff distance between S and the projected S_M, approximated on vertices and centroids of both.
double hausdorff(const TriangleSurface& a, const TriangleSurface& b) {
  const TriangleBVH tree_a(a), tree_b(b);
  double worst = 0;
  auto one_way = [&](const TriangleSurface& from, const TriangleBVH& to) {
    for (const auto& t : from.triangles) {
      const Eigen::Vector3d c = (from.points[t[0]] + from.points[t[1]] + from.points[t[2]]) / 3;
      worst = std::max(worst, std::sqrt(to.closest_point(c).squared_distance));
    }
  };
  one_way(a, tree_b);
  one_way(b, tree_a);
  return worst;
}

TEST(Projection, HausdorffDistanceShrinksAsTheResolutionHalves) {
  const TriangleSurface surface = testing::paper_like_patch(96);
  std::vector<double> distances;
  for (double resolution : {1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64}) {
    const Inserted in = insert_until_projection(surface, {{0, 0, 0}, {1, 1, 1}}, resolution);
    distances.push_back(hausdorff(surface, projected_interface(in)));
  }
  for (std::size_t i = 1; i < distances.size(); ++i) {
    const double rate = std::log2(distances[i - 1] / distances[i]);
    EXPECT_GT(rate, 1.0) << "level " << i << ": " << distances[i - 1] << " -> " << distances[i];
  }
}

}  // namespace
}  // namespace meccano
