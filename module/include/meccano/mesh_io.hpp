// Mesh output with named groups, in the formats solvers read.
//
// Groups: named sets of tets (3D physical groups) and of faces (2D physical groups). A face is given by
// a tet and its local face and is written with its normal pointing out of that tet, so the caller
// fixes each group's orientation. standard_groups() gives what every output carries: `domain` (all
// tets), the box sides `xmin` ... `zmax` (outward normals), and one group per interface tag.
// MSH 4.1 ASCII: groups may overlap (a tet in `domain` and in `volumetric_1`); elements are written
// once, in entities that partition them by group membership, and every physical group is the union of
// its entities.
// Writes are atomic (atomic_file.hpp).
#pragma once

#include <meccano/tet_mesh.hpp>

#include <string>
#include <vector>

namespace meccano {

struct FaceRef {
  TetId tet;
  int local_face;
};

struct TetGroup {
  std::string name;
  std::vector<TetId> tets;
};

struct FaceGroup {
  std::string name;
  std::vector<FaceRef> faces;
};

struct MeshGroups {
  std::vector<TetGroup> volumes;
  std::vector<FaceGroup> surfaces;
};

// `domain`, the six box sides, and `interface_NAME` for every interface tag in use, NAME taken from
// `interface_names` (index = interface index). Interface faces are oriented out of the tet on the side
// of the face where the tag was set first in tet order; stages that know the surface's normal build
// their own group instead.
MeshGroups standard_groups(const TetMesh& mesh, const std::vector<std::string>& interface_names = {});

void write_msh41(const TetMesh& mesh, const MeshGroups& groups, const std::string& path);

}  // namespace meccano
