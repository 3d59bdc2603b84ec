// A moving interface (issue 20): the node correspondence between two meshes, a step made by moving the
// previous step's interface onto the moved surface (move_surfaces), and the sequence that moves while it
// can and inserts anew when it must (SurfaceSequence). Each step is held to what a new insertion gives:
// a valid mesh, S_M's nodes on the moved surface, its faces tagged; and away from the interface, the
// previous step's nodes bit for bit.

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/mesh/bisection.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/mesh/node_correspondence.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/stages/sequence.hpp>

#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace meccano {
namespace {

constexpr double resolution = 1.0 / 16;

TriangleSurface translated(TriangleSurface surface, const Eigen::Vector3d& by) {
  for (Eigen::Vector3d& p : surface.points) p += by;
  return surface;
}

// The test patch, named "patch", raised by `steps` quarters of l_r.
TriangleSurface patch_at(int steps) {
  TriangleSurface patch = translated(testing::paper_like_patch(10), {0.0, 0.0, steps * resolution / 4});
  patch.name = "patch";
  return patch;
}

InsertionOptions band_options() {
  InsertionOptions options;
  options.resolution = resolution;
  options.smoothing.mode = SmoothingMode::band;
  return options;
}

// The largest distance of the S_M nodes to the surface, relative to the unit box.
double largest_node_distance(const InsertionResult& result, const TriangleSurface& surface) {
  const TriangleBVH tree(surface);
  double largest = 0.0;
  for (const VertexId v : result.surfaces.front().projections.front().nodes)
    largest = std::max(largest, (tree.closest_point(result.mesh.points[v]).point - result.mesh.points[v]).norm());
  return largest;
}

TEST(NodeCorrespondence, FindsEveryNodeAtTheSamePositionAndNoOther) {
  const TetMesh coarse = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {1, 1, 1}, 3);
  TetMesh refined = coarse;
  refine_marked(refined, std::vector<TetId>{0, 5, 17});
  refined.points[3].x() = std::nextafter(refined.points[3].x(), 2.0);  // one rounding step away
  const std::vector<VertexId> previous = match_previous_nodes(coarse, refined);
  ASSERT_EQ(previous.size(), refined.points.size());
  for (VertexId v = 0; v < refined.num_vertices(); ++v) {
    if (v == 3 || v >= coarse.num_vertices()) {
      EXPECT_EQ(previous[v], no_previous_node) << "node " << v;
    } else {
      EXPECT_EQ(previous[v], v);
    }
  }
  EXPECT_EQ(count_unchanged_nodes(previous), coarse.num_vertices() - 1);
}

// A quarter of l_r up: the interface follows the surface, the mesh stays valid with the previous step's
// tets, and the nodes away from the interface do not move at all.
TEST(MoveSurfaces, MovesTheInterfaceOntoTheMovedSurfaceAndLeavesTheRestAsItWas) {
  const TetMesh meccano = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {1, 1, 1}, 6);
  const InsertionOptions options = band_options();
  const std::vector<TriangleSurface> before{patch_at(0)}, after{patch_at(1)};
  const InsertionResult inserted = insert_surfaces(meccano, before, options);
  const MoveOptions move{.drag_rings = 2};  // few rings, so that the small mesh has nodes beyond the band
  const InsertionResult moved = move_surfaces(inserted, after, options, move);

  EXPECT_TRUE(verify_mesh(moved.mesh).ok()) << verify_mesh(moved.mesh).summary();
  EXPECT_EQ(count_inverted(moved.mesh), 0);
  EXPECT_EQ(moved.mesh.num_vertices(), inserted.mesh.num_vertices());
  EXPECT_LT(largest_node_distance(moved, after.front()), 1e-12);
  EXPECT_GT(largest_node_distance(inserted, after.front()), resolution / 8) << "the surface did move";
  const auto interfaces = surface_interfaces(moved);
  ASSERT_EQ(interfaces.size(), 1u);
  EXPECT_EQ(interfaces.front().faces.size(), moved.surfaces.front().projections.front().triangles.size());

  // Only the S_M nodes and the nodes within the band around them (the dragged rings and one more) may
  // move; the others keep the previous step's position exactly.
  const std::vector<VertexId> previous = match_previous_nodes(inserted.mesh, moved.mesh);
  const std::vector<VertexId>& interface_nodes = moved.surfaces.front().projections.front().nodes;
  for (const VertexId v : interface_nodes) EXPECT_EQ(previous[v], no_previous_node);
  std::vector<std::uint8_t> in_band(moved.mesh.points.size(), 0);
  std::vector<VertexId> ring = interface_nodes;
  for (const VertexId v : ring) in_band[v] = 1;
  const VertexTets stars = vertex_to_tets(moved.mesh);
  const int band_rings = std::max(options.smoothing.band_rings, move.drag_rings + 1);
  for (int k = 0; k < band_rings; ++k) {
    std::vector<VertexId> next;
    for (const VertexId v : ring)
      for (const TetId t : stars.of(v))
        for (const VertexId w : moved.mesh.tets[t])
          if (!in_band[w]) {
            in_band[w] = 1;
            next.push_back(w);
          }
    ring = std::move(next);
  }
  std::int64_t beyond = 0;
  for (VertexId v = 0; v < moved.mesh.num_vertices(); ++v)
    if (!in_band[v]) {
      ++beyond;
      EXPECT_EQ(previous[v], v) << "node " << v << " beyond the band moved";
    }
  EXPECT_GT(beyond, 0);
}

// The patch turned by `degrees` about the vertical axis through the box's centre.
TriangleSurface turned(TriangleSurface surface, double degrees) {
  const Eigen::AngleAxisd turn(degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d centre(0.5, 0.5, 0.0);
  for (Eigen::Vector3d& p : surface.points) p = centre + turn * (p - centre);
  return surface;
}

// Moved rigidly (translated, turned), the interface carries the tets standing on it whole: their other
// nodes (the first ring around S_M) follow the rigid motion that carries their S_M neighbours, so these
// tets keep their edge lengths, hence both quality measures, exactly. Faded from S_M itself, or moved by
// the mean of their neighbours' moves, they were sheared a little by every step, and the paper's minimum
// drifted down.
TEST(MoveSurfaces, ARigidMotionCarriesTheTetsStandingOnTheInterfaceWhole) {
  const TetMesh meccano = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {1, 1, 1}, 6);
  InsertionOptions options = band_options();
  options.improve = Improvement::none;  // the move's drag alone decides where the nodes go
  const InsertionResult inserted = insert_surfaces(meccano, std::vector<TriangleSurface>{patch_at(0)}, options);
  for (const auto& [motion, surface] :
       {std::pair{"translated", patch_at(1)}, std::pair{"turned", turned(patch_at(0), 2.0)}}) {
    SCOPED_TRACE(motion);
    const InsertionResult moved = move_surfaces(inserted, std::vector<TriangleSurface>{surface}, options);
    ASSERT_EQ(moved.drag.inverted_tets, 0) << "SUS would run and move the nodes again";
    const std::vector<VertexId>& interface_nodes = moved.surfaces.front().projections.front().nodes;
    std::vector<std::uint8_t> on_interface(moved.mesh.points.size(), 0), near(moved.mesh.points.size(), 0);
    for (const VertexId v : interface_nodes) on_interface[v] = 1;
    for (TetId t = 0; t < moved.mesh.num_tets(); ++t)
      if (std::ranges::any_of(moved.mesh.tets[t], [&](VertexId v) { return on_interface[v] != 0; }))
        for (const VertexId v : moved.mesh.tets[t]) near[v] = 1;  // S_M's nodes and their neighbours
    std::int64_t carried = 0;
    for (TetId t = 0; t < moved.mesh.num_tets(); ++t) {
      const auto& tet = moved.mesh.tets[t];
      if (!std::ranges::all_of(tet, [&](VertexId v) { return near[v] != 0; }) ||
          std::ranges::any_of(tet, [&](VertexId v) { return moved.mesh.meccano.box_planes(moved.mesh.grid[v]) != 0; }))
        continue;
      ++carried;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          const double before = (inserted.mesh.points[tet[i]] - inserted.mesh.points[tet[j]]).norm();
          const double after = (moved.mesh.points[tet[i]] - moved.mesh.points[tet[j]]).norm();
          ASSERT_NEAR(after, before, 1e-12) << "tet " << t << " changed shape";
        }
      EXPECT_NEAR(mean_ratio_meccano(moved.mesh, t), mean_ratio_meccano(inserted.mesh, t), 1e-9);
    }
    EXPECT_GT(carried, static_cast<std::int64_t>(interface_nodes.size()));
  }
}

TEST(MoveSurfaces, RefusesASurfaceWithAnotherTriangulation) {
  const TetMesh meccano = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {1, 1, 1}, 6);
  const InsertionOptions options = band_options();
  const InsertionResult inserted = insert_surfaces(meccano, std::vector<TriangleSurface>{patch_at(0)}, options);
  TriangleSurface finer = testing::paper_like_patch(12);
  finer.name = "patch";
  EXPECT_THROW(move_surfaces(inserted, std::vector<TriangleSurface>{finer}, options), InputError);
  TriangleSurface flipped = patch_at(0);
  std::swap(flipped.triangles[7][1], flipped.triangles[7][2]);
  EXPECT_THROW(move_surfaces(inserted, std::vector<TriangleSurface>{flipped}, options), InputError);
}

// Eight quarters of l_r up, step by step: every step valid and on its surface, the first inserted, later
// ones moved while they keep the quality, the tet count that of an insertion, and each node's previous
// node at its position.
TEST(SurfaceSequence, MovesWhileItCanAndEveryStepIsValid) {
  const TetMesh meccano = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {1, 1, 1}, 6);
  SurfaceSequence sequence(meccano, band_options());
  const TetMesh* previous_mesh = nullptr;
  TetMesh previous_copy;
  int moved = 0;
  for (int k = 0; k <= 8; ++k) {
    const TriangleSurface surface = patch_at(k);
    const SequenceStep& step = sequence.advance({surface});
    SCOPED_TRACE("step " + std::to_string(k) + " " + step.inserted_because);
    EXPECT_EQ(step.index, k);
    EXPECT_EQ(step.kind == StepKind::inserted, k == 0 || !step.inserted_because.empty());
    moved += step.kind == StepKind::moved;
    EXPECT_TRUE(verify_mesh(step.result.mesh).ok());
    EXPECT_LT(largest_node_distance(step.result, surface), 1e-12);
    ASSERT_EQ(step.previous_node.size(), step.result.mesh.points.size());
    for (VertexId v = 0; v < step.result.mesh.num_vertices(); ++v) {
      const VertexId p = step.previous_node[v];
      if (p == no_previous_node) continue;
      ASSERT_NE(previous_mesh, nullptr);
      ASSERT_EQ(previous_mesh->points[p], step.result.mesh.points[v]) << "node " << v;
    }
    EXPECT_EQ(step.nodes_unchanged, count_unchanged_nodes(step.previous_node));
    if (k > 0) {
      EXPECT_GT(step.nodes_unchanged, 0);
    }
    previous_copy = step.result.mesh;
    previous_mesh = &previous_copy;
  }
  // 8 of 8 with the drag fading by distance; 6 when it faded ring by ring and squeezed the small tets.
  EXPECT_GE(moved, 7) << "quarter steps are moved, not inserted anew";
}

TEST(SurfaceSequence, InsertsAnewWhenAskedOrWhenTheTriangulationChanges) {
  const TetMesh meccano = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {1, 1, 1}, 6);
  SurfaceSequence always(meccano, band_options(), {.always_insert = true});
  always.advance({patch_at(0)});
  EXPECT_EQ(always.advance({patch_at(1)}).kind, StepKind::inserted);

  SurfaceSequence sequence(meccano, band_options());
  sequence.advance({patch_at(0)});
  TriangleSurface finer = translated(testing::paper_like_patch(12), {0.0, 0.0, resolution / 4});
  finer.name = "patch";
  const SequenceStep& step = sequence.advance({finer});
  EXPECT_EQ(step.kind, StepKind::inserted);
  EXPECT_NE(step.inserted_because.find("triangulation"), std::string::npos) << step.inserted_because;
  EXPECT_TRUE(verify_mesh(step.result.mesh).ok());

  // Two l_r in one step: beyond max_move_in_resolutions (1), so no move is tried.
  const TriangleSurface jumped = translated(finer, {0.0, 0.0, 2 * resolution});
  const SequenceStep& jump = sequence.advance({jumped});
  EXPECT_EQ(jump.kind, StepKind::inserted);
  EXPECT_NE(jump.inserted_because.find("patch moved by 2 l_r, more than 1"), std::string::npos)
      << jump.inserted_because;
  EXPECT_TRUE(verify_mesh(jump.result.mesh).ok());
  EXPECT_LT(largest_node_distance(jump.result, jumped), 1e-12);
}

// A move that lost quality goes straight to the new insertion unless retry_after_quality_loss asks for
// the second move; a loss of -1 makes every move lose quality.
TEST(SurfaceSequence, AMoveThatLostQualityIsNotTriedAgainUnlessAsked) {
  const TetMesh meccano = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {1, 1, 1}, 6);
  for (const bool retry : {false, true}) {
    SurfaceSequence sequence(meccano, band_options(), {.max_quality_loss = -1.0, .retry_after_quality_loss = retry});
    sequence.advance({patch_at(0)});
    const SequenceStep& step = sequence.advance({patch_at(1)});
    SCOPED_TRACE(step.inserted_because);
    EXPECT_EQ(step.kind, StepKind::inserted);
    EXPECT_EQ(step.inserted_because.rfind("moving lost quality: ", 0), 0u);
    EXPECT_EQ(step.inserted_because.find("moving again") != std::string::npos, retry);
    EXPECT_TRUE(verify_mesh(step.result.mesh).ok());
  }
}

}  // namespace
}  // namespace meccano
