// verify_mesh against meshes broken on purpose: each defect a pipeline stage could leave (a lost or
// one-sided neighbour, a hole, a duplicated or overlapping tet, a wrong tag) must be reported, and a
// valid mesh must pass with its faces counted.

#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>

namespace meccano {
namespace {

TetMesh unit_cube_mesh() { return make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 3); }

// Some interior face: a tet, its local face and the tet across it.
struct InteriorFace {
  TetId tet = no_tet;
  int face = -1;
  TetId across = no_tet;
};
InteriorFace interior_face(const TetMesh& mesh, TetId from = 0) {
  for (TetId t = from; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f)
      if (mesh.neighbours[t][f] != no_tet) return {t, f, mesh.neighbours[t][f]};
  return {};
}

int local_face_towards(const TetMesh& mesh, TetId t, TetId n) {
  return static_cast<int>(std::find(mesh.neighbours[t].begin(), mesh.neighbours[t].end(), n) -
                          mesh.neighbours[t].begin());
}

// The check fails and one of its problems contains `words`.
void expect_problem(const TetMesh& mesh, const std::string& words) {
  const MeshInvariantReport report = verify_mesh(mesh);
  EXPECT_FALSE(report.ok());
  EXPECT_TRUE(
      std::ranges::any_of(report.problems, [&](const std::string& p) { return p.find(words) != std::string::npos; }))
      << "no problem mentions \"" << words << "\":\n"
      << report.summary();
}

TEST(MeshInvariants, AValidMeshPassesWithEveryFaceCountedOnce) {
  const TetMesh mesh = unit_cube_mesh();
  const MeshInvariantReport report = verify_mesh(mesh);
  ASSERT_TRUE(report.ok()) << report.summary();
  // Level 3 of one cell: each box side is 2 triangles split 3 times by the bisection of its tets.
  EXPECT_EQ(report.boundary_faces, 6 * 2 * 4);
  EXPECT_EQ(2 * report.interior_faces + report.boundary_faces, 4 * std::int64_t{mesh.num_tets()});
  EXPECT_NEAR(report.physical_volume, 1.0, 1e-12);
}

TEST(MeshInvariants, ANeighbourForgottenOnOneSideIsAHoleAndAOneSidedPair) {
  TetMesh mesh = unit_cube_mesh();
  const InteriorFace face = interior_face(mesh);
  mesh.neighbours[face.tet][face.face] = no_tet;
  expect_problem(mesh, "(a hole)");
  expect_problem(mesh, "not recorded as each other's neighbours");
}

TEST(MeshInvariants, ANeighbourThatDoesNotHoldTheFaceIsReported) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {3, 2, 1}}, 3);  // in one cell every tet meets the centre
  const InteriorFace face = interior_face(mesh);
  TetId far = 0;  // a tet sharing no vertex with the face's tet
  while (
      std::ranges::any_of(mesh.tets[far], [&](VertexId v) { return std::ranges::count(mesh.tets[face.tet], v) > 0; }))
    ++far;
  ASSERT_LT(far, mesh.num_tets());
  mesh.neighbours[face.tet][face.face] = far;
  expect_problem(mesh, "which does not hold that face");
  mesh.neighbours[face.tet][face.face] = mesh.num_tets();
  expect_problem(mesh, "not another tet");
  mesh.neighbours[face.tet][face.face] = face.tet;
  expect_problem(mesh, "not another tet");
}

TEST(MeshInvariants, ARemovedTetLeavesHolesAndAVolumeShortfall) {
  TetMesh mesh = unit_cube_mesh();
  const InteriorFace face = interior_face(mesh);
  const TetId removed = face.across, last = mesh.num_tets() - 1;
  for (TetId& n : mesh.neighbours[removed])
    if (n != no_tet) mesh.neighbours[n][local_face_towards(mesh, n, removed)] = no_tet;
  // Move the last tet into the removed one's slot, and its neighbours' references with it.
  for (TetId n : mesh.neighbours[last])
    if (n != no_tet) mesh.neighbours[n][local_face_towards(mesh, n, last)] = removed;
  mesh.tets[removed] = mesh.tets[last];
  mesh.kinds[removed] = mesh.kinds[last];
  mesh.neighbours[removed] = mesh.neighbours[last];
  mesh.face_tags[removed] = mesh.face_tags[last];
  mesh.tets.pop_back();
  mesh.kinds.pop_back();
  mesh.neighbours.pop_back();
  mesh.face_tags.pop_back();
  expect_problem(mesh, "(a hole)");
  expect_problem(mesh, "computational volume differs");
}

TEST(MeshInvariants, ADuplicatedTetIsNotItsNeighboursNeighbour) {
  TetMesh mesh = unit_cube_mesh();
  mesh.tets.push_back(mesh.tets[0]);
  mesh.kinds.push_back(mesh.kinds[0]);
  mesh.neighbours.push_back(mesh.neighbours[0]);
  mesh.face_tags.push_back(mesh.face_tags[0]);
  expect_problem(mesh, "not recorded as each other's neighbours");
  expect_problem(mesh, "computational volume differs");
}

TEST(MeshInvariants, TwoTetsOnOneSideOfTheirSharedFaceOverlap) {
  TetMesh mesh = unit_cube_mesh();
  const InteriorFace face = interior_face(mesh);
  // The tet across takes this tet's apex for its own, two of its other vertices swapped (with their
  // faces' neighbours and tags) so that it keeps the orientation it records: the two tets are now one,
  // twice, on the same side of the face.
  const int across_face = local_face_towards(mesh, face.across, face.tet);
  const int i = (across_face + 1) % 4, j = (across_face + 2) % 4;
  mesh.tets[face.across][across_face] = mesh.tets[face.tet][face.face];
  std::swap(mesh.tets[face.across][i], mesh.tets[face.across][j]);
  std::swap(mesh.neighbours[face.across][i], mesh.neighbours[face.across][j]);
  std::swap(mesh.face_tags[face.across][i], mesh.face_tags[face.across][j]);
  expect_problem(mesh, "lie on the same side of their shared face");
}

TEST(MeshInvariants, WrongTagsOnBoundaryAndInteriorFacesAreReported) {
  TetMesh mesh = unit_cube_mesh();
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f)
      if (mesh.neighbours[t][f] == no_tet && mesh.face_tags[t][f] == box_side_tag(BoxSide::xmin)) {
        mesh.face_tags[t][f] = box_side_tag(BoxSide::xmax);
        expect_problem(mesh, "is not tagged xmin");
        mesh.face_tags[t][f] = box_side_tag(BoxSide::xmin);
      }
  ASSERT_TRUE(verify_mesh(mesh).ok());
  const InteriorFace face = interior_face(mesh);
  mesh.face_tags[face.tet][face.face] = box_side_tag(BoxSide::zmax);
  expect_problem(mesh, "carries a box-side tag");
  expect_problem(mesh, "tagged differently on each side");
}

}  // namespace
}  // namespace meccano
