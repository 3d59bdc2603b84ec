// The invariant checker of `meccano-immerse check FILE.msh`: checks a tetrahedral mesh of a box read from
// any MSH file (io/msh_reader.hpp), this module's or another mesher's, in floating point (verify_mesh in
// mesh/invariants.hpp checks a TetMesh exactly, on its computational coordinates).
//
// Input   an MshMesh: its tets, its 2D groups named xmin ... zmax and interface_*, and its 3D groups
//         named inside_*, negative_* and positive_*, if it has them.
// Checks  conformity   every face of a tet is shared by at most two tets; two tets sharing a face lie on
//                      its two sides; an unshared face lies on the bounding box of the nodes (else a hole);
//         orientation  every tet has positive volume (the count of negative and flat ones otherwise);
//         volume       the tets' volumes (compensated sum) equal the nodes' bounding-box volume to 1e-9
//                      relative;
//         box sides    (when groups xmin ... zmax exist) each lies on its box plane, its areas add up to the
//                      side's area, and the unshared faces of the tets are exactly the box sides' faces;
//         interface_NAME, one per such group: interior faces only (each shared by two tets), a connected
//                      manifold disk (Euler characteristic 1, one boundary loop, no pinched vertex) or, with
//                      no boundary edge, a closed one (Euler characteristic 2), consistently oriented. The summary counts the tets with all four nodes on it,
//                      if any: not a failure, but a fault solver that splits the interface's nodes needs
//                      none (the module's meshes have none; TetGen's with -Y, coarse, may).
//         inside_NAME, one per such 3D group (the tets a closed interface_NAME encloses): across every face
//                      of interface_NAME one tet of the group, behind the face's normal (interfaces point
//                      out of their inclusions); no other face between the group and the rest of the
//                      mesh; no tet of the group on the box boundary. The summary gives its volume.
//         negative_NAME, positive_NAME, one per such 3D group (the parts of the box a clipped interface_NAME
//                      divides it into): as inside_NAME, but the faces of interface_NAME point out of the
//                      negative part and into the positive one, and both parts reach the box.
//         Planes and areas are compared to 1e-9 of the box's largest extent (squared for areas).
// Output  one CheckResult per check, each with its counts and the first problems, naming the file's
//         element tags; text() for a terminal, json() for a report.
#pragma once

#include <meccano/io/msh_reader.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace meccano {

struct CheckResult {
  std::string name;  // "conformity", "orientation", "volume", "box sides", "interface_NAME", "inside_NAME",
                     // "negative_NAME", "positive_NAME"
  bool passed = true;
  std::string summary;                // counts or values, one line
  std::vector<std::string> problems;  // the first max_reported defects found
  std::int64_t problem_count = 0;
};

struct MeshFileCheck {
  std::string source;
  std::int64_t nodes = 0, tets = 0;
  std::vector<CheckResult> checks;

  bool passed() const;
  const CheckResult* find(const std::string& name) const;  // nullptr if that check was not run
  std::string text()
      const;  // a line per check ("conformity: ok (...)" or "conformity: FAILED (...)"), problems indented
  std::string json()
      const;  // {"file", "nodes", "tets", "passed", "checks": [{"name", "passed", "summary", "problems", "problem_count"}]}
};

MeshFileCheck check_msh_mesh(const MshMesh& mesh, int max_reported = 10);

// read_msh_mesh then check_msh_mesh; InputError if the file cannot be read.
MeshFileCheck check_mesh_file(const std::string& path, int max_reported = 10);

}  // namespace meccano
