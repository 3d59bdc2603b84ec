// After step 4: lifting the worst tets (`--improve smooth` and `--improve topology`).
//
// Input    an untangled mesh after SUS (stages/smoothing.hpp) and each surface's projection.
// Why      SUS minimises a sum over every star. Its end state depends on the path: a few tets can stay
//          nearly flat where untangling left them, in stars whose other tets are good (a tet of 0.1° on a
//          real fault at extent / 30, while the same run rounded differently ends at 8°). The sum hardly
//          notices one such tet among thousands once the sweeps stop. And smoothing alone cannot mend a
//          tet whose shape its connectivity fixes (four nodes nearly coplanar with no room to move).
// Smooth   Passes over the worst tets only: the tets whose equilateral mean ratio is below `threshold`
//          give the nodes to optimise; each takes up to `newton_steps` Newton steps on its star's
//          Σ η^p with p = `power` towards the equilateral tet, δ = 10^-4 of the σ of an ideal tet of each
//          tet's own size (small tets are seen as well as large ones), and accepts a step only if it lowers
//          that sum, does not lower the star's smallest exact equilateral mean ratio (max-min: the worst
//          tet of a star never gets worse) and keeps its smallest mean ratio against the meccano
//          counterparts (the paper's measure) where it is below `threshold`, or at least `threshold`
//          where it is above. So the mesh's equilateral minimum cannot fall, nor its meccano minimum
//          below min(before, threshold) (lowest_threshold() with the ladder below). Nodes move with the
//          freedom SUS gives them (box nodes in their planes, S_M nodes on S, rim nodes along the rim,
//          crease nodes along the crease, S_M kept embedded).
//          Nodes are coloured as in SUS, so the result does not depend on the thread count. In band mode
//          only the band's nodes move, as in SUS.
// Shapes   (min_dihedral > 0 or max_dihedral < 180) after those passes, in each round: Σ η^p hardly sees a
//          tet whose mean ratio is fine but whose dihedral angle is not (the cube example's 158° tets have
//          η = 0.41). The nodes of the tets with an angle outside [min_dihedral, max_dihedral] or a mean
//          ratio below `threshold` each take up to `ascent_steps` steps of a max-min ascent of their star's
//          worst shape_over_floors ratio (mesh/quality.hpp), along the nearest point of the hull of the
//          near-worst ratios' gradients, no further than the floors, until the star meets them. A step
//          must raise that worst ratio, keep every mean ratio (both measures) at least the mesh's minimum
//          after the Newton passes or its star's worst, and leave a node on S with its S_M triangles
//          tilted from S by at most max(5°, their tilt before) and sagging from it no more than before
//          (the interface's normals and distance to S). Rim, crease and fixed nodes stay. A node that did
//          not move is tried again only once a node of its star has moved.
// Topology (options.topology) rounds of flips between smoothing passes: each tet below `threshold`, worst
//          first, tries the 2-3 flip across each of its faces and the removal of each of its edges (the
//          ring of m = 3..max_ring tets around the edge replaced by the best of the 2m-4-tet
//          triangulations of the ring, found by dynamic programming over the ring polygon: the 3-2 and
//          4-4 flips are m = 3 and 4), and takes the one whose worst new tet is best, if that beats the
//          worst tet it removes (max-min, so the mesh's minimum never falls). Tagged faces are never
//          removed or made: a flip only crosses untagged interior faces and removes edges all of whose
//          faces are untagged interior faces, so the interface and box sides keep their triangles, tags
//          and nodes; no new tet may have its four vertices on one surface. Flipped tets are remeshed
//          (TetKind::bisectable() is false): the bisection hierarchy ends there, and their paper's measure
//          is taken against the equilateral tet. Serial, in a fixed order: the result does not depend on
//          the thread count.
// Caps     (options.topology) at the start of each round of flips: an S_M triangle with an angle wider
//          than `cap_angle` under a tet outside the shape passes' floors has its longest edge flipped
//          (edge removal with the other diagonal forced), if the new S_M triangles' widest angle is
//          narrower, S_M stays embedded in P and no less aligned with S, and no new tet is inverted or
//          poorer than both 0.1 and the worst tet it replaces; the round's smoothing then lifts them.
// Creases  (options.topology) first, before any smoothing pass: S_M edges that a crease of S still crosses
//          (surface/creases.hpp) are mended, by an edge flip inside S_M along the crease, by moving an end of the
//          edge onto it, or by splitting the edge there (a new S_M node on the crease, the tets around the
//          edge halved), when that aligns S_M's triangles there better with S and leaves no tet below both
//          what it replaces and max(0.1, the mesh's worst): conform_to_creases.
// Ladder   (first_threshold in (0, threshold)) the whole stage runs at first_threshold, then at threshold:
//          every pass, flip and guard above is local and max-min, so where it ends depends on its path. With
//          the higher threshold alone the many tets between the two take moves around the worst tets
//          before they are lifted, and can leave them stuck (benchmarks.md, "The threshold raised to 0.40,
//          the worst tets first"). A mesh with no tet below first_threshold has no worst tets to lift
//          first: it gets the stage at threshold alone (statistics' first_threshold 0).
// Output   the improved mesh, still valid and conforming, its S_M nodes still on S; statistics. With
//          `smooth` the topology and the bisection hierarchy are untouched.
// Limits   a tet whose four nodes cannot move and that no flip improves (box corners, nodes of two
//          surfaces, shapes fixed by S's own triangles) stays as it is; no edge contraction, multi-face
//          removal or vertex insertion away from creases, and no flips of box faces. A cap whose flip
//          would fold S_M in P or tilt it from S stays; a tet over a well-shaped S_M triangle whose free
//          node cannot rise, and tets on S's rim, are what the faults keep outside the floors. The flips
//          below the threshold choose by mean ratio alone, so they may narrow an angle.
#pragma once

#include <meccano/mesh/quality.hpp>
#include <meccano/mesh/tet_mesh.hpp>
#include <meccano/stages/projection.hpp>
#include <meccano/stages/smoothing.hpp>
#include <meccano/stages/volumetric_approximation.hpp>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

namespace meccano {

struct ImprovementOptions {
  double threshold = 0.40;  // equilateral mean ratio below which a tet is improved
  // When below `threshold`, the whole stage runs first with this threshold, then with `threshold`: the
  // worst tets are lifted before the many between the two take the passes' and flips' moves (a single
  // stage at 0.40 left a surface's worst tet at 0.25, where one at 0.35 first reached 0.40). 0: one stage;
  // one stage too when no tet is below it.
  double first_threshold = 0.35;
  int max_passes = 10;   // smoothing passes per round
  int newton_steps = 8;  // per node and pass
  double power = 8.0;    // p of the star's Σ η^p
  // Shape passes after the Newton passes: the nodes of tets with a dihedral angle below min_dihedral or
  // above max_dihedral (degrees), or a mean ratio below `threshold`, raise their star's worst shape
  // against these floors (max-min). 0 and 180: no shape passes.
  double min_dihedral = 15.0, max_dihedral = 150.0;
  int ascent_steps = 16;    // per node and shape pass
  bool topology = false;    // flips and edge removal between the smoothing passes
  int rounds = 3;           // topology: at most this many rounds of flips, each followed by smoothing
  int max_flip_passes = 4;  // flip passes per round
  int max_ring = 10;        // the most tets around an edge that edge removal considers
  // topology: S_M triangles with an angle wider than this (degrees) are caps, whose longest edge is
  // flipped where a tet around it is outside the shape passes' floors. 180: no cap flips.
  double cap_angle = 120.0;
  std::function<void(const std::string&)> progress;  // a line per smoothing pass and per flip pass, if set
  // The paper's measure is kept at least min(its minimum before, this): each stage's own threshold.
  double lowest_threshold() const { return first_threshold > 0.0 ? std::min(first_threshold, threshold) : threshold; }
  // What the shape passes aim at: the dihedral floors and `threshold`.
  ShapeFloors floors() const { return {min_dihedral, max_dihedral, threshold}; }
};

struct FlipStats {
  std::int64_t flips_2_3 = 0, flips_3_2 = 0, flips_4_4 = 0;
  std::int64_t edge_removals = 0;       // rings of 5 or more tets
  std::int64_t surface_edge_flips = 0;  // edge removals inside S_M: two interface triangles flipped
  std::int64_t cap_flips = 0;           // edge flips inside S_M that replace a cap (flip_surface_caps)
  std::int64_t crease_splits = 0;       // S_M edges split where a crease of S crosses them
  std::int64_t crease_moves = 0;        // S_M nodes moved onto a crease that crossed their edge
  std::int64_t tets_removed = 0, tets_created = 0;
  std::int64_t operations() const {
    return flips_2_3 + flips_3_2 + flips_4_4 + edge_removals + surface_edge_flips + cap_flips + crease_splits +
           crease_moves;
  }
  FlipStats& operator+=(const FlipStats& other);
};
FlipStats operator-(FlipStats a, const FlipStats& b);
std::string describe(const FlipStats& flips);  // "N 2-3, N 3-2, N 4-4 flips, N larger edge removals, ..."


struct ImprovementStats {
  // What the stage aimed at: its floors (floors.mean_ratio is the threshold) and, with the ladder, the
  // first stage's threshold (0: one stage).
  ShapeFloors floors;
  double first_threshold = 0.0;
  int passes = 0;                                            // smoothing passes, over all rounds
  int rounds = 0;                                            // topology: rounds with at least one flip
  std::int64_t tets_below_before = 0, tets_below_after = 0;  // tets under the threshold
  std::int64_t node_updates = 0;                             // nodes optimised, over all passes
  std::int64_t nodes_moved = 0;                              // of those, the ones that moved
  double min_quality_before = 0.0, min_quality_after = 0.0;  // smallest equilateral mean ratio
  int shape_passes = 0;                                      // over all rounds
  std::int64_t shape_node_updates = 0, shape_nodes_moved = 0;
  std::int64_t tets_outside_floors_before = 0, tets_outside_floors_after = 0;  // of the shape passes' floors
  FlipStats flips;                                                             // topology
  std::int64_t remeshed_tets = 0;                                              // tets left not bisectable
};

// `sus` gives the nodes that may move: those SUS moved (its mode and band); its other fields are unused.
// `regions` are per-tet flags (V_M of each surface, which orients its interface faces) that the flips
// carry over: a created tet takes the flags of the removed tet behind its interface faces, or behind
// another face of the cavity's boundary; a flip that would give an interface face V_M on both or neither
// side is not made.
ImprovementStats improve_worst_tets(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                                    const ImprovementOptions& options = {}, const SmoothingOptions& sus = {},
                                    std::span<TetRegion* const> regions = {});

// One round of flips alone (options.threshold, max_flip_passes, max_ring): what improve_worst_tets does
// between its smoothing passes with options.topology.
FlipStats flip_worst_tets(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                          std::span<TetRegion* const> regions = {}, const ImprovementOptions& options = {});

// Untangling by flips, for the pipeline when SUS leaves tets inverted (with options.topology): each inverted
// tet, worst first, takes the 2-3 flip or edge removal (S_M's own edges included, as in flip_worst_tets)
// whose worst new tet is best, if that beats the worst tet it removes and leaves no more tets inverted
// than it removes; passes repeat while they make any (at most max_flip_passes). Since a tangled mesh's
// cavities can overlap other tets, a flip that would make an edge or face some other tet has, or a chord
// (an edge between two nodes of one S_M that is not an S_M edge), is not made. Moves no node; SUS then
// runs again from the new connectivity.
FlipStats flip_inverted_tets(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                             std::span<TetRegion* const> regions = {}, const ImprovementOptions& options = {});

// What improve_worst_tets does first with options.topology: every S_M edge that a crease line of S crosses
// between its nodes (surface/creases.hpp, straddling_crossings) is mended, by moving one of its nodes onto the
// crossing or by splitting it there, whichever leaves the best worst tet, unless a tet would be inverted
// or poorer than both 0.1 and the worst tet it changes.
FlipStats conform_to_creases(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                             std::span<TetRegion* const> regions = {}, const ImprovementOptions& options = {});

}  // namespace meccano
