// Step 3 of the method (paper §4.3): every node of S_M moves onto S, x_i = φ(φ_M^{-1}(x_Mi)).
//
// Input    the mesh, the index and side of a healed S_M (stages/surface_approximation.hpp), and S.
// Steps    1. S and S_M (its faces oriented like S) are parameterized onto P = [0,1]^2 with Floater's
//             weights (stages/parameterization.hpp); S_M's weights are taken with its nodes pulled 80 % of
//             the way onto S, so that the two parameterizations nearly agree (see stages/projection.cpp).
//             S's corners are chosen along its rim by arc length (natural corners kept); S_M's are the rim
//             nodes closest to them, in the same cyclic order around the same mean normal, so
//             φ ∘ φ_M^{-1} does not twist.
//             Before that, the rim gap (how far the farthest rim vertex of S lies from S_M's rim) is
//             measured: where S_M leaves part of S uncovered, projection would drag rim nodes across the
//             gap and tangle tets no smoothing can mend, so a gap above options.max_rim_gap is an error.
//          2. S_M follows the creases of S sharper than options.crease_angle (surface/creases.hpp): nodes near a
//             crease move, in P, onto it, forming paths of S_M edges along the crease lines.
//          3. Each S_M node's parameters u (φ_M^{-1}(x_M), or its place on a crease) are located in S's
//             parametric triangulation and the node moves to φ(u). Rim nodes land on the rim of S,
//             corners on its corners, crease nodes on the crease edges of S.
// Box      where S is clipped by the box (surface/box_clipping.hpp), its rim runs in arcs on the box faces
//          and inside the box, and so must S_M's (its rim nodes on the box are those of V_M's faces beside the
//          box). The arcs are matched in order, S_M's transitions (where one arc ends and the next begins)
//          are pinned on the square's perimeter at the coordinates of S's (RimAnchor), and S's other
//          corners go to the nodes at the same share of the matched arcs; every rim node then lands on the
//          arc of S on its own box faces, and keeps its coordinates on them exactly. A rim that runs
//          entirely on one box face (a cap standing on the box) is matched as an inner rim.
// Closed   project_closed_onto_surface, for a closed S (surface/closed_surface.hpp) and its closed S_M (a
//          sphere, built outside S): both are cut along one coordinate plane into two disks, and each half
//          of S_M is projected onto its half of S as above. The plane passes through S_M's nodes and
//          follows its edges (S_M's faces are axis-parallel, so a plane at a node's computational coordinate
//          usually does); of the planes that leave both S_M and S in two disks without chords (interior
//          edges between two rim vertices), the one nearest to the middle of S_M is taken. Both halves take
//          the same corners on the cut and space the nodes between them alike, so a node on the cut lands
//          on the same point of S from either half. The rim gap is not measured: there is no rim. Each
//          half keeps how it was cut from S (projection_target), so that a moved S is cut alike.
// Output   the moved mesh (tets may be tangled: step 4 untangles them), the parameterizations, and
//          statistics: how far nodes moved, how far they are from S afterwards, inverted tets.
// Errors   UncoveredSurfaceError (a MeshingError) if the rim gap exceeds options.max_rim_gap (the message
//          names the rim vertex of S farthest from S_M); MeshingError if S_M's rim runs on the box in other
//          arcs than S's, or touches it at a node whose rim edges do not run on it; MeshingError from the
//          parameterization (rim not one loop, corners impossible, map not one-to-one).
#pragma once

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/mesh/tet_mesh.hpp>
#include <meccano/stages/parameterization.hpp>
#include <meccano/stages/volumetric_approximation.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/creases.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <array>
#include <limits>
#include <memory>
#include <span>
#include <vector>

namespace meccano {

struct ProjectionStats {
  std::int64_t nodes = 0;  // S_M nodes moved
  std::int64_t rim_nodes = 0;
  double largest_move = 0.0;            // physical distance, x_i - x_Mi
  double largest_distance_after = 0.0;  // of a moved node to S (round-off)
  double rim_gap = 0.0;                 // RimGap::distance, before the move
  std::int64_t inverted_tets = 0;       // after the move, before smoothing
  CreaseStats creases;
};

struct ProjectionOptions {
  FloaterWeights weights = FloaterWeights::mean_value;
  double crease_angle = default_crease_angle;  // degrees; creases of S sharper than this are followed (180: none)
  // Physical distance; the pipeline sets max_rim_gap_in_resolutions l_r (stages/pipeline.hpp).
  double max_rim_gap = std::numeric_limits<double>::infinity();
};

// S_M leaves part of S uncovered: its rim gap exceeds ProjectionOptions::max_rim_gap.
class UncoveredSurfaceError : public MeshingError {
 public:
  using MeshingError::MeshingError;
};

// How far S's rim strays from S_M's: the rim vertex of S farthest from the polyline of S_M's rim, and
// that distance. A healthy S_M reaches beyond S's rim by up to about V_M's reach (a few l_r); it falls
// short where S is narrower than V_M's cubes, whose S_M faces have every node on the rim or beyond it.
struct RimGap {
  double distance = 0.0;
  int vertex = -1;  // of S
};
RimGap rim_gap(std::span<const Eigen::Vector3d> surface_points, std::span<const int> surface_rim,
               std::span<const Eigen::Vector3d> approximation_points, std::span<const int> approximation_rim);

// on_rim of a rim node pinned in P (a RimAnchor): where S_M's rim passes from one box face to another or
// into the box. Like P's corners, it stays where it is.
inline constexpr std::uint8_t pinned_rim_node = 2;

// What step 4 needs to move S_M nodes within S: φ, and each S_M node's parameters.
struct SurfaceProjection {
  int surface_index = -1;  // the surface whose S_M this is: its faces are interface_tag(surface_index)
  std::unique_ptr<ParametricSurface> surface;  // φ: P -> S
  std::vector<VertexId> nodes;                 // the S_M nodes
  std::vector<Eigen::Vector2d> uv;             // their parameters (same order)
  std::vector<std::uint8_t> on_rim;            // same order: 0 off the rim, 1 on it, pinned_rim_node
  std::vector<std::array<int, 3>> triangles;   // S_M's triangles as indices into `nodes`, oriented like S
  int orientation = 1;                         // the sign of their areas in P (uv), which step 4 keeps
  CreaseNodes creases;                         // which nodes lie on a crease line of S, and where
  ProjectionStats stats;
  // For one half of a closed S (empty for a disk): the half's triangles over S's points and the cut's
  // crossings, which lie on S's edges as `cut_crossings` say, before its rim chords were split.
  std::vector<EdgeCrossing> cut_crossings;
  std::vector<std::array<int, 3>> cut_triangles;
};

// Whether S_M's triangle (indices of `projection.nodes`) keeps S_M's orientation in P with its node `moved`
// at `uv` (the others at their parameters), with an area in P above `least_area`: what steps 3-4 and the
// improvement keep for every triangle.
bool keeps_orientation(const SurfaceProjection& projection, const std::array<int, 3>& triangle, int moved,
                       const Eigen::Vector2d& uv, double least_area = 0.0);

SurfaceProjection project_onto_surface(TetMesh& mesh, const TetRegion& volumetric, int index, int side,
                                       const TriangleSurface& surface, const TriangleBVH& tree,
                                       const ProjectionOptions& options = {});

// A closed S_M (side +1) onto a closed `surface`: the projections of its two halves, below and above the
// cut. The nodes on the cut are in both. Throws MeshingError if no coordinate plane cuts both S_M and S
// into two disks, besides the errors of project_onto_surface.
std::vector<SurfaceProjection> project_closed_onto_surface(TetMesh& mesh, const TetRegion& volumetric, int index,
                                                           const TriangleSurface& surface, const TriangleBVH& tree,
                                                           const ProjectionOptions& options = {});

// Every S_M node of `projection` moves to φ of its parameters; a rim node on the box keeps its coordinates
// on its box planes exactly (S's rim lies on them). Sets the statistics' node count, largest move and
// largest distance to S (`tree`) afterwards.
void move_nodes_onto_surface(TetMesh& mesh, SurfaceProjection& projection, const TriangleBVH& tree);

// The disk `projection` maps S_M onto, made from `surface`: S at its current points, triangulated as when
// the projection was made. S with its rim chords split, or for a half of a closed S that half, cut along
// the same edges of S at the same fractions (so a moved surface gives the same parametric triangles).
TriangleSurface projection_target(const SurfaceProjection& projection, const TriangleSurface& surface);

}  // namespace meccano
