// Closed surfaces (issue 19): a sphere, an ellipsoid, a bumpy blob, two inclusions and an inclusion beside
// an open fault, inserted through the whole pipeline. The result must be a valid mesh whose interface is
// a closed sphere (Euler characteristic 2, no rim) lying on S, oriented out of the inclusion, with the
// enclosed tets (`inside_NAME`) filling S's volume; and what cannot be inserted is refused.

#include <meccano/error.hpp>
#include <meccano/inspect/mesh_file_check.hpp>
#include <meccano/io/mesh_writers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/stages/sequence.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/validation.hpp>

#include <test_surfaces.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace meccano {
namespace {

using ::testing::HasSubstr;

const Box kUnitBox{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};

InsertionResult insert(std::span<const TriangleSurface> surfaces, const Box& box, double resolution) {
  validate_surfaces(surfaces, box);
  InsertionOptions options;
  options.resolution = resolution;
  return insert_surfaces(make_cube_meccano(box, 0), surfaces, options);
}

double tet_volume(const TetMesh& mesh, TetId t) {
  const TetPoints p = mesh.tet_points(t);
  return std::abs((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))) / 6.0;
}

// Every invariant a solver relies on, for closed surface s of `surfaces`.
// `chord_loss`: the share of S's volume the interface's flat faces may cut off.
void expect_closed_interface(const InsertionResult& result, const TriangleSurface& surface, int s,
                             double chord_loss = 0.01) {
  const TetMesh& mesh = result.mesh;
  ASSERT_TRUE(verify_mesh(mesh, {.physical = true}).ok()) << verify_mesh(mesh, {.physical = true}).summary();
  EXPECT_EQ(count_inverted(mesh), 0);
  ASSERT_TRUE(result.surfaces[s].closed);

  const std::vector<SurfaceInterface> interfaces = surface_interfaces(result);
  const SurfaceInterface& interface = interfaces[s];
  std::vector<std::array<VertexId, 3>> triangles;
  for (const InterfaceFace& face : interface.faces) triangles.push_back(face.vertices);
  // A closed 2-manifold (every edge in two faces, once in each direction) of Euler characteristic 2.
  std::map<std::pair<VertexId, VertexId>, int> directed;
  std::vector<VertexId> vertices;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      ++directed[{t[k], t[(k + 1) % 3]}];
      vertices.push_back(t[k]);
    }
  for (const auto& [edge, uses] : directed) {
    EXPECT_EQ(uses, 1) << edge.first << "-" << edge.second;
    EXPECT_TRUE(directed.contains({edge.second, edge.first})) << edge.first << "-" << edge.second;
  }
  std::ranges::sort(vertices);
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  EXPECT_EQ(static_cast<std::int64_t>(vertices.size()) - static_cast<std::int64_t>(directed.size() / 2) +
                static_cast<std::int64_t>(triangles.size()),
            2);

  // On S, and oriented out of it: the volume the interface encloses is positive and S's, but for the
  // chords its flat faces lay across S's curvature.
  const TriangleBVH tree(surface);
  const double tolerance = 1e-12 * mesh.meccano.box.diagonal();
  double largest_distance = 0.0;
  for (const auto& t : triangles)
    for (VertexId v : t)
      largest_distance = std::max(largest_distance, std::sqrt(tree.closest_point(mesh.points[v]).squared_distance));
  EXPECT_LE(largest_distance, tolerance);
  TriangleSurface as_surface;
  as_surface.points = mesh.points;
  for (const auto& t : triangles) as_surface.triangles.push_back({t[0], t[1], t[2]});
  const double enclosed = enclosed_volume(as_surface);
  EXPECT_NEAR(enclosed, std::abs(enclosed_volume(surface)), chord_loss * std::abs(enclosed_volume(surface)));

  // inside_NAME: exactly the tets behind the interface, whose volume is S's.
  const MeshGroups groups = output_groups(result);
  const auto inside = std::ranges::find(groups.volumes, "inside_" + surface.name, &TetGroup::name);
  ASSERT_NE(inside, groups.volumes.end());
  double inside_volume = 0.0;
  std::vector<std::uint8_t> in_group(mesh.tets.size(), 0);
  for (TetId t : inside->tets) {
    inside_volume += tet_volume(mesh, t);
    in_group[t] = 1;
  }
  EXPECT_NEAR(inside_volume, enclosed, 1e-9 * enclosed);
  for (const InterfaceFace& face : interface.faces) {
    EXPECT_TRUE(in_group[face.negative.tet]);
    EXPECT_FALSE(in_group[face.positive.tet]);
  }
}

TEST(ClosedSurface, ASphereIsInsertedAsAClosedInterface) {
  const TriangleSurface surface = testing::sphere(12);
  const InsertionResult result = insert({&surface, 1}, kUnitBox, 0.06);
  expect_closed_interface(result, surface, 0);
}

TEST(ClosedSurface, InwardNormalsAreTurnedOut) {
  TriangleSurface surface = testing::sphere(10);
  for (auto& t : surface.triangles) std::swap(t[1], t[2]);
  ASSERT_LT(enclosed_volume(surface), 0.0);
  const InsertionResult result = insert({&surface, 1}, kUnitBox, 0.08);
  expect_closed_interface(result, oriented_outward(surface), 0);
}

TEST(ClosedSurface, AnEllipsoidInANonCubicBox) {
  const TriangleSurface surface = testing::ellipsoid({1.0, 0.5, 0.5}, {0.7, 0.3, 0.2}, 16);
  const Box box{Eigen::Vector3d::Zero(), Eigen::Vector3d(2.0, 1.0, 1.0)};
  const InsertionResult result = insert({&surface, 1}, box, 0.05);
  expect_closed_interface(result, surface, 0);
}

TEST(ClosedSurface, ABumpyBlobAtTwoResolutions) {
  const TriangleSurface surface = testing::bumpy_blob(20);
  for (double resolution : {0.06, 0.04}) {
    SCOPED_TRACE(resolution);
    expect_closed_interface(insert({&surface, 1}, kUnitBox, resolution), surface, 0);
  }
}

// The fault comes first, so the inclusions' S_M halves are not at their surfaces' indices among the
// projections the improvement stage takes.
TEST(ClosedSurface, TwoInclusionsAndAFaultBesideThem) {
  std::vector<TriangleSurface> surfaces{
      testing::graph_patch([](double x, double) { return 0.82 + 0.05 * std::sin(6 * x); }, {0.15, 0.85}, {0.15, 0.85},
                           12, "fault"),
      testing::ellipsoid({0.28, 0.5, 0.5}, {0.15, 0.15, 0.15}, 10, "left"),
      testing::ellipsoid({0.72, 0.5, 0.5}, {0.15, 0.2, 0.15}, 10, "right")};
  const InsertionResult result = insert(surfaces, kUnitBox, 0.05);
  EXPECT_FALSE(result.surfaces[0].closed);
  // Faces up to l_r long on spheres of radius 0.15 cut off more of them: 1.3 % measured.
  expect_closed_interface(result, surfaces[1], 1, 0.03);
  expect_closed_interface(result, surfaces[2], 2, 0.03);
  const MeshGroups groups = output_groups(result);
  EXPECT_EQ(std::ranges::count_if(groups.volumes, [](const TetGroup& g) { return g.name.starts_with("inside_"); }), 2);
}

// An inclusion 0.1 thick at l_r = 0.07: the improvement's edge flips inside S_M must find the half of
// S_M that holds an edge (they once looked in the other and failed).
TEST(ClosedSurface, AThinEllipsoidAtACoarseResolution) {
  const TriangleSurface surface = testing::ellipsoid({0.5, 0.5, 0.5}, {0.35, 0.3, 0.05}, 16);
  expect_closed_interface(insert({&surface, 1}, kUnitBox, 0.07), surface, 0, 0.1);
}

// `meccano-immerse check` on the written file: the closed interface and its inside pass; an inside group
// missing a tet, or an interface turned inwards, fail with their reason.
TEST(ClosedSurface, TheFileCheckerKnowsClosedInterfacesAndInsides) {
  const TriangleSurface surface = testing::sphere(10);
  const InsertionResult result = insert({&surface, 1}, kUnitBox, 0.08);
  const std::string path =
      (std::filesystem::temp_directory_path() / ("meccano-closed-" + std::to_string(::getpid()) + ".msh")).string();
  auto check = [&](const MeshGroups& groups) {
    write_mesh(result.mesh, groups, path);
    const MeshFileCheck report = check_mesh_file(path);
    std::filesystem::remove(path);
    return report;
  };
  const MeshGroups groups = output_groups(result);
  const MeshFileCheck passed = check(groups);
  EXPECT_TRUE(passed.passed()) << passed.text();
  ASSERT_NE(passed.find("inside_sphere"), nullptr);
  EXPECT_THAT(passed.find("interface_sphere")->summary, HasSubstr("Euler characteristic 2, 0 boundary loop(s)"));

  MeshGroups missing_tet = groups;
  auto inside = std::ranges::find(missing_tet.volumes, "inside_sphere", &TetGroup::name);
  inside->tets.erase(inside->tets.begin() + static_cast<std::ptrdiff_t>(inside->tets.size() / 2));
  const MeshFileCheck holed = check(missing_tet);
  EXPECT_FALSE(holed.passed());
  EXPECT_THAT(holed.text(), HasSubstr("leaves the group without crossing interface_sphere"));

  MeshGroups turned_in = groups;
  auto interface = std::ranges::find(turned_in.surfaces, "interface_sphere", &FaceGroup::name);
  for (FaceRef& face : interface->faces) {
    const TetId other = result.mesh.neighbours[face.tet][face.local_face];
    face = {other, result.mesh.face_towards(other, face.tet)};
  }
  const MeshFileCheck inward = check(turned_in);
  EXPECT_FALSE(inward.passed());
  EXPECT_THAT(inward.text(), HasSubstr("of interface_sphere points into tet"));
}

TEST(ClosedSurface, ATorusIsRefused) {
  const TriangleSurface torus = testing::closed_torus(16);
  try {
    validate_surfaces({&torus, 1}, kUnitBox);
    FAIL() << "a torus was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("closed surface of genus 1"));
  }
}

TEST(ClosedSurface, ASphereTouchingTheBoxIsRefused) {
  const TriangleSurface surface = testing::ellipsoid({0.5, 0.5, 0.5}, {0.5, 0.3, 0.3}, 8);
  EXPECT_THROW(validate_surfaces({&surface, 1}, kUnitBox), InputError);
}

// `surface` grown about the sphere's centre (0.5, 0.5, 0.5) by `factor`.
TriangleSurface grown(TriangleSurface surface, double factor) {
  const Eigen::Vector3d centre(0.5, 0.5, 0.5);
  for (Eigen::Vector3d& p : surface.points) p = centre + factor * (p - centre);
  return surface;
}

TriangleSurface shifted(TriangleSurface surface, const Eigen::Vector3d& by) {
  for (Eigen::Vector3d& p : surface.points) p += by;
  return surface;
}

// A cut replayed on the moved points puts each crossing on the same edge at the same fraction, so the
// parts keep their triangles wherever the points went.
TEST(ClosedSurface, ACutIsReplayedOnTheMovedPoints) {
  const TriangleSurface surface = testing::sphere(8);
  const std::optional<PlaneCut> cut = cut_by_plane(surface, 2, 0.53);
  ASSERT_TRUE(cut);
  ASSERT_FALSE(cut->crossings.empty());
  ASSERT_EQ(cut->points.size(), surface.points.size() + cut->crossings.size());
  EXPECT_EQ(crossing_points(surface.points, cut->crossings), cut->points);

  const TriangleSurface moved = grown(surface, 1.1);
  const std::vector<Eigen::Vector3d> replayed = crossing_points(moved.points, cut->crossings);
  ASSERT_EQ(replayed.size(), cut->points.size());
  for (std::size_t i = 0; i < cut->crossings.size(); ++i) {
    const EdgeCrossing& at = cut->crossings[i];
    const Eigen::Vector3d& a = moved.points[at.low];
    const Eigen::Vector3d& b = moved.points[at.high];
    const Eigen::Vector3d& x = replayed[surface.points.size() + i];
    EXPECT_LT((x - a).cross(b - a).norm(), 1e-12) << "crossing " << i << " off its edge";
    EXPECT_NEAR((x - a).norm() / (b - a).norm(), at.fraction, 1e-12);
    EXPECT_GT(at.fraction, 0.0);
    EXPECT_LT(at.fraction, 1.0);
  }
}

// A closed surface moved (grown, then shifted) from the previous result: its two halves are cut as they
// were and the interface lands on the moved surface, a closed sphere enclosing its volume; the tets are
// the previous ones (with the improvement's node moves alone: its flips would change them).
TEST(ClosedSurface, MovingOneCutsItAlikeAndLandsOnTheMovedSurface) {
  const TriangleSurface surface = testing::sphere(8);
  const InsertionResult inserted = insert({&surface, 1}, kUnitBox, 0.1);
  ASSERT_EQ(inserted.surfaces.front().projections.size(), 2u);
  InsertionOptions options;
  options.resolution = 0.1;
  options.improve = Improvement::smooth;
  for (const TriangleSurface& moved_surface :
       {grown(surface, 1.08), grown(surface, 0.93), shifted(surface, {0.01, -0.02, 0.015})}) {
    const InsertionResult moved = move_surfaces(inserted, {&moved_surface, 1}, options);
    EXPECT_EQ(moved.mesh.tets, inserted.mesh.tets);
    ASSERT_EQ(moved.surfaces.front().projections.size(), 2u);
    EXPECT_GT(moved.surfaces.front().projection_stats().largest_move, 0.01);
    expect_closed_interface(moved, moved_surface, 0, 0.05);
  }
}

// A growing sphere: its steps are moved, not inserted anew, and each is a valid inclusion whose nodes away
// from it keep their places, until its area has grown by more than a tenth since its insertion (then the
// refinement made for it is stretched: the step is inserted anew).
TEST(ClosedSurface, ASequenceMovesAGrowingSphereUntilItsAreaChanged) {
  InsertionOptions options;
  options.resolution = 0.1;
  SurfaceSequence sequence(make_cube_meccano(kUnitBox, 0), options);
  const TriangleSurface sphere = testing::sphere(8);  // radius 0.3
  for (int step = 0; step < 5; ++step) {
    // Radius 0.3 + 0.004 step: the area grows by 2.7, 5.4, 8.2 and 10.9 % at steps 1-4.
    const TriangleSurface surface = grown(sphere, 1.0 + step * 0.004 / 0.3);
    const SequenceStep& done = sequence.advance({surface});
    SCOPED_TRACE("step " + std::to_string(step) + ": " + done.inserted_because);
    EXPECT_EQ(done.kind, step == 0 || step == 4 ? StepKind::inserted : StepKind::moved);
    expect_closed_interface(done.result, surface, 0, 0.05);
    if (step > 0) {
      EXPECT_GT(done.nodes_unchanged, 0);
    }
    if (step == 4) {
      EXPECT_THAT(done.inserted_because, HasSubstr("the area of sphere changed by 10.9"));
    }
  }
}

}  // namespace
}  // namespace meccano
