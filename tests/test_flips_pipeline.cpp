// Flips through the pipeline (`Improvement::topology`, improvement.hpp), on the irregular S_M of the
// perturbed test surfaces at a threshold above the default, for hundreds of flips: the interface keeps its
// orientation, S_M's triangle list stays the tagged faces, its nodes stay on S, no tet lies on one
// surface, and the mesh is the same on 1 and 2 threads. About a minute: label `long`.

#include <meccano/cube_meccano.hpp>
#include <meccano/geometry.hpp>
#include <meccano/improvement.hpp>
#include <meccano/mesh_check.hpp>
#include <meccano/pipeline.hpp>
#include <meccano/quality.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace meccano {
namespace {

// Smoothing and flips alternate; the interface keeps its orientation (every face's normal on the side of
// S's), S_M's triangle list is the tagged faces, and no tet lies on one surface.
TEST(Flips, ThroughThePipelineKeepTheInterfaceOnSAndOriented) {
  std::int64_t surface_edge_flips = 0;
  for (const auto& c : testing::surface_cases(16, true)) {
    if (!c.name.ends_with("_perturbed_lr24")) continue;  // irregular S_M: the most flips
    SCOPED_TRACE(c.name);
    InsertionOptions options;
    options.resolution = c.resolution;
    options.improve = Improvement::smooth;
    const InsertionResult smoothed = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
    options.improve = Improvement::topology;
    options.improvement.threshold = 0.5;  // more flips than the default gives on smooth surfaces
    const InsertionResult flipped = insert_surfaces(make_cube_meccano(c.box, 0), c.surfaces, options);
    ASSERT_TRUE(flipped.improvement.has_value());
    surface_edge_flips += flipped.improvement->flips.surface_edge_flips;
    const MeshCheckReport check = verify_mesh(flipped.mesh, {.physical = true});
    ASSERT_TRUE(check.ok()) << check.summary();
    EXPECT_GE(flipped.quality_after_smoothing.equilateral.min, smoothed.improvement->min_quality_before);
    EXPECT_EQ(flipped.improvement->remeshed_tets,
              std::count_if(flipped.mesh.kinds.begin(), flipped.mesh.kinds.end(), [](TetKind k) { return !k.bisectable(); }));

    const std::vector<SurfaceInterface> interfaces = surface_interfaces(flipped);
    ASSERT_EQ(interfaces.size(), c.surfaces.size());
    for (std::size_t s = 0; s < c.surfaces.size(); ++s) {
      const TriangleSurface& surface = c.surfaces[s];
      const TriangleBVH tree(surface);
      const SurfaceProjection& projection = flipped.surfaces[s].projection;
      std::set<std::array<VertexId, 3>> listed, tagged;
      for (const auto& triangle : projection.triangles) {
        std::array<VertexId, 3> key{projection.nodes[triangle[0]], projection.nodes[triangle[1]], projection.nodes[triangle[2]]};
        std::sort(key.begin(), key.end());
        listed.insert(key);
      }
      for (const InterfaceFace& face : interfaces[s].faces) {
        std::array<VertexId, 3> key = face.vertices;
        std::sort(key.begin(), key.end());
        tagged.insert(key);
        const Eigen::Vector3d centroid = (flipped.mesh.points[face.vertices[0]] + flipped.mesh.points[face.vertices[1]] +
                                          flipped.mesh.points[face.vertices[2]]) / 3.0;
        const auto& t = surface.triangles[tree.closest_point(centroid).triangle];
        const Eigen::Vector3d normal_of_s =
            (surface.points[t[1]] - surface.points[t[0]]).cross(surface.points[t[2]] - surface.points[t[0]]);
        ASSERT_GT(face.normal.dot(normal_of_s), 0.0) << "an interface face turned against S";
      }
      EXPECT_EQ(listed, tagged);
      for (VertexId v : projection.nodes)
        ASSERT_LE(std::sqrt(tree.closest_point(flipped.mesh.points[v]).squared_distance), 1e-12 * c.box.diagonal());
      std::vector<std::uint8_t> on_surface(flipped.mesh.points.size(), 0);
      for (VertexId v : projection.nodes) on_surface[v] = 1;
      for (const auto& tet : flipped.mesh.tets)
        ASSERT_FALSE(on_surface[tet[0]] && on_surface[tet[1]] && on_surface[tet[2]] && on_surface[tet[3]])
            << "a tet has its four vertices on one surface";
    }
  }
  EXPECT_GT(surface_edge_flips, 0) << "no case flipped an edge inside S_M: that path went untested";
}

// Hundreds of flips (the spherical cap with an irregular S_M at threshold 0.5), the same mesh on 1 and 2
// threads.
TEST(Flips, GiveTheSameMeshWithOneAndTwoThreads) {
  const auto cases = testing::surface_cases(16, true);
  const auto c = std::find_if(cases.begin(), cases.end(), [](const auto& candidate) { return candidate.name == "spherical_cap_perturbed_lr24"; });
  ASSERT_NE(c, cases.end());
  InsertionOptions options;
  options.resolution = c->resolution;
  options.improve = Improvement::topology;
  options.improvement.threshold = 0.5;
  options.threads = 1;
  const InsertionResult one = insert_surfaces(make_cube_meccano(c->box, 0), c->surfaces, options);
  options.threads = 2;
  const InsertionResult two = insert_surfaces(make_cube_meccano(c->box, 0), c->surfaces, options);
  ASSERT_GT(one.improvement->flips.operations(), 100);
  EXPECT_EQ(one.mesh.tets, two.mesh.tets);
  EXPECT_EQ(one.mesh.points, two.mesh.points);
}

}  // namespace
}  // namespace meccano
