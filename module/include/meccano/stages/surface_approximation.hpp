// Step 2 of the method (paper §4.2): the surface approximation S_M of an immersed surface S, healed
// until it is a disk fit for projection onto S.
//
// Input    the mesh, V_M of S (stages/volumetric_approximation.hpp, a ball with axis-parallel boundary faces),
//          S through its TriangleBVH, and the surface's index k.
// Build    1. Label every boundary node of V_M with its side of S (TriangleBVH::side: the sign of
//             (x - p)·n at the closest point p with an angle-weighted pseudo-normal n; a node closer
//             to S than 1e-12 of its size counts as on the positive side). A node whose closest
//             point is on the rim of S and which lies more than 45 degrees off the normal there is
//             beyond the rim and gets no side: there a tangent plane, not S, would decide. Where S is
//             narrower than V_M's tets (a strip or sharp tip that fits in its cubes; surface/narrow_rim.hpp,
//             at the longest edge of V_M's tets) the rim does not count: nearly every node around such a
//             part lies beyond the rim, and S_M would leave it uncovered.
//          2. S_M = the boundary faces of V_M, off the box boundary, whose 3 nodes are on the chosen
//             side. Keep its largest edge-connected component and fill its holes (components of the
//             rest of ∂V_M other than the largest): beyond the rim of S the side is decided by a
//             tangent plane, and stray faces there are noise, not surface.
//          3. Extend S_M until its rim edges are axis-parallel (computational coordinates): add the
//             boundary face of V_M across every oblique rim edge. S_M is then a union of whole squares
//             (cube faces), so every removal below removes whole squares: a face goes with the faces
//             across its oblique edges.
// Heal     repeat until nothing changes, the six rules of the paper:
//             remove corbels (two S_M faces sharing an edge, all of their nodes on the rim), except
//             those whose removal would cut S_M in pieces (a strip one square wide, where S is narrower
//             than the cubes: the part beyond would be dropped as stray); the dividing-edge rule below
//             splits their squares instead;
//             rim nodes in 5 or more S_M faces whose fan turns by more than 180 degrees (reflex rim
//             corners) are filled with the squares S_M lacks there if those lie on this side of S or
//             beyond its rim, and otherwise left as they are. The paper removes them; removal cuts a
//             notch whose corners are reflex again, and the cascade ate most of S_M on curved
//             surfaces (doc/results.md). Nodes in 5 or more faces with a flat fan (where the rim
//             crosses a step of the staircase) are not defects;
//             refine (bisect) tets with more than one face in S_M;
//             refine triangles of M with more than one edge on the rim (split their longest edge);
//             refine edges joining a node of S_M to a node of another S_M or of the box boundary;
//             refine dividing edges (edges off the rim joining two rim nodes);
//             beyond the paper, refine chord edges (edges off S_M joining two of its nodes, not both on
//             the rim): projection lays a chord on S with all its tets on one side, so some would stay
//             inverted whatever SUS does;
//          each pass re-applying steps 2-3 (component and hole clean-up, axis-parallel rim).
//          Refinement is Kossaczky bisection: the mesh stays conforming; V_M and the other surfaces'
//          regions follow through the child callback; S_M follows as a face tag.
// Side     by default +1 (the side S's normals point to) is tried first; if healing fails, the other
//          side is tried on the mesh as refined so far (SideRule chooses the order or one side only).
// Closed   a closed S (surface/closed_surface.hpp, its normals pointing out) has V_M enclosing it (its
//          inside is a cavity of the tets that meet S, which step 1 fills), every boundary node of V_M on
//          the positive side, and S_M all of V_M's boundary: a sphere. Only the positive side is tried,
//          whatever the SideRule; the rules about the rim find nothing; the others apply as they are.
// Box      where S is clipped by the box (its rim runs on the box faces), V_M reaches the box along that rim,
//          and so does S_M: the nodes of V_M on the box beside S's rim there take the side of S's normal (S
//          went on beyond the box), S_M's rim nodes may lie on the box, and edges from S_M to the box are
//          not refined. An S_M node on the box off S_M's rim is still a defect. Whether S_M's rim runs on
//          the box faces along the same arcs as S's is checked by the projection (stages/projection.hpp).
// Output   S_M as the faces tagged interface_tag(k), and the statistics of every rule.
// Invariants on return (check_surface_approximation): S_M is one connected manifold disk (Euler
//          characteristic 1, one rim loop, no pinched node), or sphere for a closed S (2, no rim), every rim edge is axis-parallel, no corbel,
//          tet with two faces in S_M, triangle with two rim edges, cross-surface, dividing or chord edge
//          remains; no S_M node is on another S_M, or on the box boundary unless it is a rim node of a
//          surface clipped by the box. Reflex rim corners that
//          could not be filled are counted, not forbidden.
// Errors   MeshingError naming the rule that did not converge, or the defect that remains, if neither
//          side heals within the pass limit.
#pragma once

#include <meccano/geometry/geometry.hpp>
#include <meccano/io/mesh_writers.hpp>
#include <meccano/mesh/tet_mesh.hpp>
#include <meccano/stages/volumetric_approximation.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <array>
#include <string>
#include <vector>

namespace meccano {

// Which side of S S_M is built on: S's normals point to the positive side. The *_first rules try the
// other side when healing fails on the first; the *_only rules fail instead.
enum class SideRule { positive_first, negative_first, positive_only, negative_only };

struct SurfaceApproximationOptions {
  int max_healing_passes = 60;
  SideRule side_rule = SideRule::positive_first;
};

struct HealingStats {
  int side = 0;      // +1 or -1: the side of S that S_M lies on
  int attempts = 0;  // sides tried
  int passes = 0;
  std::int64_t initial_faces = 0;
  std::int64_t stray_faces = 0;      // removed by the component clean-up
  std::int64_t hole_faces = 0;       // added by hole filling
  std::int64_t extension_faces = 0;  // added to make the rim axis-parallel
  std::int64_t corbels = 0;
  std::int64_t reflex_corners_filled = 0;  // reflex rim corners filled with the squares S_M lacked
  std::int64_t filled_faces = 0;           // faces added by those fills
  std::int64_t reflex_corners_left = 0;    // reflex rim corners that could not be filled
  std::int64_t tets_with_two_faces = 0;
  std::int64_t triangles_with_two_rim_edges = 0;
  std::int64_t cross_surface_edges = 0;
  std::int64_t dividing_edges = 0;
  std::int64_t chord_edges = 0;  // beyond the paper: off S_M, between two of its nodes
  std::int64_t faces = 0;        // S_M faces at the end
  std::int64_t rim_nodes = 0;
  std::string first_side_failure;  // why the first side was abandoned, if it was
};

// Builds and heals S_M of surface `index` and tags its faces interface_tag(index).
HealingStats approximate_surface(TetMesh& mesh, TetRegion& volumetric, const TriangleSurface& surface,
                                 const TriangleBVH& tree, int index, const SurfaceApproximationOptions& options = {},
                                 const std::vector<TetRegion*>& other_regions = {});

// The faces of S_M (tag interface_tag(index)), each once, oriented like S: the normal (right-hand rule on
// the vertex order) points to the side of S that S_M lies on when side = +1, and away from it when
// side = -1, i.e. it always agrees with S's normals. `volumetric` tells the two tets of a face apart.
struct ApproximationFaces {
  std::vector<std::array<VertexId, 3>> triangles;
  std::vector<FaceRef> faces;  // the tet whose outward face normal is the triangle's normal
};
ApproximationFaces approximation_faces(const TetMesh& mesh, const TetRegion& volumetric, int index, int side);

struct SurfaceApproximationCheck {
  std::int64_t faces = 0;
  bool connected = false;
  std::int64_t non_manifold_edges = 0;
  std::int64_t pinched_nodes = 0;
  std::int64_t euler = 0;
  int rim_loops = 0;
  std::int64_t oblique_rim_edges = 0;
  std::int64_t corbels = 0;
  std::int64_t reflex_rim_corners = 0;  // reflex rim corners with 5 or more faces (reported, allowed)
  std::int64_t tets_with_two_faces = 0;
  std::int64_t triangles_with_two_rim_edges = 0;
  std::int64_t cross_surface_edges = 0;
  std::int64_t dividing_edges = 0;
  std::int64_t chord_edges = 0;
  std::int64_t nodes_on_box_or_other_surface = 0;
  bool is_disk() const {
    return faces > 0 && connected && non_manifold_edges == 0 && pinched_nodes == 0 && euler == 1 && rim_loops == 1;
  }
  // What S_M of a closed surface is: V_M encloses S, and S_M is all of V_M's boundary.
  bool is_sphere() const {
    return faces > 0 && connected && non_manifold_edges == 0 && pinched_nodes == 0 && euler == 2 && rim_loops == 0;
  }
  bool healed() const {
    return (is_disk() || is_sphere()) && oblique_rim_edges == 0 && corbels == 0 && tets_with_two_faces == 0 &&
           triangles_with_two_rim_edges == 0 && cross_surface_edges == 0 && dividing_edges == 0 && chord_edges == 0 &&
           nodes_on_box_or_other_surface == 0;
  }
  std::string describe() const;
};

// `rim_on_box`: S is clipped by the box (surface/box_clipping.hpp), so S_M's rim nodes may lie on the box.
SurfaceApproximationCheck check_surface_approximation(const TetMesh& mesh, const TetRegion& volumetric, int index,
                                                      bool rim_on_box = false);

}  // namespace meccano
