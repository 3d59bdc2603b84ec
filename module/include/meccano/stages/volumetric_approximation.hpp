// Step 1 of the method (paper §4.1): the volumetric approximation V_M of an immersed surface S.
//
// Input    a conforming TetMesh (the cube meccano, possibly refined for other surfaces), S through its
//          TriangleBVH, and the resolution l_r > 0.
// Steps    1. V_M = the tets that intersect S. While some tet of V_M is coarser than the level L of
//             l_r (level_for_resolution: the coarsest bisection level whose tets all have l_T < l_r,
//             eq. 1 with l_T the longest edge), bisect those tets (Kossaczky, conforming closure) and
//             keep in V_M the children that still intersect S. Refining by level rather than by each
//             tet's own l_T gives V_M one level throughout: in cells that are not cubes, tets of one
//             level differ in l_T, and a V_M of two levels grew and tangled far more (doc/benchmarks.md,
//             "Predictable cost").
//          2. Grow V_M into a topological ball: add the star (all tets of M around it) of every
//             boundary node whose link in V_M is not a disk. The node Euler test of eq. 2,
//             χ = n_E − n_F + n_T = 1, is necessary; the link must also be connected and its triangles
//             around each link vertex must form one fan (eq. 2 alone accepts pinched links). Cavities
//             (components of the complement that V_M encloses) are filled.
//          In steps 2 and 3 a tet to be added that is coarser than level L, or with a node farther than
//          the reach from S, is bisected instead (and the step repeats), so V_M stays made of tets of
//          level L or finer with every node within reach of S. The reach (growth_reach) is l_r, or
//          the diagonal of the cubes of L's level (the cubes whose faces are the axis-parallel faces
//          of level L, which step 3 completes) when that is longer: at most √3 l_T(L) < √3 l_r.
//          Where the growth has to cross the offset at the reach, that bisection would never end (a
//          tet straddling the offset always has a child straddling it): a tet 16 times finer than
//          level L (finest_growth_levels) is added if its nodes are within the band 1.125 × reach,
//          and the growth fails if it needs one reaching beyond the band.
//          3. Grow V_M until every boundary face lies on a coordinate plane in computational
//             coordinates, by adding the tet across each face that does not; step 2 is then re-run,
//             until neither step changes V_M. If V_M then has disk links everywhere but a boundary
//             that is not a sphere (a handle), it is thickened by the stars of its boundary nodes and
//             the steps repeat.
// Output   per-tet membership of V_M, and counts of what each step did (with L and the reach).
// Invariants on return (check_ball): V_M is face-connected, every boundary node has a disk link, the
//          boundary is one closed 2-manifold with Euler characteristic 2, every boundary face is
//          axis-parallel; every tet meeting S is in V_M and has level L or finer, hence l_T < l_r;
//          every node of V_M is within the reach of S, or within 1.125 × reach at a node of a tet added
//          in the band (counted in band_tets).
// Errors   InputError for l_r <= 0; MeshingError if V_M cannot be made a ball within the pass limit, or
//          only by reaching beyond the band (the message names where).
#pragma once

#include <meccano/geometry/geometry.hpp>
#include <meccano/mesh/bisection.hpp>
#include <meccano/mesh/tet_mesh.hpp>

#include <cstdint>
#include <vector>

namespace meccano {

// Where V_M's growth crosses the offset of S at the reach, it stops bisecting at tets finest_growth_levels
// finer than V_M's level (4 halvings of every edge) and adds them if their nodes are within
// growth_band × reach of S (steps 2-3).
inline constexpr int finest_growth_levels = 12;
inline constexpr double growth_band = 1.125;

// How far from S the nodes of V_M may lie (steps 2-3): max(l_r, the diagonal of the cubes of the level
// of l_r), at most √3 l_r.
double growth_reach(const MeccanoGrid& meccano, double resolution);

// A ChildCallback that extends each region with the flag of the child's parent: bisection does not
// change the point set of a region.
ChildCallback region_follows_children(std::vector<TetRegion*> regions);

struct VolumetricOptions {
  double resolution = 0.0;  // l_r
  int max_growth_passes = 200;
};

struct VolumetricStats {
  int level = 0;       // L: the bisection level of V_M's tets (level_for_resolution)
  double reach = 0.0;  // growth_reach: how far from S V_M's nodes may lie
  int refinement_passes = 0;
  std::int64_t bisections = 0;
  std::int64_t intersection_tests = 0;
  std::int64_t tets_intersecting = 0;  // tets of V_M after refinement, before growth
  std::int64_t euler_node_stars = 0;   // nodes whose star was added by the link test
  std::int64_t cavity_tets = 0;
  std::int64_t axis_tets = 0;  // tets added to make the boundary axis-parallel
  int thickening_layers = 0;   // layers added to close handles the link test cannot see
  int growth_refinements = 0;  // times the growth bisected tets (coarse, or with nodes beyond l_r)
  std::int64_t band_tets = 0;  // tets of the finest growth level added with a node beyond the reach
  int growth_passes = 0;
  std::int64_t tets = 0;  // tets of V_M at the end
};

// Runs steps 1-3. `other_regions` (e.g. the V_M of surfaces inserted before) follow the refinement.
TetRegion approximate_volume(TetMesh& mesh, const TriangleBVH& surface, const VolumetricOptions& options,
                             VolumetricStats& stats, std::vector<TetRegion*> other_regions = {});

// Steps 2-3 alone, on any non-empty region: grows it into a ball with axis-parallel boundary faces.
// Given S, the tets added also keep every node within l_r of S (or the band, as above).
void grow_into_ball(TetMesh& mesh, TetRegion& region, const VolumetricOptions& options, VolumetricStats& stats,
                    std::vector<TetRegion*> other_regions = {}, const TriangleBVH* surface = nullptr);

struct BallCheck {
  bool nonempty = false;
  bool connected = false;
  std::int64_t non_disk_links = 0;      // boundary nodes whose link in the region is not a disk
  std::int64_t non_manifold_edges = 0;  // boundary edges not in exactly two boundary faces
  int boundary_components = 0;
  std::int64_t boundary_euler = 0;  // V - E + F of the boundary surface
  std::int64_t non_axis_faces = 0;  // boundary faces not on a coordinate plane
  bool is_ball() const {
    return nonempty && connected && non_disk_links == 0 && non_manifold_edges == 0 && boundary_components == 1 &&
           boundary_euler == 2;
  }
};

BallCheck check_ball(const TetMesh& mesh, const TetRegion& region);

}  // namespace meccano
