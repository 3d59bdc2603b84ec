// Step 4 of the method (paper §4.4): simultaneous untangling and smoothing (SUS).
//
// Input    the mesh right after projection (tets may be inverted), and each surface's projection: its
//          φ and each S_M node's parameters (stages/projection.hpp).
// Method   Every free node in turn minimises the sum, over the tets around it, of the regularised
//          distortion η* = ||S||_F^2 / (3 h(σ)^(2/3)), S = A W^-1, σ = det S, h(σ) = (σ + √(σ² + 4δ²)) / 2
//          (eqs. 5-7): A is the tet's physical edge matrix and W the target's, by default the tet's own
//          computational (meccano) counterpart, so an untouched tet is already optimal. h keeps η* finite
//          and smooth through σ = 0, so inverted tets are pushed out of inversion by the same descent that
//          improves valid ones. δ = max(√(ε(ε − σ_min)), 1e-4 · mean|σ|) over the node's star (Escobar et
//          al.'s rule with the authors' floor), ε = 1e-3 · mean|σ| (see stages/smoothing.cpp for why not theirs),
//          raised ten-fold on tangled stars while untangling stalls.
//          While tets are inverted the objective is the paper's sum; once a sweep ends with none, it
//          becomes Σ η*^p with p = `power` (the p-norm of Escobar et al. 2003, of which the paper's sum is
//          p = 1), which weighs the worst tets more: on the cube example p = 4 raises the minimum quality
//          from 0.29 to 0.40 and lowers the mean by 0.01 (doc/results.md).
//          Each node takes a few Newton steps with the analytic gradient and Hessian (its eigenvalues made
//          positive where it is not convex), steps of at most half the star's edge length, and a
//          backtracking (Armijo) line search.
// Freedom  inner nodes move in R³; nodes on a box side move in its plane, on a box edge along it, box
//          corners are fixed. S_M nodes move in P = [0,1]² and sit at φ(u): the gradient and Hessian reach
//          u by the chain rule through dφ/du, and every trial point is located again in φ's parametric
//          triangulation (a short walk from the last triangle); a step that would fold one of S_M's
//          triangles in P, or shrink it below 1 % of its area in P when smoothing began, is refused, so
//          S_M stays embedded in S and no two of its nodes slide onto one point. Rim nodes of S move
//          along their side of P, that is along the rim of S, keeping 30 % of their gap along it to each
//          rim neighbour when smoothing began, and the four corners of P stay fixed: a
//          fixed rim would keep the chord-length spacing of the projection, which ignores the volume mesh
//          behind it. Nodes on a crease of S (surface/creases.hpp) move along their crease line of P,
//          strictly inside it: they stay on the crease edges of S.
// Sweeps   non-linear Gauss-Seidel. Nodes are coloured so that no two nodes of one colour share a tet;
//          the nodes of a colour are optimised in parallel, so the result does not depend on the thread
//          count. A node is skipped when neither it nor any node of its star moved (by more than 1 % of
//          its star's edge length) since it was last optimised. The sweeps stop after `smoothing_sweeps`
//          sweeps that end with no inverted tet (the authors' rule), or earlier once such a sweep lowers
//          the objective by less than `tolerance` (relative), or after `max_sweeps` sweeps. Untangling
//          gives up earlier, once `stalled_sweeps` sweeps in a row have not lowered the fewest inverted
//          tets so far and no fallback is left to try: a stuck attempt then costs about 40 sweeps, not
//          100, before the caller tries the other side or a finer l_r.
// Fallback If tets are still inverted after `fallback_sweeps` sweeps towards the meccano target, the
//          untangling goes on towards the equilateral target, and the smoothing sweeps that follow the
//          untangling aim at the meccano target again. Some projected S_M leave stars whose meccano shapes
//          cannot all be met (one inverted tet between two rim nodes on a small disk): untangling stalls
//          there for any number of sweeps, while the equilateral target untangles it at once
//          (doc/results.md, Step 4). Should the meccano smoothing tangle the mesh again, the equilateral
//          target is kept to the end.
// Modes    whole mesh (the paper), or a band: only nodes within `band_rings` edge rings of an S_M node.
// Output   the moved mesh and the surfaces' updated parameters; statistics per sweep, also passed to
//          `on_sweep` as each sweep ends. `untangled` is false if inverted tets remain: the caller must
//          not present that mesh as a result.
#pragma once

#include <meccano/mesh/quality.hpp>
#include <meccano/mesh/tet_mesh.hpp>
#include <meccano/stages/projection.hpp>

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace meccano {

enum class SmoothingTarget { meccano, equilateral };
enum class SmoothingMode { whole_mesh, band };

struct SweepRecord {
  std::int64_t inverted = 0;  // tets with σ <= 0 after the sweep
  std::int64_t nodes_optimised = 0;
  double min_quality = 0.0;  // 1/η against the target, over the tets of free nodes
  double mean_quality = 0.0;
  double power = 1.0;                                 // the exponent p the sweep minimised Σ η*^p with
  SmoothingTarget target = SmoothingTarget::meccano;  // the target of the sweep's W
  double objective = 0.0;                             // Σ η^p over those tets after the sweep
  double seconds = 0.0;
};

struct SmoothingOptions {
  SmoothingTarget target = SmoothingTarget::meccano;
  SmoothingMode mode = SmoothingMode::whole_mesh;
  int band_rings = 3;
  int max_sweeps = 100;
  int fallback_sweeps = 20;  // tangled sweeps towards the meccano target before the equilateral fallback; 0: never
  int smoothing_sweeps = 20;
  int stalled_sweeps = 20;  // tangled sweeps without a new fewest-inverted count before giving up (fallback done)
  double tolerance = 1e-3;
  double power = 4.0;    // p of Σ η*^p once untangled; 1 is the paper's objective
  int newton_steps = 2;  // per node and sweep
  // Called after each sweep with its number (from 1) and record, for progress on long runs (SUS can take
  // minutes without another stage line); nothing is done for it when empty. The sweeps do not depend on it.
  std::function<void(int sweep, const SweepRecord& record)> on_sweep = nullptr;
};

struct SmoothingStats {
  std::int64_t inner_nodes = 0;    // free nodes by freedom
  std::int64_t box_nodes = 0;      // on a box side or edge
  std::int64_t surface_nodes = 0;  // S_M nodes inside the rim
  std::int64_t rim_nodes = 0;      // S_M rim nodes, corners of P excluded
  std::int64_t crease_nodes = 0;   // S_M nodes on a crease line of S (stages/projection.hpp)
  std::int64_t active_tets = 0;    // tets with a free node
  int colours = 0;
  std::int64_t inverted_before = 0;
  std::int64_t inverted_after = 0;
  int untangling_sweeps = 0;  // sweeps until no tet was inverted (0 if none was)
  int fallback_sweep = 0;     // the first sweep towards the equilateral fallback target (0: none)
  std::vector<SweepRecord> sweeps;
  bool untangled() const { return inverted_after == 0; }
};

// η* of one tet, S = A W^-1 with A the edge matrix of `physical` (oriented order) and W^-1 given, and its
// gradient and Hessian with respect to the position of local vertex `vertex` (0..3). Infinite (and no
// derivatives) when h(σ) underflows to 0, which needs δ = 0 and σ < 0.
struct Distortion {
  double value = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
};
Distortion regularised_distortion(const TetPoints& physical, const Eigen::Matrix3d& target_inverse, int vertex,
                                  double delta);

// With options.max_sweeps = 0 no node moves and only the inverted tets are counted (the other counts stay 0).
SmoothingStats smooth_mesh(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                           const SmoothingOptions& options = {});

}  // namespace meccano
