#include <meccano/stages/parameterization.hpp>

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>

#include "mesh/topology_helpers.hpp"

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace meccano {

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Barycentric coordinates down to -1e-12 count as inside: rounding of a point on an edge is ~1e-16.
constexpr double inside_tolerance = 1e-12;

// Beyond this many steps a walk costs more than the grid search (a handful of barycentric tests).
constexpr int hinted_walk_steps = 32;

// Below this many items a loop runs serially: waking threads costs more (milliseconds on a busy machine).
constexpr int parallel_threshold = 20000;

// A rim vertex turning by more than this is a natural corner for corners_by_arc_length.
constexpr double natural_corner_turn = std::numbers::pi / 4;

const char* const side_names[4] = {"side 0 (v = 0)", "side 1 (u = 1)", "side 2 (v = 1)", "side 3 (u = 0)"};
const Vector2d square_corners[4] = {{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}};


// The disk with its vertices renumbered compactly (in increasing view order), its triangle adjacency and
// its rim. Corner c = 3 t + k is corner k of triangle t.
struct Connectivity {
  std::vector<int> local;                     // view vertex -> compact id, -1 if no triangle uses it
  std::vector<int> global;                    // compact id -> view vertex
  std::vector<std::array<int, 3>> triangles;  // compact ids
  std::vector<int> corner_start;              // corners at vertex v: corners[corner_start[v] .. [v+1])
  std::vector<int> corners;
  std::vector<std::array<int, 3>> neighbours;  // across the edge opposite corner k; -1 on the rim
  std::vector<int> rim;                        // compact ids, rim loop from its smallest id
  std::vector<int> rim_position;               // compact id -> index in rim, -1 for interior vertices

  int vertex_count() const { return static_cast<int>(global.size()); }
  int corner_vertex(int c) const { return triangles[c / 3][c % 3]; }
  int corner_next(int c) const { return triangles[c / 3][(c % 3 + 1) % 3]; }
  int corner_previous(int c) const { return triangles[c / 3][(c % 3 + 2) % 3]; }
  std::string name(int v) const { return std::to_string(global[v]); }
};

// The triangle (other than `except`) holding the directed edge a -> b, or -1.
int triangle_with_edge(const Connectivity& c, int a, int b, int except) {
  for (int i = c.corner_start[a]; i < c.corner_start[a + 1]; ++i) {
    const int corner = c.corners[i];
    if (corner / 3 != except && c.corner_next(corner) == b) return corner / 3;
  }
  return -1;
}

Connectivity connect(DiskView disk) {
  if (disk.triangles.empty()) throw MeshingError("parameterization: the disk has no triangles");
  Connectivity c;
  const int point_count = static_cast<int>(disk.points.size());
  c.local.assign(disk.points.size(), -1);
  for (std::size_t t = 0; t < disk.triangles.size(); ++t) {
    const auto& tri = disk.triangles[t];
    for (int v : tri) {
      if (v < 0 || v >= point_count)
        throw std::invalid_argument("parameterization: triangle " + std::to_string(t) + " has vertex " +
                                    std::to_string(v) + " outside the " + std::to_string(point_count) + " points");
      c.local[v] = 0;
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0])
      throw MeshingError("parameterization: triangle " + std::to_string(t) + " repeats a vertex");
  }
  for (int v = 0; v < point_count; ++v) {
    if (c.local[v] < 0) continue;
    c.local[v] = static_cast<int>(c.global.size());
    c.global.push_back(v);
  }
  const int n = c.vertex_count();
  const int triangle_count = static_cast<int>(disk.triangles.size());
  c.triangles.resize(disk.triangles.size());
  c.corner_start.assign(n + 1, 0);
  for (int t = 0; t < triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      c.triangles[t][k] = c.local[disk.triangles[t][k]];
      ++c.corner_start[c.triangles[t][k] + 1];
    }
  }
  for (int v = 0; v < n; ++v) c.corner_start[v + 1] += c.corner_start[v];
  c.corners.resize(3 * disk.triangles.size());
  std::vector<int> fill(c.corner_start.begin(), c.corner_start.end() - 1);
  for (int corner = 0; corner < 3 * triangle_count; ++corner) c.corners[fill[c.corner_vertex(corner)]++] = corner;

  c.neighbours.resize(disk.triangles.size());
  std::vector<int> rim_next(n, -1);
  int rim_edges = 0;
  for (int t = 0; t < triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = c.triangles[t][(k + 1) % 3];
      const int b = c.triangles[t][(k + 2) % 3];
      if (triangle_with_edge(c, a, b, t) >= 0)
        throw MeshingError("parameterization: edge " + c.name(a) + "-" + c.name(b) +
                           " is used twice in the same direction (triangles inconsistently oriented, or more "
                           "than two triangles on the edge)");
      c.neighbours[t][k] = triangle_with_edge(c, b, a, t);
      if (c.neighbours[t][k] >= 0) continue;
      if (rim_next[a] >= 0)
        throw MeshingError("parameterization: the rim is not one loop: it is pinched at vertex " + c.name(a));
      rim_next[a] = b;
      ++rim_edges;
    }
  }
  if (rim_edges == 0) throw MeshingError("parameterization: the surface has no rim (it is closed)");
  const int start =
      static_cast<int>(std::find_if(rim_next.begin(), rim_next.end(), [](int v) { return v >= 0; }) - rim_next.begin());
  c.rim_position.assign(n, -1);
  for (int v = start; v >= 0 && c.rim_position[v] < 0; v = rim_next[v]) {
    c.rim_position[v] = static_cast<int>(c.rim.size());
    c.rim.push_back(v);
  }
  if (static_cast<int>(c.rim.size()) != rim_edges || rim_next[c.rim.back()] != start)
    throw MeshingError("parameterization: the rim is not one loop: the loop through vertex " + c.name(start) + " has " +
                       std::to_string(c.rim.size()) + " of the " + std::to_string(rim_edges) + " rim edges");
  // A disk has Euler characteristic 1; one rim loop with a handle or a closed component does not.
  detail::TopologyScratch scratch;
  const std::int64_t euler = detail::triangle_topology(disk.triangles, scratch).euler();
  if (euler != 1)
    throw MeshingError("parameterization: not a disk: Euler characteristic " + std::to_string(euler) +
                       " (a handle, or more than one component)");
  return c;
}

std::vector<Vector3d> compact_points(const Connectivity& c, DiskView disk) {
  std::vector<Vector3d> points(c.global.size());
  for (std::size_t v = 0; v < points.size(); ++v) points[v] = disk.points[c.global[v]];
  return points;
}

// ---------------------------------------------------------------------------------------------------
// Floater weights of an interior vertex: (neighbour, λ) with λ > 0 summing to 1; empty, or not all
// positive and finite, for a degenerate or non-manifold star.

using Weights = std::vector<std::pair<int, double>>;

void add_weight(Weights& weights, int j, double w) {
  for (auto& [vertex, value] : weights) {
    if (vertex == j) {
      value += w;
      return;
    }
  }
  weights.emplace_back(j, w);
}

// Floater 2003: w_ij = (tan(α⁻/2) + tan(α⁺/2)) / |x_j - x_i|, α± the angles at x_i of the triangles on
// either side of edge ij, straight from the 3D angles (no flattening needed).
Weights mean_value_weights(const Connectivity& c, const std::vector<Vector3d>& x, int i) {
  Weights weights;
  for (int k = c.corner_start[i]; k < c.corner_start[i + 1]; ++k) {
    const int j = c.corner_next(c.corners[k]);
    const int l = c.corner_previous(c.corners[k]);
    const Vector3d e1 = x[j] - x[i];
    const Vector3d e2 = x[l] - x[i];
    const double n1 = e1.norm();
    const double n2 = e2.norm();
    // tan(α/2) = sin α / (1 + cos α), stable for small α.
    const double tan_half = e1.cross(e2).norm() / (n1 * n2 + e1.dot(e2));
    add_weight(weights, j, tan_half / n1);
    add_weight(weights, l, tan_half / n2);
  }
  return weights;
}

// Floater 1997, third parameterization: flatten the star of x_i by the discrete geodesic polar map (edge
// lengths kept, angles scaled to sum 2π), then for each neighbour l average the barycentric coordinates
// of the origin in the triangle (p_l, p_r, p_{r+1}) that holds it. By the triangle inequality on the
// sphere no scaled angle exceeds π, so the flattened star is star-shaped around the origin and such a
// triangle exists; the one with the largest smallest coordinate is taken, which also settles the tie when
// the origin lies on a segment p_l p_r (two triangles hold it, with equal weights).
Weights shape_preserving_weights(const Connectivity& c, const std::vector<Vector3d>& x, int i) {
  std::vector<int> ring;
  const int degree = c.corner_start[i + 1] - c.corner_start[i];
  ring.push_back(c.corner_next(c.corners[c.corner_start[i]]));
  while (static_cast<int>(ring.size()) < degree) {
    int next = -1;
    for (int k = c.corner_start[i]; k < c.corner_start[i + 1]; ++k) {
      if (c.corner_next(c.corners[k]) == ring.back()) next = c.corner_previous(c.corners[k]);
    }
    if (next < 0 || next == ring.front()) return {};  // not one fan around i
    ring.push_back(next);
  }
  std::vector<double> angle(degree);
  double total = 0.0;
  for (int m = 0; m < degree; ++m) {
    const Vector3d e1 = x[ring[m]] - x[i];
    const Vector3d e2 = x[ring[(m + 1) % degree]] - x[i];
    angle[m] = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
    total += angle[m];
  }
  std::vector<Vector2d> p(degree);
  double polar = 0.0;
  for (int m = 0; m < degree; ++m) {
    p[m] = (x[ring[m]] - x[i]).norm() * Vector2d(std::cos(polar), std::sin(polar));
    polar += angle[m] * 2.0 * std::numbers::pi / total;
  }
  Weights weights;
  for (int m = 0; m < degree; ++m) weights.emplace_back(ring[m], 0.0);
  for (int l = 0; l < degree; ++l) {
    double best = -std::numeric_limits<double>::infinity();
    std::array<double, 3> best_coordinates{};
    int best_r = -1;
    for (int r = 0; r < degree; ++r) {
      const int s = (r + 1) % degree;
      if (r == l || s == l) continue;
      const double area = cross2(p[r] - p[l], p[s] - p[l]);
      if (!(area > 0.0)) continue;
      const std::array<double, 3> coordinates{cross2(p[r], p[s]) / area, cross2(p[s], p[l]) / area,
                                              cross2(p[l], p[r]) / area};
      const double smallest = std::min({coordinates[0], coordinates[1], coordinates[2]});
      if (smallest > best) {
        best = smallest;
        best_coordinates = coordinates;
        best_r = r;
      }
    }
    if (best_r < 0) return {};  // every triangle of the flattened star is degenerate
    weights[l].second += best_coordinates[0];
    weights[best_r].second += best_coordinates[1];
    weights[(best_r + 1) % degree].second += best_coordinates[2];
  }
  return weights;
}

Weights floater_weights(const Connectivity& c, const std::vector<Vector3d>& x, int i, FloaterWeights kind) {
  Weights weights =
      kind == FloaterWeights::mean_value ? mean_value_weights(c, x, i) : shape_preserving_weights(c, x, i);
  double sum = 0.0;
  for (const auto& [j, w] : weights) sum += w;
  for (auto& [j, w] : weights) w /= sum;  // NaN, and so rejected, if sum is not positive and finite
  return weights;
}

// ---------------------------------------------------------------------------------------------------
// Corners. A loop is the rim walked in one direction; positions are indices into it. A chord is an
// interior edge with both ends on the rim: it folds the map when both ends lie on one side of the square.

struct Chord {
  int a;
  int b;
  std::array<int, 2> triangles;
};

std::vector<Chord> rim_chords(const Connectivity& c) {
  std::vector<Chord> chords;
  for (int t = 0; t < static_cast<int>(c.triangles.size()); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int across = c.neighbours[t][k];
      const int a = c.triangles[t][(k + 1) % 3];
      const int b = c.triangles[t][(k + 2) % 3];
      if (across > t && c.rim_position[a] >= 0 && c.rim_position[b] >= 0)
        chords.push_back({std::min(a, b), std::max(a, b), {t, across}});
    }
  }
  return chords;
}

struct Loop {
  std::vector<int> vertices;   // compact ids
  std::vector<int> position;   // compact id -> index in vertices, -1 off the rim
  std::vector<double> length;  // cumulative chord length, length[0] = 0, length[N] = perimeter

  int size() const { return static_cast<int>(vertices.size()); }
  // Arc length walking forward from position a to position b.
  double arc(int a, int b) const {
    const double d = length[b] - length[a];
    return b >= a ? d : d + length.back();
  }
};

// The rim walked forwards (direction +1) or backwards (-1) from rim position `first`.
Loop make_loop(const Connectivity& c, const std::vector<Vector3d>& x, int first, int direction) {
  const int n = static_cast<int>(c.rim.size());
  Loop loop;
  loop.position.assign(c.global.size(), -1);
  loop.length.push_back(0.0);
  for (int i = 0; i < n; ++i) {
    const int v = c.rim[((first + direction * i) % n + n) % n];
    loop.position[v] = i;
    if (i > 0) loop.length.push_back(loop.length.back() + (x[v] - x[loop.vertices.back()]).norm());
    loop.vertices.push_back(v);
  }
  loop.length.push_back(loop.length.back() + (x[loop.vertices.front()] - x[loop.vertices.back()]).norm());
  return loop;
}

// The square's sides along a loop with corners at loop positions `corners` (cyclic order): side k runs
// from corner k to corner k + 1, both included. Positions are counted from corner 0, and corner 0 closing
// the loop is position N on side 3.
class Sides {
 public:
  Sides(const Loop& loop, const std::array<int, 4>& corners) : loop_(loop), first_(corners[0]) {
    for (int k = 1; k < 4; ++k) bound_[k] = relative(corners[k]);
    bound_[4] = loop.size();
  }
  // Position of vertex v on side k, or -1 if v is not on that side.
  int position_on(int k, int v) const {
    if (loop_.position[v] < 0) return -1;
    int r = relative(loop_.position[v]);
    if (k == 3 && r == 0) r = loop_.size();
    return bound_[k] <= r && r <= bound_[k + 1] ? r : -1;
  }

 private:
  int relative(int position) const { return (position - first_ + loop_.size()) % loop_.size(); }
  const Loop& loop_;
  int first_;
  std::array<int, 5> bound_{};
};

// A chord with both ends on side `side`, at positions lo < hi along it.
struct FlatChord {
  int side;
  int lo;
  int hi;
};

std::optional<FlatChord> on_one_side(const Sides& sides, const Chord& chord) {
  for (int k = 0; k < 4; ++k) {
    const int x = sides.position_on(k, chord.a);
    const int y = sides.position_on(k, chord.b);
    if (x >= 0 && y >= 0) return FlatChord{k, std::min(x, y), std::max(x, y)};
  }
  return std::nullopt;
}

// Moves corners (loop positions in cyclic order) until no chord lies on one side: the nearer of the
// side's two corners steps into the chord's arc on that side, which keeps the corners distinct and in
// order. Each move fixes one chord and may expose another; a bounded number of rounds must settle.
std::array<int, 4> repair_corners(const Connectivity& c, const Loop& loop, std::array<int, 4> corners) {
  const std::vector<Chord> chords = rim_chords(c);
  const int n = loop.size();
  const int rounds = 4 * static_cast<int>(chords.size()) + 8;
  for (int round = 0; round < rounds; ++round) {
    const Sides sides(loop, corners);
    std::optional<FlatChord> flat;
    for (const Chord& chord : chords) {
      if ((flat = on_one_side(sides, chord))) break;
    }
    if (!flat) return corners;
    const int k = flat->side;
    const int forward = (corners[0] + flat->lo + 1) % n;   // corner k steps forward to here
    const int backward = (corners[0] + flat->hi - 1) % n;  // or corner k + 1 back to here
    if (loop.arc(corners[k], forward) <= loop.arc(backward, corners[(k + 1) % 4])) corners[k] = forward;
    else corners[(k + 1) % 4] = backward;
  }
  throw MeshingError("parameterization: no choice of corners keeps every interior edge between rim vertices off a "
                     "single side of the square (" +
                     std::to_string(chords.size()) + " such edges)");
}

std::array<int, 4> to_view_ids(const Connectivity& c, const Loop& loop, const std::array<int, 4>& corners) {
  std::array<int, 4> ids{};
  for (int k = 0; k < 4; ++k) ids[k] = c.global[loop.vertices[corners[k]]];
  return ids;
}

void require_four_rim_vertices(const Connectivity& c) {
  if (c.rim.size() < 4)
    throw MeshingError("parameterization: the rim has " + std::to_string(c.rim.size()) +
                       " vertices; a square needs 4 corners");
}

// Angle between the incoming and the outgoing rim edge at each rim position.
std::vector<double> turning_angles(const Connectivity& c, const std::vector<Vector3d>& x) {
  const int n = static_cast<int>(c.rim.size());
  std::vector<double> turn(n);
  for (int i = 0; i < n; ++i) {
    const Vector3d in = x[c.rim[i]] - x[c.rim[(i + n - 1) % n]];
    const Vector3d out = x[c.rim[(i + 1) % n]] - x[c.rim[i]];
    turn[i] = std::atan2(in.cross(out).norm(), in.dot(out));
  }
  return turn;
}

// Makes loop positions 0 = p0 < p1 < p2 < p3 < n (n >= 4), moving as little as the order requires.
std::array<int, 4> increasing(std::array<int, 4> p, int n) {
  for (int k = 1; k < 4; ++k) p[k] = std::max(p[k], p[k - 1] + 1);
  p[3] = std::min(p[3], n - 1);
  for (int k = 2; k >= 1; --k) p[k] = std::min(p[k], p[k + 1] - 1);
  return p;
}

}  // namespace

std::vector<int> rim_loop(DiskView disk) {
  const Connectivity c = connect(disk);
  std::vector<int> rim(c.rim.size());
  for (std::size_t i = 0; i < rim.size(); ++i) rim[i] = c.global[c.rim[i]];
  return rim;
}

Vector3d vector_area(std::span<const Vector3d> points, std::span<const int> loop) {
  // Measured from the first point, which changes nothing in exact arithmetic and avoids cancellation far
  // from the origin.
  Vector3d area = Vector3d::Zero();
  for (std::size_t i = 1; i + 1 < loop.size(); ++i)
    area += (points[loop[i]] - points[loop[0]]).cross(points[loop[i + 1]] - points[loop[0]]);
  return 0.5 * area;
}

std::array<int, 4> corners_by_arc_length(DiskView disk, int start) {
  const Connectivity c = connect(disk);
  require_four_rim_vertices(c);
  const std::vector<Vector3d> x = compact_points(c, disk);
  const std::vector<double> rim_turn = turning_angles(c, x);
  int first = 0;
  if (start < 0) {
    first = static_cast<int>(std::max_element(rim_turn.begin(), rim_turn.end()) - rim_turn.begin());
  } else {
    const int v = start < static_cast<int>(c.local.size()) ? c.local[start] : -1;
    if (v < 0 || c.rim_position[v] < 0)
      throw std::invalid_argument("corners_by_arc_length: start " + std::to_string(start) + " is not a rim vertex");
    first = c.rim_position[v];
  }
  const Loop loop = make_loop(c, x, first, +1);
  const int n = loop.size();
  const double perimeter = loop.length.back();
  std::array<int, 4> p{0, 0, 0, 0};
  for (int k = 1; k < 4; ++k) {
    const double target = perimeter * k / 4.0;
    int nearest = 0;
    int natural = -1;
    for (int i = 0; i < n; ++i) {
      const double offset = std::abs(loop.length[i] - target);
      if (offset < std::abs(loop.length[nearest] - target)) nearest = i;
      const double turn = rim_turn[c.rim_position[loop.vertices[i]]];
      if (offset <= perimeter / 8.0 && turn > natural_corner_turn &&
          (natural < 0 || turn > rim_turn[c.rim_position[loop.vertices[natural]]]))
        natural = i;
    }
    p[k] = natural >= 0 ? natural : nearest;
  }
  return to_view_ids(c, loop, repair_corners(c, loop, increasing(p, n)));
}

std::array<int, 4> matching_corners(DiskView disk, const std::array<Vector3d, 4>& targets, const Vector3d& normal) {
  const Connectivity c = connect(disk);
  require_four_rim_vertices(c);
  const std::vector<Vector3d> x = compact_points(c, disk);
  const double turn = vector_area(x, c.rim).dot(normal);
  if (!(turn != 0.0))
    throw MeshingError("matching_corners: the rim of S_M does not turn around the given normal (vector area . normal "
                       "= " +
                       std::to_string(turn) + ")");
  const int direction = turn > 0.0 ? +1 : -1;
  const Loop around = make_loop(c, x, 0, direction);
  const int n = around.size();
  const auto distance = [&](const Loop& loop, int k, int i) { return (x[loop.vertices[i]] - targets[k]).norm(); };
  int first = 0;
  for (int i = 1; i < n; ++i) {
    if (distance(around, 0, i) < distance(around, 0, first)) first = i;
  }
  const Loop loop = make_loop(c, x, c.rim_position[around.vertices[first]], direction);
  // best[k][i]: the least sum of distances of corners 1..k to their targets with corner k at position <= i;
  // at[k][i]: where corner k is then. Strict comparisons keep the earliest of equals.
  std::array<std::vector<double>, 4> best;
  std::array<std::vector<int>, 4> at;
  best[0].assign(n, 0.0);
  at[0].assign(n, 0);
  for (int k = 1; k < 4; ++k) {
    best[k].assign(n, std::numeric_limits<double>::infinity());
    at[k].assign(n, -1);
    for (int i = k; i < n; ++i) {
      const double here = best[k - 1][i - 1] + distance(loop, k, i);
      best[k][i] = best[k][i - 1];
      at[k][i] = at[k][i - 1];
      if (here < best[k][i]) {
        best[k][i] = here;
        at[k][i] = i;
      }
    }
  }
  std::array<int, 4> p{0, 0, 0, 0};
  int limit = n - 1;
  for (int k = 3; k >= 1; --k) {
    p[k] = at[k][limit];
    limit = p[k] - 1;
  }
  return to_view_ids(c, loop, repair_corners(c, loop, p));
}

namespace {

// The direction (+1 or -1) of the rim walk from corner 0 that meets corners 1, 2, 3 (view vertices) in
// this order.
int walk_direction(const Connectivity& c, const std::array<int, 4>& corners) {
  const int n = static_cast<int>(c.rim.size());
  std::array<int, 4> at{};
  for (int k = 0; k < 4; ++k) {
    const int v = corners[k] >= 0 && corners[k] < static_cast<int>(c.local.size()) ? c.local[corners[k]] : -1;
    if (v < 0 || c.rim_position[v] < 0)
      throw std::invalid_argument("parameterize_to_square: corner " + std::to_string(corners[k]) +
                                  " is not a rim vertex");
    at[k] = c.rim_position[v];
  }
  const auto follows = [&](int direction) {
    const auto offset = [&](int k) { return ((at[k] - at[0]) * direction % n + n) % n; };
    return 0 < offset(1) && offset(1) < offset(2) && offset(2) < offset(3);
  };
  if (follows(+1)) return +1;
  if (follows(-1)) return -1;
  throw std::invalid_argument("parameterize_to_square: the corners are not distinct rim vertices in cyclic order");
}

// Tutte/Floater: one-to-one unless an interior edge has both ends on one side. Name a triangle with all
// three vertices on that side when there is one (the common case: an ear whose apex is not a corner).
void require_no_fold(const Connectivity& c, const Loop& loop, const std::array<int, 4>& p) {
  const Sides sides(loop, p);
  std::string fold;
  for (const Chord& chord : rim_chords(c)) {
    const std::optional<FlatChord> flat = on_one_side(sides, chord);
    if (!flat) continue;
    for (int t : chord.triangles) {
      const auto& tri = c.triangles[t];
      if (std::all_of(tri.begin(), tri.end(), [&](int v) { return sides.position_on(flat->side, v) >= 0; }))
        throw MeshingError("parameterize_to_square: triangle " + std::to_string(t) + " (vertices " + c.name(tri[0]) +
                           ", " + c.name(tri[1]) + ", " + c.name(tri[2]) + ") has all three vertices on " +
                           side_names[flat->side] + " of the square: it would be flat; choose other corners");
    }
    if (fold.empty())
      fold = "parameterize_to_square: interior edge " + c.name(chord.a) + "-" + c.name(chord.b) +
             " joins two vertices of " + side_names[flat->side] + " of the square: the map would fold there";
  }
  if (!fold.empty()) throw MeshingError(fold);
}

// A rim vertex pinned at perimeter coordinate `at`: the corners at 0, 1, 2, 3, anchors between them.
struct Pin {
  int position;  // in the loop
  double at;
};

// The corners and anchors as pins in loop order, with the corner closing the loop at position N.
// Throws std::invalid_argument if an anchor is not a rim vertex, is a corner, or breaks the order.
std::vector<Pin> pins_along(const Connectivity& c, const Loop& loop, const std::array<int, 4>& p,
                            std::span<const RimAnchor> anchors) {
  std::vector<Pin> pins;
  for (int k = 0; k < 4; ++k) pins.push_back({p[k], static_cast<double>(k)});
  for (const RimAnchor& anchor : anchors) {
    const int v = anchor.vertex >= 0 && anchor.vertex < static_cast<int>(c.local.size()) ? c.local[anchor.vertex] : -1;
    if (v < 0 || loop.position[v] < 0 || !(anchor.at > 0.0 && anchor.at < 4.0))
      throw std::invalid_argument("parameterize_to_square: anchor " + std::to_string(anchor.vertex) +
                                  " is not a rim vertex with a perimeter coordinate in (0, 4)");
    pins.push_back({loop.position[v], anchor.at});
  }
  std::ranges::sort(pins, {}, &Pin::position);
  pins.push_back({loop.size(), 4.0});
  for (std::size_t i = 0; i + 1 < pins.size(); ++i)
    if (!(pins[i].position < pins[i + 1].position && pins[i].at < pins[i + 1].at))
      throw std::invalid_argument("parameterize_to_square: the anchors and corners are not in one order along the "
                                  "rim and the square's perimeter");
  return pins;
}

// Rim: chord-length spacing between consecutive pins; every piece lies on one side k, and
// corner + t * (side direction) keeps the side's constant coordinate exactly 0 or 1. Interior vertices
// are left NaN.
std::vector<Vector2d> rim_on_square(const Connectivity& c, const Loop& loop, const std::array<int, 4>& p,
                                    std::span<const RimAnchor> anchors) {
  std::vector<Vector2d> uv(c.global.size(), Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  const std::vector<Pin> pins = pins_along(c, loop, p, anchors);
  for (std::size_t j = 0; j + 1 < pins.size(); ++j) {
    const Pin& from = pins[j];
    const Pin& to = pins[j + 1];
    const int k = static_cast<int>(from.at);
    const double arc = loop.length[to.position] - loop.length[from.position];
    if (!(arc > 0.0))
      throw MeshingError("parameterize_to_square: the rim between perimeter coordinates " + std::to_string(from.at) +
                         " and " + std::to_string(to.at) + " on " + side_names[k] + " has zero length");
    const double start = from.at - k, end = to.at - k;
    for (int i = from.position; i < to.position; ++i) {
      const double t = start + (end - start) * ((loop.length[i] - loop.length[from.position]) / arc);
      uv[loop.vertices[i]] = square_corners[k] + t * (square_corners[(k + 1) % 4] - square_corners[k]);
    }
  }
  return uv;
}

// Interior: (I - Λ) u = Λ_rim u_rim, one LU factorisation for both coordinates.
void solve_interior(const Connectivity& c, const std::vector<Vector3d>& x, FloaterWeights weights,
                    std::vector<Vector2d>& uv) {
  std::vector<int> unknown(c.global.size(), -1);
  std::vector<int> interior;
  for (int v = 0; v < c.vertex_count(); ++v) {
    if (c.rim_position[v] >= 0) continue;
    unknown[v] = static_cast<int>(interior.size());
    interior.push_back(v);
  }
  const int m = static_cast<int>(interior.size());
  if (m == 0) return;
  std::vector<Weights> rows(m);
#pragma omp parallel for schedule(static) if (m > parallel_threshold)
  for (int r = 0; r < m; ++r) rows[r] = floater_weights(c, x, interior[r], weights);
  for (int r = 0; r < m; ++r) {
    if (rows[r].empty() ||
        !std::all_of(rows[r].begin(), rows[r].end(), [](const auto& entry) { return entry.second > 0.0; }))
      throw MeshingError("parameterize_to_square: no valid Floater weights at vertex " + c.name(interior[r]) +
                         " (degenerate triangles around it)");
  }
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::MatrixX2d rhs = Eigen::MatrixX2d::Zero(m, 2);
  for (int r = 0; r < m; ++r) {
    entries.emplace_back(r, r, 1.0);
    for (const auto& [j, w] : rows[r]) {
      if (unknown[j] >= 0) entries.emplace_back(r, unknown[j], -w);
      else rhs.row(r) += w * uv[j].transpose();
    }
  }
  Eigen::SparseMatrix<double> matrix(m, m);
  matrix.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  lu.compute(matrix);
  if (lu.info() != Eigen::Success)
    throw MeshingError("parameterize_to_square: sparse LU factorisation failed: " + lu.lastErrorMessage());
  const Eigen::MatrixX2d solution = lu.solve(rhs);
  if (lu.info() != Eigen::Success) throw MeshingError("parameterize_to_square: sparse LU solve failed");
  for (int r = 0; r < m; ++r) uv[interior[r]] = solution.row(r).transpose();
}

// Every parametric triangle must have the sign of the walk; find the first that does not.
void require_one_to_one(const Connectivity& c, const std::vector<Vector2d>& uv, int direction) {
  const int triangle_count = static_cast<int>(c.triangles.size());
  int first_bad = triangle_count;
#pragma omp parallel for reduction(min : first_bad) schedule(static) if (triangle_count > parallel_threshold)
  for (int t = 0; t < triangle_count; ++t) {
    const auto& tri = c.triangles[t];
    const double area = 0.5 * cross2(uv[tri[1]] - uv[tri[0]], uv[tri[2]] - uv[tri[0]]);
    if (!(direction * area > 0.0)) first_bad = std::min(first_bad, t);
  }
  if (first_bad < triangle_count) {
    const auto& tri = c.triangles[first_bad];
    throw MeshingError("parameterize_to_square: parametric triangle " + std::to_string(first_bad) + " (vertices " +
                       c.name(tri[0]) + ", " + c.name(tri[1]) + ", " + c.name(tri[2]) +
                       ") is flipped or flat: the Floater map is not one-to-one");
  }
}

}  // namespace

double perimeter_coordinate(const Vector2d& uv) {
  if (uv.y() == 0.0 && uv.x() < 1.0) return uv.x();
  if (uv.x() == 1.0 && uv.y() < 1.0) return 1.0 + uv.y();
  if (uv.y() == 1.0 && uv.x() > 0.0) return 2.0 + (1.0 - uv.x());
  if (uv.x() == 0.0 && uv.y() > 0.0) return 3.0 + (1.0 - uv.y());
  throw std::invalid_argument("perimeter_coordinate: the point is not on the square's perimeter");
}

SquareParameterization parameterize_to_square(DiskView disk, const std::array<int, 4>& corners, FloaterWeights weights,
                                              std::span<const RimAnchor> anchors) {
  const Connectivity c = connect(disk);
  require_four_rim_vertices(c);
  const std::vector<Vector3d> x = compact_points(c, disk);
  const int direction = walk_direction(c, corners);
  const Loop loop = make_loop(c, x, c.rim_position[c.local[corners[0]]], direction);
  std::array<int, 4> p{};
  for (int k = 0; k < 4; ++k) p[k] = loop.position[c.local[corners[k]]];
  require_no_fold(c, loop, p);
  std::vector<Vector2d> uv = rim_on_square(c, loop, p, anchors);
  solve_interior(c, x, weights, uv);
  require_one_to_one(c, uv, direction);

  SquareParameterization result;
  result.uv.assign(disk.points.size(), Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (int v = 0; v < c.vertex_count(); ++v) result.uv[c.global[v]] = uv[v];
  for (int v : loop.vertices) result.rim.push_back(c.global[v]);
  result.corners = corners;
  result.orientation = direction;
  result.weights = weights;
  return result;
}

// ---------------------------------------------------------------------------------------------------

ParametricSurface::ParametricSurface(DiskView disk, SquareParameterization parameterization)
    : parameterization_(std::move(parameterization)) {
  Connectivity c = connect(disk);
  if (parameterization_.uv.size() != disk.points.size())
    throw std::invalid_argument("ParametricSurface: the parameterization has " +
                                std::to_string(parameterization_.uv.size()) + " parameters for " +
                                std::to_string(disk.points.size()) + " points");
  points_ = compact_points(c, disk);
  uv_.resize(c.global.size());
  for (std::size_t v = 0; v < uv_.size(); ++v) {
    uv_[v] = parameterization_.uv[c.global[v]];
    if (!uv_[v].allFinite())
      throw std::invalid_argument("ParametricSurface: vertex " + c.name(static_cast<int>(v)) + " has no parameters");
  }
  triangles_ = std::move(c.triangles);
  neighbours_ = std::move(c.neighbours);

  // About one triangle per cell; each triangle is listed in every cell its bounding box meets. A point's
  // cell and a box's cell range come from the same monotone formula, so the triangle holding a point is
  // always listed in the point's cell.
  const int triangle_count = static_cast<int>(triangles_.size());
  grid_size_ = std::max(1, static_cast<int>(std::ceil(std::sqrt(double(triangle_count)))));
  const auto cell_of = [this](double value) {
    return std::clamp(static_cast<int>(value * grid_size_), 0, grid_size_ - 1);
  };
  std::vector<std::array<int, 4>> range(triangle_count);  // u0, u1, v0, v1
  cell_start_.assign(std::size_t(grid_size_) * grid_size_ + 1, 0);
  for (int t = 0; t < triangle_count; ++t) {
    const auto& tri = triangles_[t];
    const Vector2d lo = uv_[tri[0]].cwiseMin(uv_[tri[1]]).cwiseMin(uv_[tri[2]]);
    const Vector2d hi = uv_[tri[0]].cwiseMax(uv_[tri[1]]).cwiseMax(uv_[tri[2]]);
    range[t] = {cell_of(lo.x()), cell_of(hi.x()), cell_of(lo.y()), cell_of(hi.y())};
    for (int j = range[t][2]; j <= range[t][3]; ++j) {
      for (int i = range[t][0]; i <= range[t][1]; ++i) ++cell_start_[std::size_t(j) * grid_size_ + i + 1];
    }
  }
  for (std::size_t cell = 1; cell < cell_start_.size(); ++cell) cell_start_[cell] += cell_start_[cell - 1];
  cell_triangles_.resize(cell_start_.back());
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (int t = 0; t < triangle_count; ++t) {
    for (int j = range[t][2]; j <= range[t][3]; ++j) {
      for (int i = range[t][0]; i <= range[t][1]; ++i) cell_triangles_[fill[std::size_t(j) * grid_size_ + i]++] = t;
    }
  }
}

Vector3d ParametricSurface::barycentric(int triangle, const Vector2d& uv) const {
  const auto& tri = triangles_[triangle];
  const Vector2d a = uv_[tri[0]] - uv;
  const Vector2d b = uv_[tri[1]] - uv;
  const Vector2d c = uv_[tri[2]] - uv;
  const double area = cross2(b - a, c - a);
  return Vector3d(cross2(b, c), cross2(c, a), cross2(a, b)) / area;
}

namespace {

ParametricSurface::Location inside(int triangle, Vector3d coordinates) {
  coordinates = coordinates.cwiseMax(0.0);
  return {triangle, coordinates / coordinates.sum()};
}

Vector2d clamped_to_square(const Vector2d& uv) {
  if (!uv.allFinite()) throw std::invalid_argument("ParametricSurface: non-finite parameter point");
  return uv.cwiseMax(0.0).cwiseMin(1.0);
}

}  // namespace

ParametricSurface::Location ParametricSurface::grid_search(const Vector2d& uv) const {
  const auto cell_of = [this](double value) {
    return std::clamp(static_cast<int>(value * grid_size_), 0, grid_size_ - 1);
  };
  const std::size_t cell = std::size_t(cell_of(uv.y())) * grid_size_ + cell_of(uv.x());
  int best = -1;
  Vector3d best_coordinates = Vector3d::Constant(-std::numeric_limits<double>::infinity());
  for (int i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
    const Vector3d coordinates = barycentric(cell_triangles_[i], uv);
    if (coordinates.minCoeff() > best_coordinates.minCoeff()) {
      best = cell_triangles_[i];
      best_coordinates = coordinates;
    }
  }
  if (best < 0 || best_coordinates.minCoeff() < -inside_tolerance)
    throw MeshingError("ParametricSurface: no parametric triangle holds (" + std::to_string(uv.x()) + ", " +
                       std::to_string(uv.y()) + ")");
  return inside(best, best_coordinates);
}

std::optional<ParametricSurface::Location> ParametricSurface::walk(const Vector2d& uv, int start, int max_steps) const {
  if (start < 0 || start >= triangle_count())
    throw std::invalid_argument("ParametricSurface::walk: no triangle " + std::to_string(start));
  if (max_steps < 0) throw std::invalid_argument("ParametricSurface::walk: negative step limit");
  const Vector2d target = clamped_to_square(uv);
  const auto& first = triangles_[start];
  const Vector2d origin = (uv_[first[0]] + uv_[first[1]] + uv_[first[2]]) / 3.0;
  const Vector2d line = target - origin;
  int t = start;
  for (int step = 0;; ++step) {
    const Vector3d coordinates = barycentric(t, target);
    if (coordinates.minCoeff() >= -inside_tolerance) return inside(t, coordinates);
    if (step == max_steps) return std::nullopt;
    // Leave through an edge beyond which the target lies (opposite a negative coordinate), the most
    // negative one unless the line misses it: with two such edges, the line crosses the one whose ends
    // it separates.
    int exit = 0;
    for (int k = 1; k < 3; ++k) {
      if (coordinates[k] < coordinates[exit]) exit = k;
    }
    int other = -1;
    for (int k : {(exit + 1) % 3, (exit + 2) % 3}) {
      if (coordinates[k] < 0.0) other = k;
    }
    if (other >= 0) {
      const auto side = [&](int k) { return cross2(line, uv_[triangles_[t][k]] - origin); };
      const double at_shared = side(3 - exit - other);  // the edge opposite `exit` joins `other` and this corner
      if (at_shared != 0.0 && at_shared * side(other) > 0.0) exit = other;
    }
    t = neighbours_[t][exit];
    if (t < 0) return std::nullopt;
  }
}

ParametricSurface::Location ParametricSurface::locate(const Vector2d& uv, int hint) const {
  const Vector2d target = clamped_to_square(uv);
  if (hint >= 0) {
    if (std::optional<Location> found = walk(target, hint, hinted_walk_steps)) return *found;
  }
  return grid_search(target);
}

Vector3d ParametricSurface::evaluate(const Location& location) const {
  const auto& tri = triangles_[location.triangle];
  return location.barycentric[0] * points_[tri[0]] + location.barycentric[1] * points_[tri[1]] +
         location.barycentric[2] * points_[tri[2]];
}

Eigen::Matrix<double, 3, 2> ParametricSurface::derivative(int triangle) const {
  const auto& tri = triangles_[triangle];
  Eigen::Matrix<double, 3, 2> edges;
  edges << points_[tri[1]] - points_[tri[0]], points_[tri[2]] - points_[tri[0]];
  Eigen::Matrix2d parametric;
  parametric << uv_[tri[1]] - uv_[tri[0]], uv_[tri[2]] - uv_[tri[0]];
  return edges * parametric.inverse();
}

double ParametricSurface::alignment(const std::array<Eigen::Vector3d, 3>& x, int triangle) const {
  const Eigen::Matrix<double, 3, 2> tangents = derivative(triangle);
  const Eigen::Vector3d normal = tangents.col(0).cross(tangents.col(1));
  const Eigen::Vector3d chord = (x[1] - x[0]).cross(x[2] - x[0]);
  return std::abs(chord.normalized().dot(normal.normalized()));
}

}  // namespace meccano
