// Invariant checks of a TetMesh, run by the tests and, cheaply, at the end of every pipeline stage.
//
// Checked, with exact integer arithmetic on computational coordinates where it matters:
//   - every tet has 4 distinct vertices, non-zero volume and the orientation its kind records;
//   - conformity: every face is shared by one or two tets; shared faces are each other's neighbours;
//     unshared faces have no neighbour, lie on a box side and carry that side's tag; interior faces
//     carry no box-side tag and the same tag on both sides. Checked through `neighbours` (no sort): a
//     recorded neighbour must hold the face in the opposite orientation and point back, a face without
//     one must lie on a box side; with the orientations and the box tiling below, the tets then cover
//     the box once, so no face can have three tets. With physical = false a remeshed tet's orientation
//     is not checked (it has no exact one), so neither is the cover around it;
//   - the boundary faces tile each box side exactly (their areas add up to the side's area);
//   - the tets' computational volumes add up to the box volume exactly;
//   - optionally (physical = true) every tet is positively oriented in physical space and the physical
//     volumes add up to the box volume to round-off.
#pragma once

#include <meccano/mesh/tet_mesh.hpp>

#include <string>
#include <vector>

namespace meccano {

struct MeshInvariantOptions {
  bool physical = true;
  int max_reported = 20;
};

struct MeshInvariantReport {
  std::vector<std::string> problems;  // the first max_reported problems found
  std::int64_t problem_count = 0;
  std::int64_t interior_faces = 0;
  std::int64_t boundary_faces = 0;
  double physical_volume = 0.0;
  std::int64_t inverted_physical = 0;
  bool ok() const { return problem_count == 0; }
  std::string summary() const;
};

MeshInvariantReport verify_mesh(const TetMesh& mesh, const MeshInvariantOptions& options = {});

}  // namespace meccano
