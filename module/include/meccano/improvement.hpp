// After step 4: lifting the worst tets (`--improve smooth`).
//
// Input    an untangled mesh after SUS (smoothing.hpp) and each surface's projection.
// Why      SUS minimises a sum over every star. Its end state depends on the path: a few tets can stay
//          nearly flat where untangling left them, in stars whose other tets are good (a tet of 0.1° on a
//          real fault at extent / 30, while the same run rounded differently ends at 8°). The sum hardly
//          notices one such tet among thousands once the sweeps stop.
// Method   Passes over the worst tets only: the tets whose equilateral mean ratio is below `threshold`
//          give the nodes to optimise; each takes up to `newton_steps` Newton steps on its star's
//          Σ η^p with p = `power` towards the equilateral tet, δ = 10^-4 of the σ of an ideal tet of each
//          tet's own size (small tets are seen as well as large ones), and accepts a step only if it lowers
//          that sum, does not lower the star's smallest exact equilateral mean ratio (max-min: the worst
//          tet of a star never gets worse) and keeps its smallest mean ratio against the meccano
//          counterparts (the paper's measure) where it is below `threshold`, or at least `threshold`
//          where it is above. So the mesh's equilateral minimum cannot fall, nor its meccano minimum
//          below min(before, threshold). Nodes move with the freedom SUS gives them (box nodes in their planes,
//          S_M nodes on S, rim nodes along the rim, crease nodes along the crease, S_M kept embedded).
//          Nodes are coloured as in SUS, so the result does not depend on the thread count. In band mode
//          only the band's nodes move, as in SUS.
// Output   the moved mesh, still valid and conforming (no topology changes: tags and the bisection
//          hierarchy are untouched), its S_M nodes still on S; statistics.
// Limits   smoothing alone: a tet whose four nodes cannot move (box corners, nodes of two surfaces) or
//          whose shape is fixed by S's own triangles stays as it is; flips and insertions (Stellar's
//          topological operations, `--improve topology` in issue 18) are not done.
#pragma once

#include <meccano/projection.hpp>
#include <meccano/smoothing.hpp>
#include <meccano/tet_mesh.hpp>

#include <cstdint>
#include <span>

namespace meccano {

struct ImprovementOptions {
  double threshold = 0.35;  // equilateral mean ratio below which a tet's nodes are optimised
  int max_passes = 10;
  int newton_steps = 8;     // per node and pass
  double power = 8.0;       // p of the star's Σ η^p
};

struct ImprovementStats {
  int passes = 0;
  std::int64_t tets_below_before = 0, tets_below_after = 0;  // tets under the threshold
  std::int64_t node_updates = 0;                             // nodes optimised, over all passes
  std::int64_t nodes_moved = 0;                              // of those, the ones that moved
  double min_quality_before = 0.0, min_quality_after = 0.0;  // smallest equilateral mean ratio
};

// `sus` gives the nodes that may move: those SUS moved (its mode and band); its other fields are unused.
ImprovementStats improve_worst_tets(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                                    const ImprovementOptions& options = {}, const SmoothingOptions& sus = {});

}  // namespace meccano
