#include <meccano/stages/smoothing.hpp>

#include <meccano/stages/improvement.hpp>

#include <meccano/geometry/geometry.hpp>
#include <meccano/mesh/quality.hpp>

#include "mesh/topology_helpers.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

namespace meccano {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
// A node has up to 3 parameters; unused ones have zero columns in the Jacobian, hence zero gradient and
// Hessian entries, so the Newton step leaves them at 0.
using Parameters = Vector3d;
using Jacobian = Matrix3d;

constexpr double infinity = std::numeric_limits<double>::infinity();
// No move may shrink an S_M triangle in P below this fraction of its area when smoothing began. Without
// it, two rim nodes of Western Santa Cruz Island at E/50 slid onto one point (a triangle of area 3e-14 in P)
// and left the three tets between them flat for good; 1 %, 10 % and 30 % all untangle it and E/70 in
// 25-40 sweeps, and 1 % constrains the smoothing least (doc/benchmarks.md, "Western Santa Cruz Island
// without retries").
constexpr double uv_collapse_floor = 0.01;
// Nor bring a rim node nearer a rim neighbour, along their side of P, than this fraction of their gap
// when smoothing began. The area floor does not hold rim nodes apart: the third node of a rim triangle
// can lie close to the rim (a triangle with two rim edges is split through it, surface_approximation.hpp),
// and as it moves inward the triangle keeps its area while its rim edge shrinks. On the low-dip hard
// surface at extent / 100 two rim nodes met so (47 m to 0.4 m, l_r 236 m) and the tet between them and two
// free nodes stayed inverted for 41 sweeps until the side retry; with 10 % one such tet stayed, with 30 %
// the mesh untangled in 7 sweeps (doc/benchmarks.md, "Rim nodes kept apart").
constexpr double rim_gap_floor = 0.3;

// ---------------------------------------------------------------------------------------------------
// The distortion of one tet as a function of one of its vertices.
//
// With the vertex at x, S = A W^-1 is affine in x: dS = dx bᵀ with b = W^-T c, where c = e_k for local
// vertex k = 1..3 and c = -(1,1,1) for vertex 0 (A's columns are p_k - p_0). So N = ||S||² has gradient
// 2 S b and Hessian 2|b|² I, and σ = det S is linear in x with gradient cof(S) b. Writing r = √(σ² + 4δ²),
// h'(σ) = h / r, and for f = N / (3 h^(2/3)):
//   ∇f = f a,  a = ∇N / N - (2/3) ∇σ / r,
//   ∇²f = f (a aᵀ + 2|b|²/N I - ∇N ∇Nᵀ / N² + (2/3) σ / r³ ∇σ ∇σᵀ).

// The smallest of `measure` (a tet's mean ratio, mesh/quality.hpp) over `tets`, +∞ if there is none.
template <class Measure>
double smallest_over(std::span<const TetId> tets, const Measure& measure) {
  double smallest = infinity;
  const auto count = static_cast<std::int64_t>(tets.size());
#pragma omp parallel for schedule(static) reduction(min : smallest)
  for (std::int64_t i = 0; i < count; ++i) smallest = std::min(smallest, measure(tets[i]));
  return smallest;
}

// The smallest equilateral and meccano mean ratios over some tets.
struct MeanRatioMinima {
  double equilateral = 0.0, meccano = 0.0;
};

Matrix3d edge_matrix(const std::array<Vector3d, 4>& p) {
  Matrix3d a;
  a << p[1] - p[0], p[2] - p[0], p[3] - p[0];
  return a;
}

Matrix3d cofactor(const Matrix3d& s) {
  Matrix3d c;
  c << s.col(1).cross(s.col(2)), s.col(2).cross(s.col(0)), s.col(0).cross(s.col(1));
  return c;
}

double regularised_distortion(double frobenius_squared, double sigma, double delta) {
  // h = (σ + r) / 2 with r = √(σ² + 4δ²); for σ < 0 the equal form 2δ² / (r - σ) avoids cancellation.
  const double r = std::sqrt(sigma * sigma + 4.0 * delta * delta);
  const double h = sigma >= 0.0 ? 0.5 * (sigma + r) : 2.0 * delta * delta / (r - sigma);
  return h > 0.0 ? frobenius_squared / (3.0 * std::cbrt(h * h)) : infinity;
}

// One tet as a function of the free vertex's displacement d from where the star was taken. Only that
// vertex moves, so S changes by a rank-one term, S(d) = S0 + d bᵀ, and exactly (the matrix determinant
// lemma for σ):
//   N(d) = N0 + 2 d·u + |d|² β   with u = S0 b, β = |b|²;      σ(d) = σ0 + d·w   with w = cof(S0) b.
// Nine numbers per tet then give f, ∇f and ∇²f anywhere, with no vertex gathered and no matrix product:
// a node's Newton steps and line search cost a few flops per tet of its star.
struct StarTet {
  double n0 = 0.0, beta = 0.0, sigma0 = 0.0;
  Vector3d u = Vector3d::Zero(), w = Vector3d::Zero();
  double delta = 0.0;  // the regularisation of σ for this update (Smoother::set_deltas)

  double frobenius_squared(const Vector3d& d) const { return n0 + 2.0 * d.dot(u) + d.squaredNorm() * beta; }
  double sigma(const Vector3d& d) const { return sigma0 + d.dot(w); }
};

StarTet star_tet(const Matrix3d& s, const Matrix3d& target_inverse, int k) {
  const Vector3d b =
      k == 0 ? Vector3d(-target_inverse.colwise().sum().transpose()) : Vector3d(target_inverse.row(k - 1));
  return {s.squaredNorm(), b.squaredNorm(), s.determinant(), s * b, cofactor(s) * b};
}

double distortion_at(const StarTet& tet, const Vector3d& d) {
  return regularised_distortion(tet.frobenius_squared(d), tet.sigma(d), tet.delta);
}

// The exact distortion (δ = 0): infinite unless σ > 0.
double exact_distortion_at(const StarTet& tet, const Vector3d& d) {
  return regularised_distortion(tet.frobenius_squared(d), tet.sigma(d), 0.0);
}

// f, ∇f and ∇²f at d (no derivatives where f is infinite).
Distortion distortion_derivatives(const StarTet& tet, const Vector3d& d) {
  const double delta = tet.delta;
  Distortion f;
  const double n = tet.frobenius_squared(d);
  const double sigma = tet.sigma(d);
  f.value = regularised_distortion(n, sigma, delta);
  if (!std::isfinite(f.value)) return f;
  const double r = std::sqrt(sigma * sigma + 4.0 * delta * delta);
  const Vector3d grad_n = 2.0 * (tet.u + tet.beta * d);
  const Vector3d a = grad_n / n - (2.0 / 3.0) * tet.w / r;
  f.gradient = f.value * a;
  f.hessian =
      f.value * (a * a.transpose() + (2.0 * tet.beta / n) * Matrix3d::Identity() -
                 grad_n * grad_n.transpose() / (n * n) + (2.0 / 3.0) * sigma / (r * r * r) * tet.w * tet.w.transpose());
  return f;
}

// f^p, with the exponents SUS uses (1 while untangling, 4 after) spared a call to std::pow.
double raise(double f, double power) {
  if (power == 1.0) return f;
  if (power == 4.0) return (f * f) * (f * f);
  return std::pow(f, power);
}

// The star's worst exact distortion at d (infinite if a tet is inverted).
double worst_exact_distortion(std::span<const StarTet> tets, const Vector3d& d) {
  double largest = 0.0;
  for (const StarTet& tet : tets) largest = std::max(largest, exact_distortion_at(tet, d));
  return largest;
}

// Adds f^p and its derivatives: ∇(f^p) = p f^(p-1) ∇f, ∇²(f^p) = p f^(p-1) ∇²f + p(p-1) f^(p-2) ∇f ∇fᵀ.
void add_power(const Distortion& d, double power, Distortion& sum) {
  if (power == 1.0) {
    sum.value += d.value;
    sum.gradient += d.gradient;
    sum.hessian += d.hessian;
    return;
  }
  const double f = d.value;
  const double f_to_p = raise(f, power);
  sum.value += f_to_p;
  if (!std::isfinite(f)) return;
  const double first = power * f_to_p / f;
  sum.gradient += first * d.gradient;
  sum.hessian += first * d.hessian + (power - 1.0) * first / f * d.gradient * d.gradient.transpose();
}

// The Newton direction -H⁻¹g in a node's parameters (j: dx/dparameters, whose zero columns are parameters
// the node does not have), with H's eigenvalues made positive (|λ|, bounded away from 0) so that the
// direction descends even where the objective is not convex. Where H is positive definite with no tiny
// pivot that is plain Newton: a Cholesky solve gives it without the eigen-decomposition.
Parameters descent_direction(Matrix3d h, const Parameters& g, const Jacobian& j) {
  for (int i = 0; i < 3; ++i)
    if (j.col(i).squaredNorm() == 0.0) h(i, i) = 1.0;  // an unused parameter: g_i = 0, so its step is 0
  const Eigen::LLT<Matrix3d> cholesky(h);
  if (cholesky.info() == Eigen::Success && cholesky.matrixLLT().diagonal().cwiseAbs2().minCoeff() >= 1e-8 * h.trace())
    return -cholesky.solve(g);
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eigen(h);
  Parameters magnitudes = eigen.eigenvalues().cwiseAbs();
  const double floor = std::max(1e-8 * magnitudes.maxCoeff(), std::numeric_limits<double>::min());
  magnitudes = magnitudes.cwiseMax(floor);
  return -(eigen.eigenvectors() * (eigen.eigenvectors().transpose() * g).cwiseQuotient(magnitudes));
}

// ---------------------------------------------------------------------------------------------------
// How each node may move.

enum class Freedom : std::uint8_t { fixed, space, box, surface, rim, crease };

struct NodeFreedom {
  Freedom kind = Freedom::space;
  std::uint8_t free_axes = 7;  // box: bit i set if coordinate i may change
  std::uint8_t rim_axis = 0;   // rim: the parameter (0 = u, 1 = v) that runs along its side of P
  int surface = -1;            // surface, rim and crease: which projection, and the node's index in it
  int index = -1;
  const CreaseLine* crease = nullptr;  // crease: the line of P it moves along
};

// A rim node's neighbours along S_M's rim (node indices of its surface, -1 for none) and, per neighbour,
// the least signed difference of their parameters along the node's side of P (rim_gap_floor).
struct RimNeighbours {
  std::array<int, 2> node{-1, -1};
  std::array<double, 2> least_gap{0.0, 0.0};
};

// How far S_M's triangles around a node stray from S (Smoother::chord_stray).
struct ChordStray {
  double tilt = 0.0, sag = 0.0;  // radians, length
};

// Where a node is: its position and, on a surface, its parameters and the triangle holding them (and on
// a crease, its arc length along the line).
struct Placement {
  Vector3d x;
  Vector2d uv = Vector2d::Zero();
  int triangle = -1;
  double arc = 0.0;
};

class Smoother {
 public:
  Smoother(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces, const SmoothingOptions& options)
      : mesh_(mesh), surfaces_(surfaces), options_(options), stars_(vertex_to_tets(mesh)) {
    oriented_.resize(mesh.tets.size());
#pragma omp parallel for schedule(static)
    for (TetId t = 0; t < mesh.num_tets(); ++t) oriented_[t] = mesh.oriented_tet(t);
    aim_at(options.target);
    classify_nodes();
  }

  SmoothingStats run();
  // `only`, if not empty, limits the nodes optimised to those it flags (per vertex).
  ImprovementStats improve(const ImprovementOptions& options, std::span<const std::uint8_t> only = {});

 private:
  static Matrix3d equilateral_target() {
    Matrix3d w;
    w << 1.0, 0.5, 0.5, 0.0, std::sqrt(3.0) / 2.0, std::sqrt(3.0) / 6.0, 0.0, 0.0, std::sqrt(2.0 / 3.0);
    return w;
  }
  // Sets every tet's W^-1 for `target`. The meccano's tets come in few shapes (the bisection's, level by
  // level), so each W^-1 is kept once per shape, keyed by the tet's exact edge matrix in grid coordinates,
  // and a tet holds the index of its own: a node's star then reads a small table that stays in cache
  // instead of 72 bytes per tet from all over memory.
  void aim_at(SmoothingTarget target) {
    target_ = target;
    target_inverses_.clear();
    target_of_tet_.assign(mesh_.tets.size(), 0);
    if (target == SmoothingTarget::equilateral) {
      target_inverses_.push_back(equilateral_target().inverse());
      return;
    }
    std::map<std::array<std::int64_t, 9>, std::uint32_t> shape_index;
    // A remeshed tet has no meccano counterpart: the equilateral tet is its target.
    std::optional<std::uint32_t> equilateral_shape;
    for (TetId t = 0; t < mesh_.num_tets(); ++t) {
      if (!mesh_.bisectable(t)) {
        if (!equilateral_shape) {
          equilateral_shape = static_cast<std::uint32_t>(target_inverses_.size());
          target_inverses_.push_back(equilateral_target().inverse());
        }
        target_of_tet_[t] = *equilateral_shape;
        continue;
      }
      const auto& v = oriented_[t];
      std::array<std::int64_t, 9> edges;
      for (int k = 0; k < 3; ++k)
        for (int axis = 0; axis < 3; ++axis) edges[3 * k + axis] = mesh_.grid[v[k + 1]][axis] - mesh_.grid[v[0]][axis];
      const auto [shape, added] = shape_index.try_emplace(edges, static_cast<std::uint32_t>(target_inverses_.size()));
      if (added) target_inverses_.push_back(meccano_target_inverse(t));
      target_of_tet_[t] = shape->second;
    }
  }
  // W^-1 of tet t's meccano counterpart (its computational tet), or of the equilateral tet for a
  // remeshed one.
  Matrix3d meccano_target_inverse(TetId t) const {
    if (!mesh_.bisectable(t)) return equilateral_target().inverse();
    const auto& v = oriented_[t];
    Matrix3d w;
    for (int k = 0; k < 3; ++k)
      for (int axis = 0; axis < 3; ++axis)
        w(axis, k) = mesh_.meccano.cell_size[axis] *
                     static_cast<double>(mesh_.grid[v[k + 1]][axis] - mesh_.grid[v[0]][axis]) /
                     static_cast<double>(grid_cell);
    return w.inverse();
  }
  const Matrix3d& target_inverse(TetId t) const { return target_inverses_[target_of_tet_[t]]; }

  void classify_nodes();
  std::vector<VertexId> free_nodes() const;
  std::vector<std::vector<VertexId>> colour(const std::vector<VertexId>& nodes) const;
  template <class Visit>
  void for_each_star_vertex(VertexId v, Visit&& visit) const {
    for (TetId t : stars_.of(v))
      for (VertexId w : oriented_[t])
        if (w != v) visit(w);
  }

  // A, the edge matrix of tet t at the current positions, and S = A W^-1.
  Matrix3d physical_edges(TetId t) const {
    const auto& v = oriented_[t];
    return edge_matrix({mesh_.points[v[0]], mesh_.points[v[1]], mesh_.points[v[2]], mesh_.points[v[3]]});
  }
  Matrix3d s_matrix(TetId t) const { return physical_edges(t) * target_inverse(t); }
  // A node's star at its current position, and its mean edge length at the node (the scale of a
  // sensible step).
  struct Star {
    std::span<StarTet> tets;
    double mean_edge = 0.0;
    std::span<StarTet> guard;  // improving: the same tets against the meccano target (exact, δ = 0)
  };
  Star take_star(VertexId v) const;
  double star_objective(std::span<const StarTet> star, const Vector3d& d) const;
  Distortion star_derivatives(std::span<const StarTet> star, const Vector3d& d) const;
  bool set_deltas(std::span<StarTet> star) const;

  Placement placement(VertexId v) const;
  Jacobian jacobian(VertexId v, const Placement& at) const;
  bool move(VertexId v, const Placement& from, const Parameters& step, Placement& to) const;
  bool keeps_surface_embedded(const NodeFreedom& node, const Vector2d& uv) const;
  void find_rim_neighbours(int s);
  bool keeps_rim_gaps(const NodeFreedom& node, double along) const;
  bool optimise(VertexId v);
  bool lift_worst_shape(VertexId v);
  ChordStray chord_stray(VertexId v, const Placement& at) const;
  void store(VertexId v, const Placement& at);
  SweepRecord measure() const;

  // What run() keeps from one sweep to the next.
  struct SweepState {
    explicit SweepState(std::size_t vertices) : last_moved(vertices, 0), last_optimised(vertices, -1) {}
    void look_at_all_again() { std::fill(last_optimised.begin(), last_optimised.end(), -1); }
    // A node needs another look only if it or a node of its star moved since it was last optimised.
    std::vector<std::int64_t> last_moved, last_optimised;
    std::int64_t epoch = 0;
    int clean_sweeps = 0;
    std::int64_t fewest_inverted = std::numeric_limits<std::int64_t>::max();
    int stalled_sweeps = 0;  // since ε was last raised or the fewest inverted count lowered
    int sweeps_since_fewest = 0;
  };
  void count_free_nodes(std::span<const VertexId> nodes);
  void collect_active_tets(std::span<const VertexId> nodes);
  void switch_target(SmoothingTarget target, SweepState& state);
  void fall_back_if_stalled(int sweep, SweepState& state);
  std::int64_t optimise_colours(const std::vector<std::vector<VertexId>>& colours, SweepState& state);
  SweepRecord record_sweep(std::int64_t optimised, std::chrono::steady_clock::time_point start) const;
  std::optional<double> comparable_objective() const;
  bool untangling_stuck(const SweepRecord& record, SweepState& state);
  bool smoothing_done(int sweep, const SweepRecord& record, std::optional<double> previous_objective,
                      SweepState& state);
  // The exponent p of Σ η*^p: the paper's 1 while tangled, options_.power once a sweep ends untangled;
  // the improvement's own.
  double power() const { return improving_ ? improving_->power : tangled_ ? 1.0 : options_.power; }

  TetMesh& mesh_;
  std::span<SurfaceProjection* const> surfaces_;
  SmoothingOptions options_;
  VertexTets stars_;
  std::vector<std::array<VertexId, 4>> oriented_;
  SmoothingTarget target_ = SmoothingTarget::meccano;  // what the W^-1 are for now
  std::vector<Matrix3d> target_inverses_;              // one per shape of tet
  std::vector<std::uint32_t> target_of_tet_;
  bool returned_from_fallback_ = false;  // did the smoothing aim at the meccano target again after the fallback?
  std::vector<NodeFreedom> freedom_;
  std::vector<std::vector<int>> hints_;  // per surface and node: the triangle of φ^-1(S) last holding it
  std::vector<std::vector<int>> triangle_start_, node_triangles_;  // per surface: node -> S_M triangles (CSR)
  std::vector<std::vector<double>> least_uv_area_;                 // per surface and S_M triangle
  std::vector<std::vector<RimNeighbours>> rim_neighbours_;         // per surface and node (rim nodes only)
  std::vector<TetId> active_tets_;
  SmoothingStats stats_;
  bool tangled_ = true;  // did the last sweep end with inverted tets (or none ran yet)?
  static constexpr double initial_untangling_epsilon = 1e-3;
  double untangling_epsilon_ = initial_untangling_epsilon;  // ε / mean|σ|, raised while untangling stalls
  const ImprovementOptions* improving_ = nullptr;           // set while improve() runs
  ShapeFloors floors_;                                      // improving: what the shape passes aim at
  double shape_mean_ratio_floor_ = 0.0;                     // shape passes: no tet's η / threshold below it
  double shape_meccano_floor_ = 0.0;                        // shape passes: nor its meccano η below it
};

void Smoother::classify_nodes() {
  freedom_.assign(mesh_.points.size(), {});
  for (VertexId v = 0; v < mesh_.num_vertices(); ++v) {
    NodeFreedom& node = freedom_[v];
    const std::uint8_t planes = mesh_.meccano.box_planes(mesh_.grid[v]);
    for (int axis = 0; axis < 3; ++axis)
      if (planes & (3u << (2 * axis))) node.free_axes &= static_cast<std::uint8_t>(~(1u << axis));
    if (node.free_axes == 0) node.kind = Freedom::fixed;
    else if (node.free_axes != 7) node.kind = Freedom::box;
  }
  hints_.resize(surfaces_.size());
  triangle_start_.resize(surfaces_.size());
  node_triangles_.resize(surfaces_.size());
  least_uv_area_.resize(surfaces_.size());
  rim_neighbours_.resize(surfaces_.size());
  for (int s = 0; s < static_cast<int>(surfaces_.size()); ++s) {
    const SurfaceProjection& projection = *surfaces_[s];
    for (const auto& t : projection.triangles)
      least_uv_area_[s].push_back(uv_collapse_floor * std::abs(cross2(projection.uv[t[1]] - projection.uv[t[0]],
                                                                      projection.uv[t[2]] - projection.uv[t[0]])));
    hints_[s].assign(projection.nodes.size(), -1);
    std::vector<int>& start = triangle_start_[s];
    start.assign(projection.nodes.size() + 1, 0);
    for (const auto& triangle : projection.triangles)
      for (int i : triangle) ++start[i + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    node_triangles_[s].resize(start.back());
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int t = 0; t < static_cast<int>(projection.triangles.size()); ++t)
      for (int i : projection.triangles[t]) node_triangles_[s][fill[i]++] = t;
    for (int i = 0; i < static_cast<int>(projection.nodes.size()); ++i) {
      NodeFreedom& node = freedom_[projection.nodes[i]];
      // On another surface, or on the box off a rim that runs there: cannot follow both. A rim node on
      // the box slides along S's rim, which runs on the same box planes (stages/projection.hpp, "Box").
      const bool slides_on_box = node.kind == Freedom::box && projection.on_rim[i] == 1;
      if (node.kind != Freedom::space && !slides_on_box) {
        node.kind = Freedom::fixed;
        continue;
      }
      node.surface = s;
      node.index = i;
      node.kind = Freedom::surface;
      if (const int line = projection.creases.line_of[i]; line >= 0) {
        node.kind = Freedom::crease;
        node.crease = &projection.creases.lines[line];
        continue;
      }
      if (!projection.on_rim[i]) continue;
      // Rim parameters lie exactly on the square's sides; a corner of P lies on two and stays fixed.
      const Vector2d& uv = projection.uv[i];
      const bool u_on_side = uv.x() == 0.0 || uv.x() == 1.0;
      const bool v_on_side = uv.y() == 0.0 || uv.y() == 1.0;
      node.kind = (u_on_side && v_on_side) || projection.on_rim[i] == pinned_rim_node ? Freedom::fixed : Freedom::rim;
      node.rim_axis = u_on_side ? 1 : 0;
    }
    find_rim_neighbours(s);
  }
}

// Surface s's rim edges are the edges of one S_M triangle each; a sliding rim node keeps rim_gap_floor of
// its gap to each of its two neighbours along them.
void Smoother::find_rim_neighbours(int s) {
  const SurfaceProjection& projection = *surfaces_[s];
  detail::TopologyScratch scratch;
  detail::triangle_topology(projection.triangles, scratch);
  rim_neighbours_[s].assign(projection.nodes.size(), {});
  for (const detail::Edge& edge : scratch.boundary)
    for (const auto& [a, b] : {edge, std::pair{edge.second, edge.first}}) {
      const NodeFreedom& node = freedom_[projection.nodes[a]];
      if (node.kind != Freedom::rim || node.surface != s) continue;  // fixed, or on the other half's S_M
      RimNeighbours& neighbours = rim_neighbours_[s][a];
      const int k = neighbours.node[0] < 0 ? 0 : 1;
      neighbours.node[k] = b;
      neighbours.least_gap[k] = rim_gap_floor * (projection.uv[a][node.rim_axis] - projection.uv[b][node.rim_axis]);
    }
}

// Whether a rim node at `along` (its parameter along its side of P) keeps its gaps to its rim neighbours.
bool Smoother::keeps_rim_gaps(const NodeFreedom& node, double along) const {
  const RimNeighbours& neighbours = rim_neighbours_[node.surface][node.index];
  for (int k = 0; k < 2; ++k) {
    if (neighbours.node[k] < 0) continue;
    const double gap = along - surfaces_[node.surface]->uv[neighbours.node[k]][node.rim_axis];
    const double least = neighbours.least_gap[k];
    if (least > 0.0 ? gap < least : gap > least) return false;
  }
  return true;
}

std::vector<VertexId> Smoother::free_nodes() const {
  std::vector<std::uint8_t> wanted(mesh_.points.size(), options_.mode == SmoothingMode::whole_mesh);
  if (options_.mode == SmoothingMode::band) {
    std::vector<VertexId> ring;
    for (const SurfaceProjection* projection : surfaces_)
      for (VertexId v : projection->nodes) {
        wanted[v] = 1;
        ring.push_back(v);
      }
    for (int step = 0; step < options_.band_rings; ++step) {
      std::vector<VertexId> next;
      for (VertexId v : ring)
        for_each_star_vertex(v, [&](VertexId w) {
          if (!wanted[w]) {
            wanted[w] = 1;
            next.push_back(w);
          }
        });
      ring = std::move(next);
    }
  }
  std::vector<VertexId> nodes;
  for (VertexId v = 0; v < mesh_.num_vertices(); ++v)
    if (wanted[v] && freedom_[v].kind != Freedom::fixed) nodes.push_back(v);
  return nodes;
}

// Greedy colouring in node order: deterministic, and about as many colours as a node has neighbours.
std::vector<std::vector<VertexId>> Smoother::colour(const std::vector<VertexId>& nodes) const {
  std::vector<int> colour_of(mesh_.points.size(), -1);
  std::vector<std::vector<VertexId>> colours;
  std::vector<std::uint8_t> taken;
  for (VertexId v : nodes) {
    taken.assign(colours.size() + 1, 0);
    for_each_star_vertex(v, [&](VertexId w) {
      if (colour_of[w] >= 0) taken[colour_of[w]] = 1;
    });
    const int c = static_cast<int>(std::find(taken.begin(), taken.end(), 0) - taken.begin());
    if (c == static_cast<int>(colours.size())) colours.emplace_back();
    colours[c].push_back(v);
    colour_of[v] = c;
  }
  return colours;
}

// The star of v at its current position, in a buffer of the calling thread (nodes are optimised in
// parallel); valid until the thread takes the next star.
Smoother::Star Smoother::take_star(VertexId v) const {
  thread_local std::vector<StarTet> tets, guard;
  tets.clear();
  guard.clear();
  double edges = 0.0;
  int count = 0;
  for (TetId t : stars_.of(v)) {
    int local = 0;
    for (int i = 0; i < 4; ++i) {
      const VertexId w = oriented_[t][i];
      if (w == v) {
        local = i;
      } else {
        edges += (mesh_.points[w] - mesh_.points[v]).norm();
        ++count;
      }
    }
    const Matrix3d a = physical_edges(t);
    tets.push_back(star_tet(a * target_inverse(t), target_inverse(t), local));
    if (improving_) {  // computed here: a table per shape (aim_at) costs a pass over every tet
      const Matrix3d meccano = meccano_target_inverse(t);
      guard.push_back(star_tet(a * meccano, meccano, local));
    }
  }
  return {tets, edges / std::max(count, 1), guard};
}

double Smoother::star_objective(std::span<const StarTet> star, const Vector3d& d) const {
  double value = 0.0;
  for (const StarTet& tet : star) value += raise(distortion_at(tet, d), power());
  return value;
}

Distortion Smoother::star_derivatives(std::span<const StarTet> star, const Vector3d& d) const {
  Distortion sum;
  for (const StarTet& tet : star) add_power(distortion_derivatives(tet, d), power(), sum);
  return sum;
}

// Each tet's δ for the node's update, and whether the star holds an inverted tet.
// SUS: one δ per star, Escobar et al.'s rule δ = √(ε(ε − σ_min)) when σ_min < ε, with the authors' floor
// 1e-4 · mean|σ| (their code never lets δ reach 0). Their ε (2.2e-10 on a mesh scaled to radius 10) left
// the cube example with 5 tets inverted after 100 sweeps: each sat in a local minimum behind S.
// ε = 1e-3 · mean|σ| smooths the objective where the star is tangled and untangled it in 4 sweeps; on
// valid stars δ is the floor, so the smoothing itself is unchanged.
// Improvement: the star's floor exceeds the σ of tets far smaller than their neighbours, whose cost then
// falls with their size (N / 3δ^(2/3)) however flat they are; so each tet's floor is 1e-4 of the σ of an
// ideal tet of its own size, (‖S‖²/3)^(3/2), and small tets are seen as well as large ones.
bool Smoother::set_deltas(std::span<StarTet> star) const {
  double sigma_min = infinity, sigma_sum = 0.0;
  for (const StarTet& tet : star) {
    sigma_min = std::min(sigma_min, tet.sigma0);
    sigma_sum += std::abs(tet.sigma0);
  }
  const bool tangled = sigma_min <= 0.0;
  if (improving_) {
    for (StarTet& tet : star) tet.delta = 1e-4 * tet.n0 / 3.0 * std::sqrt(tet.n0 / 3.0);
    return tangled;
  }
  const double scale = sigma_sum / static_cast<double>(std::max<std::size_t>(star.size(), 1));
  // The raised ε is for tangled stars only: on a valid star it would soften the barrier that keeps it
  // valid, and untangling elsewhere would tangle it.
  const double epsilon = (tangled ? untangling_epsilon_ : initial_untangling_epsilon) * scale;
  const double untangling = sigma_min < epsilon ? std::sqrt(epsilon * (epsilon - sigma_min)) : 0.0;
  const double delta = std::max(untangling, 1e-4 * scale);
  for (StarTet& tet : star) tet.delta = delta;
  return tangled;
}

Placement Smoother::placement(VertexId v) const {
  Placement at{mesh_.points[v]};
  const NodeFreedom& node = freedom_[v];
  if (node.surface >= 0) {
    at.uv = surfaces_[node.surface]->uv[node.index];
    at.triangle = surfaces_[node.surface]->surface->locate(at.uv, hints_[node.surface][node.index]).triangle;
    if (node.kind == Freedom::crease) at.arc = surfaces_[node.surface]->creases.parameter[node.index];
  }
  return at;
}

// dx/d(parameters) at a placement.
Jacobian Smoother::jacobian(VertexId v, const Placement& at) const {
  const NodeFreedom& node = freedom_[v];
  Jacobian j = Jacobian::Zero();
  switch (node.kind) {
    case Freedom::space: return Jacobian::Identity();
    case Freedom::box:
      for (int axis = 0, column = 0; axis < 3; ++axis)
        if (node.free_axes & (1u << axis)) j(axis, column++) = 1.0;
      break;
    case Freedom::surface: j.leftCols<2>() = surfaces_[node.surface]->surface->derivative(at.triangle); break;
    case Freedom::rim: j.col(0) = surfaces_[node.surface]->surface->derivative(at.triangle).col(node.rim_axis); break;
    case Freedom::crease:
      // φ is continuous across the crease edge and affine along it: either triangle gives this column.
      j.col(0) = surfaces_[node.surface]->surface->derivative(at.triangle) * node.crease->direction(at.arc);
      break;
    case Freedom::fixed: break;
  }
  return j;
}

// The placement after a step in the node's parameters; false if it would leave the node's domain
// (the box, or the open square P for surface parameters: reaching P's boundary would put the node on
// the rim of S).
bool Smoother::move(VertexId v, const Placement& from, const Parameters& step, Placement& to) const {
  const NodeFreedom& node = freedom_[v];
  to = from;
  switch (node.kind) {
    case Freedom::space: to.x += step; return true;
    case Freedom::box: {
      const Box& box = mesh_.meccano.box;
      for (int axis = 0, column = 0; axis < 3; ++axis)
        if (node.free_axes & (1u << axis)) {
          to.x[axis] += step[column++];
          if (!(to.x[axis] > box.min[axis] && to.x[axis] < box.max[axis])) return false;
        }
      return true;
    }
    case Freedom::surface:
      to.uv += step.head<2>();
      if (!((to.uv.array() > 0.0).all() && (to.uv.array() < 1.0).all())) return false;
      break;
    case Freedom::rim:
      to.uv[node.rim_axis] += step[0];
      if (!(to.uv[node.rim_axis] > 0.0 && to.uv[node.rim_axis] < 1.0)) return false;
      if (!keeps_rim_gaps(node, to.uv[node.rim_axis])) return false;
      break;
    case Freedom::crease:
      // Strictly inside the line: its ends are where the crease fades or meets another one.
      to.arc += step[0];
      if (!(to.arc > 0.0 && to.arc < node.crease->length())) return false;
      to.uv = node.crease->at(to.arc);
      break;
    case Freedom::fixed: return false;
  }
  if (!keeps_surface_embedded(node, to.uv)) return false;
  const ParametricSurface& surface = *surfaces_[node.surface]->surface;
  const auto location = surface.locate(to.uv, from.triangle);
  to.triangle = location.triangle;
  to.x = surface.evaluate(location);
  for (int axis = 0; axis < 3; ++axis)  // a rim node on the box keeps its coordinates there exact
    if (!(node.free_axes & (1u << axis))) to.x[axis] = from.x[axis];
  return true;
}

// Whether S_M's triangles around a surface node keep their orientation in P with the node at uv. The
// tets alone do not guarantee it: S_M's triangles are chords of a curved S, and a triangle can fold in P
// while both its tets stay valid; the fold then locks its neighbours in place.
bool Smoother::keeps_surface_embedded(const NodeFreedom& node, const Vector2d& uv) const {
  const SurfaceProjection& projection = *surfaces_[node.surface];
  const auto& start = triangle_start_[node.surface];
  for (int k = start[node.index]; k < start[node.index + 1]; ++k)
    if (!keeps_orientation(projection, projection.triangles[node_triangles_[node.surface][k]], node.index, uv,
                           least_uv_area_[node.surface][node_triangles_[node.surface][k]]))
      return false;
  return true;
}

// A few safeguarded Newton steps on the node's star. The new position is kept however small the move.
// Any move of a node whose star was tangled counts (its neighbours get another look next sweep):
// untangling creeps. Elsewhere only a move beyond 1 % of the star's edge length counts, so sweeps stop
// revisiting regions that have settled, also while a few tets elsewhere are still being untangled
// (revisiting every node then made the last untangling sweeps cost as much as the first: twice the
// seconds per tet on faults whose last inverted tets took 20 sweeps).
bool Smoother::optimise(VertexId v) {
  const auto [star, length, guard] = take_star(v);
  const bool tangled_star = set_deltas(star);
  const Placement start = placement(v);
  Placement at = start;
  Distortion model = star_derivatives(star, Vector3d::Zero());
  // Improving: the star's worst exact distortion towards the equilateral tet, which no step may raise,
  // and towards the meccano targets, which may rise only up to 1 / threshold (so a star's meccano minimum
  // either stays or stays above the threshold, and the mesh's meccano minimum cannot fall below
  // min(before, threshold): the paper's measure is not traded away where it is already poor).
  double worst_at = improving_ ? worst_exact_distortion(star, Vector3d::Zero()) : 0.0;
  double guard_at =
      improving_ ? std::max(worst_exact_distortion(guard, Vector3d::Zero()), 1.0 / improving_->threshold) : 0.0;
  const int steps = improving_ ? improving_->newton_steps
                    : tangled_ ? 2 * options_.newton_steps
                               : options_.newton_steps;
  bool stalled = false;  // a Newton step found no acceptable point along its direction
  for (int step = 0; step < steps; ++step) {
    const double value = model.value;
    const Jacobian j = jacobian(v, at);
    const Parameters g = j.transpose() * model.gradient;
    if (!std::isfinite(value) || g.norm() * length <= 1e-12 * value) break;
    Parameters direction = descent_direction(j.transpose() * model.hessian * j, g, j);
    // At most half the star's edge length per step: the quadratic model means little beyond that.
    const double physical = (j * direction).norm();
    if (physical > 0.5 * length) direction *= 0.5 * length / physical;
    const double slope = g.dot(direction);
    // The line search evaluates the derivatives too, except after the last step: the next step needs them
    // where the trial is accepted, and the first trial (the Newton step) mostly is.
    const bool last = step + 1 == steps;
    Placement trial;
    Distortion at_trial;
    bool accepted = false;
    double worst_trial = 0.0, guard_trial = 0.0;
    for (double alpha = 1.0; alpha > 1e-6 && !accepted; alpha *= 0.5) {
      if (!move(v, at, alpha * direction, trial)) continue;
      const Vector3d d = trial.x - start.x;
      at_trial = last ? Distortion{star_objective(star, d)} : star_derivatives(star, d);
      accepted = at_trial.value <= value + 1e-4 * alpha * slope;
      if (accepted && improving_)
        accepted = (worst_trial = worst_exact_distortion(star, d)) <= worst_at &&
                   (guard_trial = worst_exact_distortion(guard, d)) <= guard_at;
    }
    if (!accepted) {
      stalled = true;
      break;
    }
    const double moved = (trial.x - at.x).norm();
    at = trial;
    model = at_trial;
    if (improving_) {
      worst_at = worst_trial;
      guard_at = std::max(guard_trial, 1.0 / improving_->threshold);
    }
    if (moved <= 1e-9 * length) break;
  }
  // Improving a surface node: Newton's model takes φ's derivative on one triangle of S in P. Where Floater's
  // map squeezes part of S into a thin strip of P (a rim trimmed along S's triangles, with ears and rim
  // chords: on Western Santa Cruz Island at E/50 an S_M node sat at v = 1.6e-7, φ's derivative 4.9e3 along u
  // and 9.0e6 along v), its step leaves P or crosses into triangles whose derivatives differ by orders of
  // magnitude, and the node stays where SUS left it however poor its star (a 2.8° tet there). So when a
  // Newton step found nothing and the node made no headway, straight moves in P towards its S_M neighbours'
  // parameters and their centroid are tried, and the one whose star's worst tet is best is taken if it
  // lowers the objective, raises the worst tet and keeps the meccano guard, as a Newton step must.
  if (improving_ && stalled && freedom_[v].kind == Freedom::surface && (at.x - start.x).norm() <= 1e-2 * length) {
    const NodeFreedom& node = freedom_[v];
    const SurfaceProjection& projection = *surfaces_[node.surface];
    const auto& first = triangle_start_[node.surface];
    std::vector<int> neighbours;
    for (int k = first[node.index]; k < first[node.index + 1]; ++k)
      for (const int w : projection.triangles[node_triangles_[node.surface][k]])
        if (w != node.index) neighbours.push_back(w);
    std::sort(neighbours.begin(), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
    std::vector<Vector2d> targets;
    Vector2d centroid = Vector2d::Zero();
    for (const int w : neighbours) {
      targets.push_back(projection.uv[w]);
      centroid += projection.uv[w] / static_cast<double>(neighbours.size());
    }
    targets.push_back(centroid);
    const Placement from = at;
    double best_worst = worst_at;
    for (const Vector2d& target : targets)
      for (double fraction = 0.5; fraction > 0.01; fraction *= 0.5) {
        Parameters step = Parameters::Zero();
        step.head<2>() = fraction * (target - from.uv);
        Placement trial;
        if (!move(v, from, step, trial)) continue;
        const Vector3d d = trial.x - start.x;
        const double worst_trial = worst_exact_distortion(star, d);
        if (worst_trial >= best_worst || star_objective(star, d) >= model.value ||
            worst_exact_distortion(guard, d) > guard_at)
          continue;
        at = trial;
        best_worst = worst_trial;
      }
  }
  const double moved = (at.x - start.x).norm();
  if (moved == 0.0) return false;
  store(v, at);
  return tangled_star || moved > 1e-2 * length;
}

// The shape passes' node update: a max-min ascent of the star's worst shape ratio (shape_over_floors: each
// dihedral angle and the mean ratio against its floor). The Newton passes' Σ η^p hardly sees a tet whose
// mean ratio is fine but whose dihedral angle is not: on the cube example at l_r = 1/64 the largest
// angles, 158°, are in tets of η = 0.41 standing on S_M triangles of 124°. So the worst ratio is raised
// directly. The gradients of the ratios within 0.02 of the worst are taken by differences in the node's
// own parameters (in space, on its box planes or on S; each scaled to a length by its column of
// dx/dparameters), and the step follows the point of their convex hull nearest the origin, no further
// than the floors. It is taken only if the star's worst ratio rises, no mean ratio falls below the mesh's
// minimum after the Newton passes (shape_mean_ratio_floor_; the paper's measure likewise, below its star's
// worst: shape_meccano_floor_), and a node on S leaves its S_M triangles tilted from S by at most
// max(5°, before) and sagging from it no more than before.
bool Smoother::lift_worst_shape(VertexId v) {
  // Rim and crease nodes stay: sliding along S's rim or crease lines moves the chords that follow those
  // lines, and the interface's distance to S with them (on the faults, its Hausdorff distance grew up to 18 %).
  const Freedom kind = freedom_[v].kind;
  if (kind == Freedom::fixed || kind == Freedom::rim || kind == Freedom::crease) return false;
  const auto [star, length, guard] = take_star(v);
  const double guard_at = std::max(worst_exact_distortion(guard, Vector3d::Zero()), 1.0 / shape_meccano_floor_);
  thread_local std::vector<std::pair<TetPoints, int>> tets;  // the star's points and v's place in each
  thread_local std::vector<double> ratios, trial_ratios;
  thread_local std::vector<Vector3d> gradients;
  thread_local std::vector<std::size_t> active;       // the ratios within active_band of the worst
  thread_local std::vector<std::size_t> active_tets;  // the tets (indices into `tets`) they belong to
  tets.clear();
  for (TetId t : stars_.of(v)) {
    TetPoints p;
    int local = 0;
    for (int i = 0; i < 4; ++i) {
      p[i] = mesh_.points[oriented_[t][i]];
      if (oriented_[t][i] == v) local = i;
    }
    tets.emplace_back(p, local);
  }
  // The ratios of tets[k] with v at x, into their places in `out` (the 7 of tets[k] from 7 k); returns
  // the smallest.
  constexpr std::size_t ratios_per_tet = 7;
  auto evaluate_tet = [&](std::size_t k, const Vector3d& x, std::vector<double>& out) {
    auto [p, local] = tets[k];
    p[local] = x;
    const auto tet_ratios = shape_over_floors(p, floors_);
    std::copy(tet_ratios.begin(), tet_ratios.end(), out.begin() + static_cast<std::ptrdiff_t>(ratios_per_tet * k));
    return *std::min_element(tet_ratios.begin(), tet_ratios.end());
  };
  // Every ratio of the star with v at x, into `out`; returns the smallest.
  auto evaluate = [&](const Vector3d& x, std::vector<double>& out) {
    out.resize(ratios_per_tet * tets.size());
    double smallest = infinity;
    for (std::size_t k = 0; k < tets.size(); ++k) smallest = std::min(smallest, evaluate_tet(k, x, out));
    return smallest;
  };
  // The ratios of the tets in active_tets alone: the gradient probes need the active ratios only, a few
  // tets of the star's 20 to 30.
  auto evaluate_active = [&](const Vector3d& x, std::vector<double>& out) {
    for (const std::size_t k : active_tets) evaluate_tet(k, x, out);
  };
  constexpr double active_band = 0.02;
  const double difference = 1e-7 * length;
  const Placement start = placement(v);
  Placement at = start, probe, trial;
  double worst_ratio = evaluate(at.x, ratios);
  auto smallest_mean_ratio = [](const std::vector<double>& of_star) {
    double smallest = infinity;
    for (std::size_t i = ratios_per_tet - 1; i < of_star.size(); i += ratios_per_tet)
      smallest = std::min(smallest, of_star[i]);
    return smallest;
  };
  // A node on S may slide only while its S_M triangles tilt from S no more than 5° or than before, and sag
  // from it no more than before: the interface's normals and its distance to S are what its users check.
  const ChordStray stray_before = chord_stray(v, start);
  const double tilt_allowed = std::max(stray_before.tilt, 5.0 * std::numbers::pi / 180.0);
  auto strays_no_further = [&](const Placement& moved_to) {
    const ChordStray stray = chord_stray(v, moved_to);
    return stray.tilt <= tilt_allowed && stray.sag <= stray_before.sag;
  };
  // Until the star meets the floors: beyond them the ascent would only trade the paper's measure (the
  // counterparts' shapes) for angles nobody asked for.
  for (int step = 0; step < improving_->ascent_steps && worst_ratio < 1.0; ++step) {
    const Jacobian j = jacobian(v, at);
    std::array<double, 3> scale{};
    active.clear();
    active_tets.clear();
    for (std::size_t i = 0; i < ratios.size(); ++i)
      if (ratios[i] < worst_ratio + active_band) {
        active.push_back(i);
        if (active_tets.empty() || active_tets.back() != i / ratios_per_tet) active_tets.push_back(i / ratios_per_tet);
      }
    trial_ratios.resize(ratios.size());  // evaluate_active fills only the active tets' places
    gradients.assign(active.size(), Vector3d::Zero());
    for (int k = 0; k < 3; ++k) {
      scale[k] = j.col(k).norm();
      if (scale[k] == 0.0) continue;
      double sign = 1.0;
      Parameters offset = Parameters::Zero();
      offset[k] = difference / scale[k];
      if (!move(v, at, offset, probe)) {
        sign = -1.0;
        if (!move(v, at, -offset, probe)) continue;
      }
      evaluate_active(probe.x, trial_ratios);
      for (std::size_t a = 0; a < active.size(); ++a)
        gradients[a][k] = sign * (trial_ratios[active[a]] - ratios[active[a]]) / difference;
    }
    const Vector3d direction = hull_point_nearest_origin(gradients);
    const double norm = direction.norm();
    if (!(norm > 1e-9 / length)) break;  // a max-min optimum within the node's freedom
    bool accepted = false;
    // The worst ratio rises at about `norm` per unit of length along the direction: no further than it
    // takes to reach the floors, so that nodes move no more than the angles need.
    const double first_reach = std::min(0.1 * length, (1.0 - worst_ratio) / norm);
    for (double reach = first_reach; reach > 1e-4 * length && !accepted; reach *= 0.5) {
      Parameters offset = Parameters::Zero();
      for (int k = 0; k < 3; ++k)
        if (scale[k] > 0.0) offset[k] = reach * direction[k] / (norm * scale[k]);
      if (!move(v, at, offset, trial)) continue;
      const double trial_worst = evaluate(trial.x, trial_ratios);
      accepted = trial_worst > worst_ratio + 1e-9 && smallest_mean_ratio(trial_ratios) >= shape_mean_ratio_floor_ &&
                 worst_exact_distortion(guard, trial.x - start.x) <= guard_at && strays_no_further(trial);
      if (accepted) worst_ratio = trial_worst;
    }
    if (!accepted) break;
    at = trial;
    std::swap(ratios, trial_ratios);
  }
  if (at.x == start.x) return false;
  store(v, at);
  return true;
}

// How far S_M's triangles around surface node v, with v at `at`, stray from S: the largest angle between
// a triangle and S at its parametric centroid, and the largest distance between the triangle's centroid
// and that point of S (its sag). Zero for a node off the surfaces.
ChordStray Smoother::chord_stray(VertexId v, const Placement& at) const {
  const NodeFreedom& node = freedom_[v];
  if (node.surface < 0) return {};
  const SurfaceProjection& projection = *surfaces_[node.surface];
  const ParametricSurface& surface = *projection.surface;
  const auto& start = triangle_start_[node.surface];
  double smallest_cosine = 1.0;
  ChordStray stray;
  for (int k = start[node.index]; k < start[node.index + 1]; ++k) {
    const auto& corners = projection.triangles[node_triangles_[node.surface][k]];
    std::array<Vector3d, 3> x;
    Vector2d centroid = Vector2d::Zero();
    for (int i = 0; i < 3; ++i) {
      const bool moved = corners[i] == node.index;
      x[i] = moved ? at.x : mesh_.points[projection.nodes[corners[i]]];
      centroid += (moved ? at.uv : projection.uv[corners[i]]) / 3.0;
    }
    const auto location = surface.locate(centroid, at.triangle);
    stray.sag = std::max(stray.sag, ((x[0] + x[1] + x[2]) / 3.0 - surface.evaluate(location)).norm());
    smallest_cosine = std::min(smallest_cosine, surface.alignment(x, location.triangle));
  }
  stray.tilt = std::acos(std::clamp(smallest_cosine, -1.0, 1.0));
  return stray;
}

void Smoother::store(VertexId v, const Placement& at) {
  mesh_.points[v] = at.x;
  const NodeFreedom& node = freedom_[v];
  if (node.surface >= 0) {
    surfaces_[node.surface]->uv[node.index] = at.uv;
    hints_[node.surface][node.index] = at.triangle;
    if (node.kind == Freedom::crease) surfaces_[node.surface]->creases.parameter[node.index] = at.arc;
  }
}

// Inverted tets and the target quality over the active tets (per-tet values first, then a serial sum, so
// the result does not depend on the thread count).
SweepRecord Smoother::measure() const {
  std::vector<double> distortion(active_tets_.size());
  const auto count = static_cast<std::int64_t>(active_tets_.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < count; ++i) {
    const TetId t = active_tets_[i];
    const Matrix3d s = s_matrix(t);
    const double sigma = s.determinant();
    distortion[i] = sigma > 0.0 ? s.squaredNorm() / (3.0 * std::cbrt(sigma * sigma)) : infinity;
  }
  SweepRecord record;
  record.min_quality = 1.0;
  for (double eta : distortion) {
    const double q = std::isfinite(eta) ? 1.0 / eta : 0.0;
    record.inverted += q == 0.0;
    record.min_quality = std::min(record.min_quality, q);
    record.mean_quality += q;
    record.objective += raise(eta, power());
  }
  if (count > 0) record.mean_quality /= static_cast<double>(count);
  return record;
}

// Counts the free nodes by how they may move, for the stats.
void Smoother::count_free_nodes(std::span<const VertexId> nodes) {
  for (VertexId v : nodes) {
    switch (freedom_[v].kind) {
      case Freedom::space: ++stats_.inner_nodes; break;
      case Freedom::box: ++stats_.box_nodes; break;
      case Freedom::surface: ++stats_.surface_nodes; break;
      case Freedom::rim: ++stats_.rim_nodes; break;
      case Freedom::crease: ++stats_.crease_nodes; break;
      case Freedom::fixed: break;
    }
  }
}

// The tets of the free nodes' stars: those the sweeps measure.
void Smoother::collect_active_tets(std::span<const VertexId> nodes) {
  std::vector<std::uint8_t> active(mesh_.tets.size(), 0);
  for (VertexId v : nodes)
    for (TetId t : stars_.of(v)) active[t] = 1;
  for (TetId t = 0; t < mesh_.num_tets(); ++t)
    if (active[t]) active_tets_.push_back(t);
  stats_.active_tets = static_cast<std::int64_t>(active_tets_.size());
}

// A new target changes every node's objective: all of them get another look.
void Smoother::switch_target(SmoothingTarget target, SweepState& state) {
  aim_at(target);
  state.look_at_all_again();
}

void Smoother::fall_back_if_stalled(int sweep, SweepState& state) {
  if (tangled_ && target_ == SmoothingTarget::meccano && options_.fallback_sweeps > 0 &&
      (sweep > options_.fallback_sweeps || returned_from_fallback_)) {
    // Untangling towards the meccano target stalled (or its smoothing tangled the mesh again).
    switch_target(SmoothingTarget::equilateral, state);
    if (stats_.fallback_sweep == 0) stats_.fallback_sweep = sweep;
    untangling_epsilon_ = initial_untangling_epsilon;
    state.fewest_inverted = std::numeric_limits<std::int64_t>::max();
    state.stalled_sweeps = state.sweeps_since_fewest = 0;
  }
}

// Optimises the nodes that need another look, one colour after the other, the nodes of a colour in
// parallel. How many were optimised.
std::int64_t Smoother::optimise_colours(const std::vector<std::vector<VertexId>>& colours, SweepState& state) {
  std::vector<std::int64_t>& last_moved = state.last_moved;
  std::vector<std::int64_t>& last_optimised = state.last_optimised;
  std::int64_t optimised = 0;
  for (const auto& group : colours) {
    const std::int64_t epoch = ++state.epoch;
    const auto size = static_cast<std::int64_t>(group.size());
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : optimised)
    for (std::int64_t i = 0; i < size; ++i) {
      const VertexId v = group[i];
      std::int64_t latest = last_moved[v];
      for_each_star_vertex(v, [&](VertexId w) { latest = std::max(latest, last_moved[w]); });
      if (latest < last_optimised[v]) continue;
      last_optimised[v] = epoch;
      ++optimised;
      if (optimise(v)) last_moved[v] = epoch;
    }
  }
  return optimised;
}

// The record of the sweep begun at `start`, measured now.
SweepRecord Smoother::record_sweep(std::int64_t optimised, std::chrono::steady_clock::time_point start) const {
  SweepRecord record = measure();
  record.nodes_optimised = optimised;
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  record.power = power();
  record.target = target_;
  return record;
}

// The last sweep's objective, if the next sweep's can be compared with it: both used the same power and W.
std::optional<double> Smoother::comparable_objective() const {
  const bool comparable = !stats_.sweeps.empty() && stats_.sweeps.back().power == power() &&
                          stats_.sweeps.back().target == target_ && stats_.sweeps.back().inverted == 0;
  return comparable ? std::optional<double>(stats_.sweeps.back().objective) : std::nullopt;
}

// After a sweep that left tets inverted: whether untangling is stuck, and the smoothing gives up.
bool Smoother::untangling_stuck(const SweepRecord& record, SweepState& state) {
  // Stalled untangling: the tangled stars sit in local minima of a steep objective. A larger ε
  // (a larger δ where stars are tangled) flattens it so that nodes can pass through.
  if (record.inverted < state.fewest_inverted) {
    state.fewest_inverted = record.inverted;
    state.stalled_sweeps = state.sweeps_since_fewest = 0;
  } else if (++state.stalled_sweeps >= 3 && untangling_epsilon_ < 1.0) {
    untangling_epsilon_ *= 10.0;
    state.stalled_sweeps = 0;
  }
  const bool fallback_pending =
      target_ == SmoothingTarget::meccano && options_.fallback_sweeps > 0 && stats_.fallback_sweep == 0;
  return ++state.sweeps_since_fewest > options_.stalled_sweeps && !fallback_pending;
}

// After a sweep that left no tet inverted: whether the smoothing is done.
bool Smoother::smoothing_done(int sweep, const SweepRecord& record, std::optional<double> previous_objective,
                              SweepState& state) {
  // A raised ε would keep δ large on valid stars, and their barrier soft: smoothing could tangle again.
  untangling_epsilon_ = initial_untangling_epsilon;
  // The objective's power changes with the first untangled sweep: every node gets another look.
  if (state.clean_sweeps == 0) state.look_at_all_again();
  if (state.clean_sweeps++ == 0 && stats_.inverted_before > 0) stats_.untangling_sweeps = sweep;
  if (state.clean_sweeps >= options_.smoothing_sweeps || record.nodes_optimised == 0) return true;
  if (target_ != options_.target && !returned_from_fallback_) {
    switch_target(options_.target, state);  // untangled by the fallback: smooth towards the chosen target
    returned_from_fallback_ = true;
    return false;
  }
  return previous_objective && *previous_objective - record.objective <= options_.tolerance * *previous_objective;
}

SmoothingStats Smoother::run() {
  const std::vector<VertexId> nodes = free_nodes();
  count_free_nodes(nodes);
  collect_active_tets(nodes);
  stats_.inverted_before = count_inverted(mesh_);

  const auto colours = colour(nodes);
  stats_.colours = static_cast<int>(colours.size());
  SweepState state(mesh_.points.size());
  for (int sweep = 1; sweep <= options_.max_sweeps; ++sweep) {
    fall_back_if_stalled(sweep, state);
    const auto start = std::chrono::steady_clock::now();
    const SweepRecord record = record_sweep(optimise_colours(colours, state), start);
    const std::optional<double> previous_objective = comparable_objective();
    stats_.sweeps.push_back(record);
    if (options_.on_sweep) options_.on_sweep(sweep, record);
    // Untangling uses the paper's sum; once a sweep ends untangled, the next ones weigh bad tets more.
    tangled_ = record.inverted > 0;
    if (tangled_ ? untangling_stuck(record, state) : smoothing_done(sweep, record, previous_objective, state)) break;
  }
  stats_.inverted_after = count_inverted(mesh_);
  return stats_;
}

ImprovementStats Smoother::improve(const ImprovementOptions& options, std::span<const std::uint8_t> only) {
  improving_ = &options;
  floors_ = options.floors();
  tangled_ = false;
  aim_at(SmoothingTarget::equilateral);
  std::vector<std::uint8_t> movable(mesh_.points.size(), 0);
  for (VertexId v : free_nodes()) movable[v] = only.empty() || only[v];
  // The tets measured: every tet, or with `only` the stars of its movable nodes, the only tets the passes
  // can change; the others count as fine (+∞) except in the shape passes' floors, which stay the mesh's.
  // The statistics are then those of the stars: a restricted call (a round of flips touches a few
  // hundred tets of 270 000 on the cube example) measures their shapes, not the whole mesh's.
  std::vector<TetId> measured;
  MeanRatioMinima unmeasured{infinity, infinity};  // the other tets' minima, which the passes cannot change
  if (only.empty()) {
    measured.resize(mesh_.tets.size());
    std::iota(measured.begin(), measured.end(), TetId{0});
  } else {
    std::vector<std::uint8_t> in_star(mesh_.tets.size(), 0);
    for (VertexId v = 0; v < mesh_.num_vertices(); ++v)
      if (movable[v])
        for (const TetId t : stars_.of(v)) in_star[t] = 1;
    std::vector<TetId> others;
    for (TetId t = 0; t < mesh_.num_tets(); ++t) (in_star[t] ? measured : others).push_back(t);
    unmeasured = {smallest_over(others, [&](TetId t) { return mean_ratio_equilateral(oriented_points(mesh_, t)); }),
                  smallest_over(others, [&](TetId t) { return mean_ratio_meccano(mesh_, t); })};
  }
  std::vector<double> quality(mesh_.tets.size(), infinity);
  // Passes over the tets whose quality (tet_quality) is below `limit`: each optimises their movable nodes
  // with `update`, colour by colour, until none is left, none moves or max_passes have run. With
  // skip_settled, a node that did not move is left out of the next pass unless a node of its star moved:
  // its update depends on its star alone, so it would fail again. Not for the Newton passes: optimise
  // reports only moves beyond 1 % of an edge, and a node it calls unmoved may have moved a little.
  struct Passes {
    int count = 0;
    std::int64_t updates = 0, moved = 0, below_before = 0, below_after = 0;
    double min_before = 0.0, min_after = 0.0;
    std::vector<TetId> touched;  // the stars of the nodes updated, sorted
  };
  auto run_passes = [&](auto tet_quality, double limit, bool (Smoother::*update)(VertexId), bool skip_settled,
                        const std::string& pass_name, const std::string& where) {
    auto measure_tets = [&](const std::vector<TetId>& tets) {
      const auto count = static_cast<std::int64_t>(tets.size());
#pragma omp parallel for schedule(static)
      for (std::int64_t i = 0; i < count; ++i) quality[tets[i]] = tet_quality(oriented_points(mesh_, tets[i]));
    };
    auto worst_nodes = [&] {  // in vertex order
      std::vector<VertexId> nodes;
      for (TetId t = 0; t < mesh_.num_tets(); ++t)
        if (quality[t] < limit)
          for (VertexId v : mesh_.tets[t])
            if (movable[v]) nodes.push_back(v);
      std::sort(nodes.begin(), nodes.end());
      nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
      return nodes;
    };
    auto below = [&] {
      return static_cast<std::int64_t>(
          std::count_if(quality.begin(), quality.end(), [&](double q) { return q < limit; }));
    };
    auto smallest = [&] { return measured.empty() ? 0.0 : *std::min_element(quality.begin(), quality.end()); };
    Passes passes;
    measure_tets(measured);
    passes.below_before = below();
    passes.min_before = smallest();
    std::vector<std::uint8_t> moved_now(mesh_.points.size(), 0), settled(mesh_.points.size(), 0);
    std::vector<VertexId> nodes = worst_nodes();
    while (!nodes.empty() && passes.count < options.max_passes) {
      ++passes.count;
      std::int64_t moved = 0;
      for (const auto& group : colour(nodes)) {
        const auto size = static_cast<std::int64_t>(group.size());
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : moved)
        for (std::int64_t i = 0; i < size; ++i) {
          moved_now[group[i]] = (this->*update)(group[i]);
          moved += moved_now[group[i]];
        }
      }
      const std::size_t tried = nodes.size();
      passes.updates += static_cast<std::int64_t>(tried);
      passes.moved += moved;
      std::vector<TetId> touched;
      for (VertexId v : nodes) touched.insert(touched.end(), stars_.of(v).begin(), stars_.of(v).end());
      std::sort(touched.begin(), touched.end());
      touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
      measure_tets(touched);
      passes.touched.insert(passes.touched.end(), touched.begin(), touched.end());
      if (skip_settled) {
        for (VertexId v : nodes) settled[v] = !moved_now[v];
        for (VertexId v : nodes)
          if (moved_now[v])
            for (TetId t : stars_.of(v))
              for (VertexId w : mesh_.tets[t]) settled[w] = 0;
      }
      for (VertexId v : nodes) moved_now[v] = 0;
      nodes = worst_nodes();
      if (skip_settled) std::erase_if(nodes, [&](VertexId v) { return settled[v] != 0; });
      if (options.progress)
        options.progress("improvement " + pass_name + " pass " + std::to_string(passes.count) + ": " +
                         std::to_string(moved) + " of " + std::to_string(tried) + " nodes moved; " +
                         std::to_string(below()) + " tets " + where + ", smallest " + std::to_string(smallest()));
      if (moved == 0) break;
    }
    passes.below_after = below();
    passes.min_after = smallest();
    std::sort(passes.touched.begin(), passes.touched.end());
    passes.touched.erase(std::unique(passes.touched.begin(), passes.touched.end()), passes.touched.end());
    return passes;
  };
  ImprovementStats stats;
  const Passes newton = run_passes([](const TetPoints& p) { return mean_ratio_equilateral(p); }, options.threshold,
                                   &Smoother::optimise, false, "mean ratio", "below the threshold");
  stats.passes = newton.count;
  stats.node_updates = newton.updates;
  stats.nodes_moved = newton.moved;
  stats.tets_below_before = newton.below_before;
  stats.tets_below_after = newton.below_after;
  stats.min_quality_before = newton.min_before;
  stats.min_quality_after = newton.min_after;
  if (!floors_.angles_off()) {
    // The shape passes trade either mean ratio for angles only above the mesh's minimum after the Newton
    // passes: neither minimum falls.
    shape_mean_ratio_floor_ = std::min(newton.min_after, unmeasured.equilateral) / options.threshold;
    shape_meccano_floor_ =
        std::min(smallest_over(measured, [&](TetId t) { return mean_ratio_meccano(mesh_, t); }), unmeasured.meccano);
    std::vector<double> equilateral = quality;  // the Newton passes' measure, which the shape passes replace
    // Most nodes of the tets left outside the floors are held (by the guards, or neighbours that stay):
    // trying them again cost as much as the first pass for a few per cent of moves.
    const Passes shape =
        run_passes([&](const TetPoints& p) { return worst_shape_over_floors(p, floors_); }, 1.0,
                   &Smoother::lift_worst_shape, true, "shape", "outside the floors (worst ratio to them)");
    stats.shape_passes = shape.count;
    stats.shape_node_updates = shape.updates;
    stats.shape_nodes_moved = shape.moved;
    stats.tets_outside_floors_before = shape.below_before;
    stats.tets_outside_floors_after = shape.below_after;
    // The shape passes may lower mean ratios above the mesh's minimum, in the stars they touched: count the
    // tets below the threshold again.
    for (const TetId t : shape.touched) equilateral[t] = mean_ratio_equilateral(oriented_points(mesh_, t));
    stats.tets_below_after =
        std::count_if(equilateral.begin(), equilateral.end(), [&](double q) { return q < options.threshold; });
    stats.min_quality_after = measured.empty() ? 0.0 : *std::min_element(equilateral.begin(), equilateral.end());
  }
  improving_ = nullptr;
  return stats;
}

// The mesh's tets below options.threshold, its smallest equilateral mean ratio and, if the shape passes
// run, its tets outside their floors.
struct QualityCounts {
  std::int64_t below = 0, outside = 0;
  double smallest = 0.0;
};
QualityCounts count_quality(const TetMesh& mesh, const ImprovementOptions& options) {
  const ShapeFloors floors = options.floors();
  std::int64_t below = 0, outside = 0;
  double smallest = infinity;
#pragma omp parallel for schedule(static) reduction(+ : below, outside) reduction(min : smallest)
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    const TetPoints p = oriented_points(mesh, t);
    const double q = mean_ratio_equilateral(p);
    below += q < options.threshold;
    smallest = std::min(smallest, q);
    if (!floors.angles_off()) outside += worst_shape_over_floors(p, floors) < 1.0;
  }
  return {below, outside, mesh.tets.empty() ? 0.0 : smallest};
}

// The passes and node updates of `more` (Newton and shape passes) added to `stats`.
void add_smoothing_work(ImprovementStats& stats, const ImprovementStats& more) {
  stats.passes += more.passes;
  stats.node_updates += more.node_updates;
  stats.nodes_moved += more.nodes_moved;
  stats.shape_passes += more.shape_passes;
  stats.shape_node_updates += more.shape_node_updates;
  stats.shape_nodes_moved += more.shape_nodes_moved;
}

// count_quality into stats' "after" fields.
void count_after_improvement(const TetMesh& mesh, const ImprovementOptions& options, ImprovementStats& stats) {
  const QualityCounts counts = count_quality(mesh, options);
  stats.tets_below_after = counts.below;
  stats.min_quality_after = counts.smallest;
  if (!options.floors().angles_off()) stats.tets_outside_floors_after = counts.outside;
}

}  // namespace

Distortion regularised_distortion(const TetPoints& physical, const Matrix3d& target_inverse, int vertex, double delta) {
  StarTet tet = star_tet(edge_matrix(physical) * target_inverse, target_inverse, vertex);
  tet.delta = delta;
  return distortion_derivatives(tet, Vector3d::Zero());
}

SmoothingStats smooth_mesh(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                           const SmoothingOptions& options) {
  if (options.max_sweeps <= 0) {  // nothing moves: a moved interface's step skips the smoother's set-up
    SmoothingStats counted;
    counted.inverted_before = counted.inverted_after = count_inverted(mesh);
    return counted;
  }
  return Smoother(mesh, surfaces, options).run();
}

ImprovementStats improve_worst_tets(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                                    const ImprovementOptions& options, const SmoothingOptions& sus,
                                    std::span<TetRegion* const> regions) {
  if (options.lowest_threshold() < options.threshold) {
    // The worst tets first: the whole stage at first_threshold, then at threshold. The counts before are
    // the mesh's against the final threshold and floors; the work is that of both stages.
    const QualityCounts before = count_quality(mesh, options);
    ImprovementOptions first = options, then = options;
    first.threshold = options.first_threshold;
    first.first_threshold = then.first_threshold = 0.0;
    // With no tet below first_threshold (a moved interface's step starts from a mesh the ladder lifted)
    // there are no worst tets to lift first: the first stage would only run the second's shape passes
    // and flips at a lower floor, for the same worst tets (doc/comparison.md, "One stage where no tet
    // is below the first threshold").
    const bool ladder = before.smallest < first.threshold;
    const ImprovementStats lifted =
        ladder ? improve_worst_tets(mesh, surfaces, first, sus, regions) : ImprovementStats{};
    ImprovementStats stats = improve_worst_tets(mesh, surfaces, then, sus, regions);
    stats.tets_below_before = before.below;
    stats.min_quality_before = before.smallest;
    stats.tets_outside_floors_before = before.outside;
    if (!ladder) return stats;
    stats.first_threshold = first.threshold;
    add_smoothing_work(stats, lifted);
    stats.rounds += lifted.rounds;
    stats.flips += lifted.flips;
    return stats;
  }
  // improve() aims at the equilateral tet and guards the meccano measure; SUS's mode and band decide which
  // nodes are free. A flip changes the stars, so each round smooths with a Smoother built afresh.
  auto smooth = [&](std::span<const std::uint8_t> only) {
    return Smoother(mesh, surfaces,
                    {.target = SmoothingTarget::equilateral, .mode = sus.mode, .band_rings = sus.band_rings})
        .improve(options, only);
  };
  const FlipStats mends = options.topology ? conform_to_creases(mesh, surfaces, regions, options) : FlipStats{};
  if (options.topology && options.progress) options.progress("improvement creases: " + describe(mends));
  ImprovementStats stats = smooth({});
  stats.floors = options.floors();
  stats.flips += mends;
  if (!options.topology) return stats;
  for (int round = 0; round < options.rounds; ++round) {
    const FlipStats flips = flip_worst_tets(mesh, surfaces, regions, options);
    if (flips.operations() == 0) break;
    ++stats.rounds;
    stats.flips += flips;
    // Elsewhere the nodes and their stars are as the last smoothing left them, which would do the same
    // again: only the nodes of flipped tets are optimised.
    std::vector<std::uint8_t> flipped(mesh.points.size(), 0);
    for (TetId t = 0; t < mesh.num_tets(); ++t)
      if (!mesh.bisectable(t))
        for (VertexId v : mesh.tets[t]) flipped[v] = 1;
    add_smoothing_work(stats, smooth(flipped));
  }
  // A round's smoothing measured only the stars it could change: the mesh's counts after the last round.
  if (stats.rounds > 0) count_after_improvement(mesh, options, stats);
  for (TetId t = 0; t < mesh.num_tets(); ++t) stats.remeshed_tets += !mesh.bisectable(t);
  return stats;
}

}  // namespace meccano
