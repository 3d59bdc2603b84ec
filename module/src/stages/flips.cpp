// The topological half of the improvement stage: 2-3 flips and edge removal (stages/improvement.hpp).
#include <meccano/error.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/stages/improvement.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace meccano {
namespace {

using Tet = std::array<VertexId, 4>;
constexpr double unacceptable = -std::numeric_limits<double>::infinity();
// A crease mend or a cap flip may leave a tet this poor (equilateral mean ratio), for the smoothing after
// it to lift (doc/benchmarks.md, "Creases" and "Cap flips"); a crease mend also as poor as the mesh's worst
// if that is poorer.
constexpr double mend_floor = 0.1;
// Passes of conform_to_creases per surface: each mends crossings that the previous ones made or left.
constexpr int max_crease_passes = 8;

// True when `to` is an even permutation of `from` (same vertices): the same orientation.
bool same_orientation(Tet from, const Tet& to) {
  bool even = true;
  for (int i = 0; i < 4; ++i) {
    if (from[i] == to[i]) continue;
    const auto j = std::find(from.begin() + i + 1, from.end(), to[i]) - from.begin();
    std::swap(from[i], from[j]);
    even = !even;
  }
  return even;
}

// A face of the boundary of the tets a flip replaces.
struct BoundaryFace {
  std::array<VertexId, 3> key;  // sorted vertices
  TetId owner;                  // the removed tet behind it
  TetId neighbour;              // the tet in front, or no_tet
  int neighbour_face;           // the face's index in `neighbour`
  FaceTag tag;
};

// Two S_M triangles exchanged for two others over the same four nodes (node indices of the surface).
struct SurfaceFlip {
  int surface;
  std::array<std::array<int, 3>, 2> removed;  // sorted
  std::array<std::array<int, 3>, 2> created;  // oriented like S
};

// Some tets and the positively oriented tets that would replace them, filling the same cavity.
struct Retriangulation {
  std::vector<TetId> removed;
  std::vector<Tet> created;
  std::vector<TetId> flag_parent;  // per created tet: the removed tet whose region flags it takes by default
  double worst_removed = 0.0;      // the smallest quality among `removed`
  double worst_created = unacceptable;
  // An edge removal inside S_M: the faces of `created` that become interface faces, and S_M's change.
  std::vector<std::pair<std::array<VertexId, 3>, FaceTag>> tagged_faces;
  std::optional<SurfaceFlip> surface_flip;
  // A crease split: the apexes x of the S_M triangles (a, b, x) it halves (empty for flips).
  std::vector<VertexId> split_apexes;
  bool widens_cap = false;  // an edge flip inside S_M that replaces a cap (flip_surface_caps)
};

class Flipper {
 public:
  Flipper(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces, std::span<TetRegion* const> regions,
          const ImprovementOptions& options)
      : mesh_(mesh),
        surfaces_(surfaces),
        regions_(regions),
        options_(options),
        floors_{options.floors()},
        surface_of_(mesh.points.size(), -1),
        projection_of_(mesh.points.size(), -1),
        node_index_(mesh.points.size(), -1) {
    for (int s = 0; s < static_cast<int>(surfaces.size()); ++s)
      for (int i = 0; i < static_cast<int>(surfaces[s]->nodes.size()); ++i) {
        const VertexId v = surfaces[s]->nodes[i];
        surface_of_[v] = surfaces[s]->surface_index;
        if (projection_of_[v] >= 0) {  // on the cut of a closed surface: in both halves
          shared_index_.emplace(std::pair{projection_of_[v], v}, node_index_[v]);
          shared_index_.emplace(std::pair{s, v}, i);
          projection_of_[v] = shared_node;
        } else if (projection_of_[v] == shared_node) {
          shared_index_.emplace(std::pair{s, v}, i);
        } else {
          projection_of_[v] = s;
          node_index_[v] = i;
        }
      }
    for (int s = 0; s < static_cast<int>(surfaces.size()); ++s) triangle_index(s);
    for (const TetRegion* region : regions)
      if (region->size() != mesh.tets.size())
        throw std::invalid_argument("flip_worst_tets: a region's size is not the tet count");
  }

  // Mends S_M where a crease line of S crosses one of its edges between the edge's nodes
  // (straddling_crossings): the two S_M triangles there are chords across the crease, their normals off
  // both sides' (by up to 60 degrees on real faults). Passes repeat while they mend any, since a mend
  // changes which edges the lines cross; each crossing gets the best of its mends (mend_crossing).
  FlipStats conform_to_creases() {
    double worst = std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(static) reduction(min : worst)
    for (TetId t = 0; t < mesh_.num_tets(); ++t) worst = std::min(worst, quality(mesh_.oriented_tet(t)));
    mend_floor_ = std::max(std::pow(mend_floor, 3), worst);  // quality() is cubed
    index_incident();
    for (int s = 0; s < static_cast<int>(surfaces_.size()); ++s) {
      for (int pass = 0; pass < max_crease_passes; ++pass) {
        const SurfaceProjection& projection = *surfaces_[s];
        std::vector<int> touched;  // nodes of the edges mended in this pass: their other crossings wait
        for (const CreaseCrossing& crossing :
             straddling_crossings(projection.creases, projection.triangles, projection.uv)) {
          if (std::ranges::find(touched, crossing.a) != touched.end() ||
              std::ranges::find(touched, crossing.b) != touched.end() || !mend_crossing(s, crossing))
            continue;
          touched.push_back(crossing.a);
          touched.push_back(crossing.b);
        }
        if (touched.empty()) break;
      }
    }
    incident_.clear();
    compact();
    return stats_;
  }

  FlipStats run() {
    const int caps = flip_surface_caps();
    if (options_.progress)
      options_.progress("improvement cap flips: " + std::to_string(stats_.cap_flips) + " of " + std::to_string(caps) +
                        " S_M caps under tets outside the floors");
    std::vector<TetId> candidates(mesh_.tets.size());
    std::iota(candidates.begin(), candidates.end(), TetId{0});
    for (int pass = 1; pass <= options_.max_flip_passes; ++pass) {
      const FlipStats before = stats_;
      const auto worst = worst_of(candidates);
      created_.clear();
      for (const auto& [quality, t] : worst) improve(t);
      if (options_.progress)
        options_.progress("improvement flips " + std::to_string(pass) + ": " + std::to_string(worst.size()) +
                          " tets below the threshold tried; " + describe(stats_ - before));
      if (stats_.operations() == before.operations()) break;
      // Flips move no node: the tets below the threshold now are among those tried and those created.
      candidates.clear();
      for (const auto& [quality, t] : worst) candidates.push_back(t);
      candidates.insert(candidates.end(), created_.begin(), created_.end());
    }
    compact();
    return stats_;
  }

  // Untangling: each inverted tet, worst first, takes its best flip or edge removal (improve) that
  // leaves no more tets inverted than it removes, in passes while a pass makes any. S_M edges are among
  // those removed, so an S_M triangle squeezed flat against a crease edge, which no node move gives
  // volume, may be flipped away.
  FlipStats untangle() {
    untangling_ = true;
    index_incident();  // for unsafe_while_tangled
    for (int pass = 1; pass <= options_.max_flip_passes; ++pass) {
      std::vector<TetId> inverted;
      for (TetId t = 0; t < mesh_.num_tets(); ++t)
        if (!dead(t) && !(quality(mesh_.oriented_tet(t)) > 0.0)) inverted.push_back(t);
      const FlipStats before = stats_;
      for (const auto& [quality, t] : worst_of(inverted)) improve(t);
      if (stats_.operations() == before.operations()) break;
    }
    incident_.clear();
    compact();
    return stats_;
  }

 private:
  // The cube of the equilateral mean ratio of a positively ordered tet, negative when inverted: flips only
  // compare qualities, and the cube orders them the same way without a cube root.
  double quality(const Tet& tet) const {
    const double cubed = mean_ratio_equilateral_cubed(
        {mesh_.points[tet[0]], mesh_.points[tet[1]], mesh_.points[tet[2]], mesh_.points[tet[3]]});
    return std::isfinite(cubed) ? cubed : unacceptable;
  }
  // A new tet's quality, unacceptable when its four vertices lie on one surface (a fault solver cannot
  // use such a tet).
  double new_tet_quality(const Tet& tet) const {
    const int surface = surface_of_[tet[0]];
    if (surface >= 0 && surface_of_[tet[1]] == surface && surface_of_[tet[2]] == surface &&
        surface_of_[tet[3]] == surface)
      return unacceptable;
    return quality(tet);
  }

  // The live tets among `tets` (repeats allowed) below the threshold, worst first (ties by index: a fixed
  // order).
  std::vector<std::pair<double, TetId>> worst_of(std::vector<TetId>& tets) const {
    std::sort(tets.begin(), tets.end());
    tets.erase(std::unique(tets.begin(), tets.end()), tets.end());
    std::vector<double> qualities(tets.size());  // measured in parallel, taken in order
    const auto count = static_cast<std::int64_t>(tets.size());
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < count; ++i)
      qualities[i] = dead(tets[i]) ? std::numeric_limits<double>::infinity() : quality(mesh_.oriented_tet(tets[i]));
    std::vector<std::pair<double, TetId>> worst;
    for (std::int64_t i = 0; i < count; ++i)
      if (qualities[i] < cubed_threshold()) worst.emplace_back(qualities[i], tets[i]);
    std::sort(worst.begin(), worst.end());
    return worst;
  }

  bool dead(TetId t) const { return mesh_.tets[t][0] < 0; }
  // The threshold in the measure of quality().
  double cubed_threshold() const { return options_.threshold * options_.threshold * options_.threshold; }

  static int local_index(const Tet& tet, VertexId v) {
    return static_cast<int>(std::find(tet.begin(), tet.end(), v) - tet.begin());
  }

  // Tries every flip and edge removal that removes t; applies the one whose worst new tet is best, if it
  // beats the worst tet it removes.
  void improve(TetId t) {
    if (dead(t)) return;
    const double q = quality(mesh_.oriented_tet(t));
    if (q >= cubed_threshold()) return;  // a flip next to it has already mended it
    std::optional<Retriangulation> best;
    auto consider = [&](std::optional<Retriangulation> candidate) {
      if (candidate && candidate->worst_created > candidate->worst_removed &&
          (!best || candidate->worst_created > best->worst_created) &&
          (!untangling_ || (inverts_no_more(*candidate) && !unsafe_while_tangled(*candidate))))
        best = std::move(candidate);
    };
    const Tet& v = mesh_.tets[t];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) consider(edge_removal(t, v[i], v[j]));
    for (int f = 0; f < 4; ++f) consider(flip_2_3(t, f));
    if (best) apply(*best);
  }

  // Whether r leaves at most as many tets inverted as it removes.
  bool inverts_no_more(const Retriangulation& r) const {
    auto inverted = [&](const Tet& tet) { return !(quality(tet) > 0.0); };
    const auto removed = std::ranges::count_if(r.removed, [&](TetId t) { return inverted(mesh_.oriented_tet(t)); });
    return std::ranges::count_if(r.created, inverted) <= removed;
  }

  // Whether r would make an edge or a face that a tet outside the cavity already has (needs incident_),
  // or a chord: an edge between two nodes of one S_M that is not an edge of S_M. In a valid mesh the new
  // tets' orientation rules out the first; in a tangled one the cavity may overlap other tets, and such a
  // flip would break the mesh's manifold structure. The tets around a chord all lie on one side of S_M,
  // so some stay inverted for good (stages/surface_approximation.cpp, which heals them away).
  bool unsafe_while_tangled(const Retriangulation& r) const {
    // The new S_M edge of an edge flip inside S_M: the two new interface faces' common nodes.
    std::vector<VertexId> new_surface_edge;
    if (r.tagged_faces.size() == 2)
      std::ranges::set_intersection(r.tagged_faces[0].first, r.tagged_faces[1].first,
                                    std::back_inserter(new_surface_edge));
    auto chord = [&](VertexId u, VertexId v) {
      return surface_of_[u] >= 0 && surface_of_[u] == surface_of_[v] &&
             !(new_surface_edge.size() == 2 && std::ranges::find(new_surface_edge, u) != new_surface_edge.end() &&
               std::ranges::find(new_surface_edge, v) != new_surface_edge.end());
    };
    auto holds = [&](TetId t, std::span<const VertexId> simplex) {
      return std::ranges::all_of(
          simplex, [&](VertexId v) { return std::ranges::find(mesh_.tets[t], v) != mesh_.tets[t].end(); });
    };
    auto held_by_removed = [&](std::span<const VertexId> simplex) {
      return std::ranges::any_of(r.removed, [&](TetId t) { return holds(t, simplex); });
    };
    auto held_outside = [&](std::span<const VertexId> simplex) {
      return std::ranges::any_of(star_of(simplex[0]), [&](TetId t) {
        return std::ranges::find(r.removed, t) == r.removed.end() && holds(t, simplex);
      });
    };
    for (const Tet& tet : r.created)
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          const std::array<VertexId, 2> edge{tet[i], tet[j]};
          if (!held_by_removed(edge) && (chord(tet[i], tet[j]) || held_outside(edge))) return true;
          for (int k = j + 1; k < 4; ++k) {
            const std::array<VertexId, 3> face{tet[i], tet[j], tet[k]};
            if (!held_by_removed(face) && held_outside(face)) return true;
          }
        }
    return false;
  }

  // An S_M cap (a triangle (a, b, c) whose angle at c is wider than options_.cap_angle) gives the tets standing
  // on it a dihedral angle about as wide along the edges from c upwards, and no node move within S mends it:
  // the guards on S_M's tilt and sag hold c. So each cap with a tet outside the floors around its longest
  // edge (a, b) has that edge flipped to (c, d), d the apex of S_M's triangle across it (edge_removal),
  // if the two new S_M triangles' widest angle is narrower than the old ones', S_M stays embedded in P and
  // no less aligned with S (interface_flip), and no new tet is inverted or poorer than both mend_floor and
  // the worst tet it replaces. The new tets are then smoothed with the rest of the round's. Returns how
  // many caps had a tet outside the floors.
  int flip_surface_caps() {
    if (options_.cap_angle >= 180.0) return 0;
    int caps = 0;
    index_incident();
    const double floor = std::pow(mend_floor, 3);  // quality() is cubed
    const double cap_cosine = std::cos(options_.cap_angle * std::numbers::pi / 180.0);
    for (int s = 0; s < static_cast<int>(surfaces_.size()); ++s) {
      const SurfaceProjection& projection = *surfaces_[s];
      for (std::size_t k = 0; k < projection.triangles.size(); ++k) {
        const std::array<int, 3> triangle = projection.triangles[k];  // a flip below rewrites it
        const auto [corner, cosine] = widest_corner(s, triangle);
        if (cosine > cap_cosine) continue;
        const VertexId a = projection.nodes[triangle[(corner + 1) % 3]],
                       b = projection.nodes[triangle[(corner + 2) % 3]];
        const TetId start = tet_holding_edge(s, a, b);
        const std::vector<TetId> around = tets_around_edge(mesh_, start, a, b);
        if (std::ranges::none_of(
                around, [&](TetId t) { return worst_shape_over_floors(oriented_points(mesh_, t), floors_) < 1.0; }))
          continue;
        ++caps;
        std::optional<Retriangulation> flip = edge_removal(start, a, b, floor);
        if (!flip || !flip->surface_flip) continue;
        auto widest_cosine = [&](const std::array<std::array<int, 3>, 2>& pair) {
          return std::min(widest_corner(s, pair[0]).second, widest_corner(s, pair[1]).second);
        };
        if (widest_cosine(flip->surface_flip->created) <= widest_cosine(flip->surface_flip->removed)) continue;
        flip->widens_cap = true;
        apply(*flip);
      }
    }
    incident_.clear();
    return caps;
  }

  // The corner of S_M's triangle (node indices of surface s) with the widest angle, and its cosine.
  std::pair<int, double> widest_corner(int s, const std::array<int, 3>& triangle) const {
    const SurfaceProjection& projection = *surfaces_[s];
    std::pair<int, double> widest{0, 2.0};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& x = mesh_.points[projection.nodes[triangle[k]]];
      const Eigen::Vector3d u = mesh_.points[projection.nodes[triangle[(k + 1) % 3]]] - x,
                            w = mesh_.points[projection.nodes[triangle[(k + 2) % 3]]] - x;
      const double cosine = u.dot(w) / (u.norm() * w.norm());
      if (cosine < widest.second) widest = {k, cosine};
    }
    return widest;
  }

  // Points incident_ at a tet holding each vertex, for star_of.
  void index_incident() {
    incident_.assign(mesh_.points.size(), no_tet);
    for (TetId t = 0; t < mesh_.num_tets(); ++t)
      for (VertexId v : mesh_.tets[t]) incident_[v] = t;
  }

  // A tet holding surface s's S_M edge (a, b) (found from incident_).
  TetId tet_holding_edge(int s, VertexId a, VertexId b) const {
    const std::vector<TetId> around_a = star_of(a);
    const auto start = std::ranges::find_if(
        around_a, [&](TetId t) { return std::ranges::find(mesh_.tets[t], b) != mesh_.tets[t].end(); });
    if (start == around_a.end())
      throw MeshingError("an S_M edge of surface " + std::to_string(s) + " is not an edge of the mesh");
    return *start;
  }

  // The tets holding vertex v (found from incident_).
  std::vector<TetId> star_of(VertexId v) const {
    std::vector<TetId> star{incident_[v]};
    for (std::size_t i = 0; i < star.size(); ++i)
      for (int f = 0; f < 4; ++f) {
        const TetId n = mesh_.neighbours[star[i]][f];
        if (mesh_.tets[star[i]][f] != v && n != no_tet && std::ranges::find(star, n) == star.end()) star.push_back(n);
      }
    return star;
  }

  double worst_of_tets(std::span<const TetId> tets) const {
    double worst = std::numeric_limits<double>::infinity();
    for (TetId t : tets) worst = std::min(worst, quality(mesh_.oriented_tet(t)));
    return worst;
  }

  // Mends one crossing of surface s's S_M edge (a, b) by a crease line. If S_M's triangles (a, b, p) and
  // (b, a, q) have p and q on the line, by flipping (a, b) to (p, q), which lies along it. Otherwise by the
  // best of: moving a onto the crossing, moving b there (a node neither on the rim nor on a line already),
  // or splitting the edge there (the tets around it halved); the new or moved node lies at φ of the
  // crossing, on the crease edges of S. A mend must align the S_M triangles it changes better with S
  // (their worst alignment), keep S_M embedded in P, and leave no tet inverted or below both mend_floor
  // and the worst tet it changes. Whether a mend was made.
  bool mend_crossing(int s, const CreaseCrossing& crossing) {
    SurfaceProjection& projection = *surfaces_[s];
    const CreaseLine& line = projection.creases.lines[crossing.line];
    // A crossing at a line's end touches the rim of S or another line's end, where the node could not move.
    if (projection.on_rim[crossing.a] && projection.on_rim[crossing.b]) return false;
    if (!(crossing.s > 1e-9 * line.length() && crossing.s < (1.0 - 1e-9) * line.length())) return false;
    const VertexId a = projection.nodes[crossing.a], b = projection.nodes[crossing.b];
    const TetId start = tet_holding_edge(s, a, b);

    if (std::optional<Retriangulation> flip = edge_removal(start, a, b, mend_floor_); flip && flip->surface_flip) {
      bool along = true;
      for (const auto& triangle : flip->surface_flip->created)
        for (int node : triangle)
          if (node != crossing.a && node != crossing.b) along &= projection.creases.line_of[node] == crossing.line;
      if (along && acceptable(flip->worst_created, flip->worst_removed) && apply(*flip)) return true;
    }

    const Eigen::Vector3d point = projection.surface->evaluate(projection.surface->locate(crossing.at));
    int mover = -1;
    double best = unacceptable;
    for (int node : {crossing.a, crossing.b}) {
      if (projection.on_rim[node] || projection.creases.line_of[node] >= 0) continue;
      const VertexId v = projection.nodes[node];
      const std::vector<TetId> star = star_of(v);
      const std::vector<std::array<int, 3>> triangles = surface_triangles_around(s, v, star);
      const bool embedded = std::ranges::all_of(
          triangles, [&](const std::array<int, 3>& t) { return keeps_orientation(projection, t, node, crossing.at); });
      if (!embedded) continue;
      const double before = worst_of_tets(star);
      const double aligned_before = worst_alignment(s, triangles);
      const Eigen::Vector3d kept_point = mesh_.points[v];
      const Eigen::Vector2d kept_uv = projection.uv[node];
      mesh_.points[v] = point;
      projection.uv[node] = crossing.at;
      const double after = worst_of_tets(star);
      const bool aligned = worst_alignment(s, triangles) > aligned_before;
      mesh_.points[v] = kept_point;
      projection.uv[node] = kept_uv;
      if (aligned && acceptable(after, before) && after > best) {
        best = after;
        mover = node;
      }
    }

    const int vertices = mesh_.num_vertices();
    std::optional<Retriangulation> split = crease_split(s, crossing, point, start);
    if (split && split->worst_created > best && acceptable(split->worst_created, split->worst_removed) &&
        split_aligns(s, crossing, split->split_apexes) && apply(*split)) {
      add_split_node(s, crossing, split->split_apexes);
      return true;
    }
    drop_vertices_from(vertices);
    if (mover < 0) return false;
    mesh_.points[projection.nodes[mover]] = point;
    projection.uv[mover] = crossing.at;
    projection.creases.line_of[mover] = crossing.line;
    projection.creases.parameter[mover] = crossing.s;
    ++stats_.crease_moves;
    return true;
  }

  // Whether a mend whose worst new tet is `created` may replace tets whose worst is `removed`: if it is
  // valid and not below both `removed` and the floor (mend_floor, or the mesh's worst tet if that is
  // poorer): the mesh's worst tet never gets worse.
  bool acceptable(double created, double removed) const {
    return created > 0.0 && created >= std::min(removed, mend_floor_);
  }

  double worst_alignment(int s, std::span<const std::array<int, 3>> triangles) const {
    double worst = 1.0;
    for (const auto& triangle : triangles) worst = std::min(worst, triangle_alignment(s, triangle));
    return worst;
  }

  // Whether the halves of S_M's triangles (a, b, x) at the split's new vertex (the mesh's last, at
  // crossing.at in P) are better aligned with S than the triangles.
  bool split_aligns(int s, const CreaseCrossing& crossing, std::span<const VertexId> apexes) const {
    const SurfaceProjection& projection = *surfaces_[s];
    const Eigen::Vector3d& m = mesh_.points.back();
    const Eigen::Vector3d &xa = mesh_.points[projection.nodes[crossing.a]],
                          &xb = mesh_.points[projection.nodes[crossing.b]];
    const Eigen::Vector2d &ua = projection.uv[crossing.a], &ub = projection.uv[crossing.b];
    double before = 1.0, after = 1.0;
    for (VertexId x : apexes) {
      const Eigen::Vector2d& ux = projection.uv[node_index(s, x)];
      before = std::min(before, triangle_alignment(s, {crossing.a, crossing.b, node_index(s, x)}));
      after = std::min({after, alignment(s, {xa, m, mesh_.points[x]}, (ua + crossing.at + ux) / 3.0),
                        alignment(s, {m, xb, mesh_.points[x]}, (crossing.at + ub + ux) / 3.0)});
    }
    return after > before;
  }

  // S_M's triangles around its node v (surface s's interface faces among the tets of `star`), oriented.
  std::vector<std::array<int, 3>> surface_triangles_around(int s, VertexId v, std::span<const TetId> star) const {
    const SurfaceProjection& projection = *surfaces_[s];
    const auto& index = triangle_of_[s];
    std::vector<std::array<int, 3>> triangles;
    for (TetId t : star)
      for (int f = 0; f < 4; ++f) {
        const Tet& tet = mesh_.tets[t];
        if (tet[f] == v || mesh_.face_tags[t][f] != tag_of(s)) continue;
        std::array<int, 3> nodes;
        for (int k = 0; k < 3; ++k) nodes[k] = node_index(s, tet[face_vertices[f][k]]);
        const auto held = index.find(sorted_triangle(nodes));
        if (held == index.end()) continue;  // a triangle of the other half of a closed S_M
        const std::array<int, 3>& triangle = projection.triangles[held->second];
        if (std::ranges::find(triangles, triangle) == triangles.end()) triangles.push_back(triangle);
      }
    return triangles;
  }

  // The split of S_M's edge at `crossing` (surface s; `start` holds the edge): a new vertex at `point` (left in the mesh; the
  // caller keeps it with add_split_node or drops it), the tets around the edge halved through it, the
  // tagged faces around the edge halved with their tags. Nothing if a face around the edge lies on the
  // box or another surface.
  std::optional<Retriangulation> crease_split(int s, const CreaseCrossing& crossing, const Eigen::Vector3d& point,
                                              TetId start) {
    const SurfaceProjection& projection = *surfaces_[s];
    const VertexId a = projection.nodes[crossing.a], b = projection.nodes[crossing.b];

    GridPoint grid;
    for (int k = 0; k < 3; ++k)
      grid[k] = mesh_.grid[a][k] + std::llround(crossing.r * static_cast<double>(mesh_.grid[b][k] - mesh_.grid[a][k]));
    const VertexId m = mesh_.add_vertex(point, grid);
    surface_of_.push_back(projection.surface_index);
    projection_of_.push_back(s);
    node_index_.push_back(static_cast<int>(projection.nodes.size()));
    incident_.push_back(no_tet);

    Retriangulation r;
    r.removed = tets_around_edge(mesh_, start, a, b);
    r.worst_removed = worst_of_tets(r.removed);
    r.worst_created = std::numeric_limits<double>::infinity();
    std::vector<VertexId>& apexes = r.split_apexes;
    for (TetId t : r.removed) {
      const Tet oriented = mesh_.oriented_tet(t);
      for (VertexId replaced : {a, b}) {
        Tet created = oriented;
        created[local_index(oriented, replaced)] = m;
        r.worst_created = std::min(r.worst_created, new_tet_quality(created));
        r.created.push_back(created);
        r.flag_parent.push_back(t);
      }
      for (int f = 0; f < 4; ++f) {
        const VertexId opposite = mesh_.tets[t][f];
        const FaceTag tag = mesh_.face_tags[t][f];
        if (opposite == a || opposite == b || tag == no_face_tag) continue;
        if (mesh_.neighbours[t][f] == no_tet || tag != tag_of(s)) return std::nullopt;
        VertexId x = no_tet;
        for (VertexId v : mesh_.tets[t])
          if (v != a && v != b && v != opposite) x = v;
        if (std::ranges::find(apexes, x) != apexes.end()) continue;  // seen from the tet on its other side
        apexes.push_back(x);
        r.tagged_faces.push_back({sorted_face({a, m, x, b}, 3), tag});
        r.tagged_faces.push_back({sorted_face({m, b, x, a}, 3), tag});
      }
    }
    if (apexes.size() != 2) return std::nullopt;
    return r;
  }

  // Removes the vertices from `count` on (a split's vertex that was not kept).
  void drop_vertices_from(int count) {
    mesh_.points.resize(count);
    mesh_.grid.resize(count);
    surface_of_.resize(count);
    projection_of_.resize(count);
    node_index_.resize(count);
    incident_.resize(count);
  }

  // After a crease split of surface s's S_M at `crossing`: its new vertex (the mesh's last) becomes an S_M
  // node on the crease line, and S_M's triangles (a, b, x) become (a, m, x) and (m, b, x).
  void add_split_node(int s, const CreaseCrossing& crossing, std::span<const VertexId> apexes) {
    SurfaceProjection& projection = *surfaces_[s];
    const int node = static_cast<int>(projection.nodes.size());
    projection.nodes.push_back(mesh_.num_vertices() - 1);
    projection.uv.push_back(crossing.at);
    projection.on_rim.push_back(0);
    projection.creases.line_of.push_back(crossing.line);
    projection.creases.parameter.push_back(crossing.s);
    auto& index = triangle_index(s);
    for (VertexId x : apexes) {
      const int apex = node_index(s, x);
      const auto old = index.find(sorted_triangle({crossing.a, crossing.b, apex}));
      if (old == index.end()) throw MeshingError("a crease split did not find S_M's triangle");
      const int t = old->second;
      index.erase(old);
      std::array<int, 3>& triangle = projection.triangles[t];
      int i = 0;  // triangle = (triangle[i], triangle[i + 1], apex), cyclically
      while (triangle[(i + 2) % 3] != apex) ++i;
      const std::array<int, 3> first{triangle[i], node, apex}, second{node, triangle[(i + 1) % 3], apex};
      triangle = first;
      index.emplace(sorted_triangle(first), t);
      index.emplace(sorted_triangle(second), static_cast<int>(projection.triangles.size()));
      projection.triangles.push_back(second);
    }
  }

  // For each created tet, the removed tet whose region flags it takes: the one behind its interface faces
  // on the cavity's boundary (so that each interface face keeps V_M on the same side, which orients it),
  // else r.flag_parent. Empty if a created tet's interface faces disagree.
  std::vector<TetId> flag_parents(const Retriangulation& r, std::span<const BoundaryFace> boundary) const {
    std::vector<TetId> parents = r.flag_parent;
    auto same_flags = [&](TetId x, TetId y) {
      return std::all_of(regions_.begin(), regions_.end(),
                         [&](const TetRegion* region) { return (*region)[x] == (*region)[y]; });
    };
    for (std::size_t i = 0; i < r.created.size(); ++i) {
      bool on_interface = false;
      for (int f = 0; f < 4; ++f) {
        const auto key = sorted_face(r.created[i], f);
        const auto face =
            std::find_if(boundary.begin(), boundary.end(), [&](const BoundaryFace& b) { return b.key == key; });
        if (face == boundary.end() || !is_interface_tag(face->tag)) continue;
        if (on_interface && !same_flags(face->owner, parents[i])) return {};
        on_interface = true;
        parents[i] = face->owner;
      }
    }
    return parents;
  }

  static std::array<VertexId, 3> sorted_face(const Tet& tet, int f) {
    std::array<VertexId, 3> key{tet[face_vertices[f][0]], tet[face_vertices[f][1]], tet[face_vertices[f][2]]};
    std::sort(key.begin(), key.end());
    return key;
  }

  // The tets around the edge (a, b) of tet t = T_0, in ring order, with their ring vertices, and the
  // interface faces around the edge, if it lies inside S_M.
  struct EdgeRing {
    std::vector<TetId> tets;         // T_0..T_{m-1}
    std::vector<VertexId> vertices;  // r_0..r_{m-1}
    FaceTag interface = no_face_tag;
    std::vector<int> on_interface;  // ring indices i of the interface faces (a, b, r_i)
  };

  // Nothing if the edge is on the mesh's boundary, has more than options_.max_ring tets around it, or
  // has tagged faces around it other than at most two of one interface.
  std::optional<EdgeRing> ring_around(TetId t, VertexId a, VertexId b) const {
    const Tet& first = mesh_.tets[t];
    EdgeRing around;
    std::vector<VertexId>& ring = around.vertices;
    for (VertexId v : first)
      if (v != a && v != b) ring.push_back(v);
    around.tets.push_back(t);
    for (TetId current = t;;) {
      // Cross the face of T_i opposite r_i, which holds a, b and r_{i+1}.
      const int i = static_cast<int>(around.tets.size()) - 1;
      const int face = local_index(mesh_.tets[current], ring[i]);
      if (const FaceTag tag = mesh_.face_tags[current][face]; tag != no_face_tag) {
        if (!is_interface_tag(tag) || (around.interface != no_face_tag && tag != around.interface) ||
            around.on_interface.size() == 2)
          return std::nullopt;
        around.interface = tag;
        around.on_interface.push_back(i + 1);
      }
      const TetId next = mesh_.neighbours[current][face];
      if (next == no_tet) return std::nullopt;
      if (next == t) break;
      if (static_cast<int>(around.tets.size()) == options_.max_ring) return std::nullopt;
      const VertexId shared = ring.back();
      for (VertexId v : mesh_.tets[next])
        if (v != a && v != b && v != shared) ring.push_back(v);
      around.tets.push_back(next);
      current = next;
    }
    ring.pop_back();  // r_m is r_0
    return around;
  }

  // With an interface, starts the ring at r_p (a rotation keeps its order): the diagonal is then
  // (r_0, r_q). Returns q (0 without an interface), nothing if (r_p, r_q) is not a diagonal.
  static std::optional<int> start_at_interface(EdgeRing& around) {
    if (around.on_interface.empty()) return 0;
    const int m = static_cast<int>(around.tets.size());
    const int p = around.on_interface[0] % m;
    std::rotate(around.vertices.begin(), around.vertices.begin() + p, around.vertices.end());
    std::rotate(around.tets.begin(), around.tets.begin() + p, around.tets.end());
    const int q = (around.on_interface[1] % m - p + m) % m;
    if (q < 2 || q > m - 2) return std::nullopt;  // r_p and r_q adjacent: (r_p, r_q) is not a diagonal
    return q;
  }

  // best[i][j]: the best worst tet over the triangulations of the sub-polygon r_i..r_j; split[i][j] its
  // apex.
  struct RingTriangulations {
    std::vector<std::vector<double>> best;
    std::vector<std::vector<int>> split;
  };

  // The best triangulations of the `polygons` of the closed ring r_0..r_m, each triangle (i, k, j)
  // making the tets (a, r_i, r_k, r_j) and (b, r_i, r_j, r_k).
  RingTriangulations best_triangulations(VertexId a, VertexId b, const std::vector<VertexId>& ring,
                                         std::span<const std::pair<int, int>> polygons) const {
    const int m = static_cast<int>(ring.size()) - 1;
    std::vector<std::vector<double>> best(m + 1, std::vector<double>(m + 1, std::numeric_limits<double>::infinity()));
    std::vector<std::vector<int>> split(m + 1, std::vector<int>(m + 1, -1));
    auto triangle_quality = [&](int i, int k, int j) {
      return std::min(new_tet_quality({a, ring[i], ring[k], ring[j]}), new_tet_quality({b, ring[i], ring[j], ring[k]}));
    };
    for (const auto& [lo, hi] : polygons)
      for (int width = 2; width <= hi - lo; ++width)
        for (int i = lo; i + width <= hi; ++i) {
          const int j = i + width;
          best[i][j] = unacceptable;
          for (int k = i + 1; k < j; ++k) {
            const double worst = std::min({best[i][k], best[k][j], triangle_quality(i, k, j)});
            if (worst > best[i][j]) {
              best[i][j] = worst;
              split[i][j] = k;
            }
          }
        }
    return {std::move(best), std::move(split)};
  }

  // Adds to r the tets of the triangulations `split` of the `polygons` of the closed ring.
  static void add_triangulated_tets(Retriangulation& r, VertexId a, VertexId b, const std::vector<VertexId>& ring,
                                    std::span<const std::pair<int, int>> polygons,
                                    const std::vector<std::vector<int>>& split) {
    for (const auto& [lo, hi] : polygons) {
      // The tets over the sub-polygon lo..hi lie where T_lo .. T_{hi-1} were: on one side of S_M.
      const TetId side = r.removed[lo];
      std::vector<std::pair<int, int>> pending{{lo, hi}};
      while (!pending.empty()) {
        const auto [i, j] = pending.back();
        pending.pop_back();
        if (j - i < 2) continue;
        const int k = split[i][j];
        r.created.push_back({a, ring[i], ring[k], ring[j]});
        r.created.push_back({b, ring[i], ring[j], ring[k]});
        r.flag_parent.insert(r.flag_parent.end(), 2, side);
        pending.push_back({i, k});
        pending.push_back({k, j});
      }
    }
  }

  // The tets around the interior edge (a, b) as a ring T_0..T_{m-1} with ring vertices r_0..r_{m-1},
  // T_i = (a, b, r_i, r_{i+1}), replaced by the tets (a, r_i, r_k, r_j) and (b, r_i, r_j, r_k) over the
  // triangles (i < k < j) of the ring polygon's triangulation whose worst tet is best. When (a, b) is an
  // edge inside S_M, two of the faces around it, (a, b, r_p) and (a, b, r_q), are interface faces: the
  // triangulation must then hold the diagonal (r_p, r_q), whose faces (a, r_p, r_q) and (b, r_p, r_q)
  // become the interface there (interface_flip decides whether S_M may take them). Nothing unless the
  // worst new tet beats the worst removed one, or `floor` if that is lower.
  std::optional<Retriangulation> edge_removal(TetId t, VertexId a, VertexId b,
                                              double floor = std::numeric_limits<double>::infinity()) const {
    std::optional<EdgeRing> around = ring_around(t, a, b);
    if (!around || around->on_interface.size() == 1) return std::nullopt;  // 1: a rim edge
    std::vector<VertexId>& ring = around->vertices;
    if (!same_orientation(mesh_.oriented_tet(t), {a, b, ring[0], ring[1]})) std::swap(a, b);
    const std::optional<int> diagonal_end = start_at_interface(*around);
    if (!diagonal_end) return std::nullopt;
    const int q = *diagonal_end;

    Retriangulation r;
    r.removed = std::move(around->tets);
    r.worst_removed = std::numeric_limits<double>::infinity();
    for (TetId removed : r.removed) r.worst_removed = std::min(r.worst_removed, quality(mesh_.oriented_tet(removed)));

    // The ring closes with r_m = r_0, so that the sub-polygons r_0..r_q and r_q..r_m split the ring
    // along the diagonal.
    const int m = static_cast<int>(r.removed.size());
    ring.push_back(ring[0]);
    const std::vector<std::pair<int, int>> polygons =
        q == 0 ? std::vector<std::pair<int, int>>{{0, m - 1}} : std::vector<std::pair<int, int>>{{0, q}, {q, m}};
    const RingTriangulations triangulations = best_triangulations(a, b, ring, polygons);
    r.worst_created = std::numeric_limits<double>::infinity();
    for (const auto& [lo, hi] : polygons) r.worst_created = std::min(r.worst_created, triangulations.best[lo][hi]);
    if (!(r.worst_created > std::min(r.worst_removed, floor))) return std::nullopt;
    if (q != 0) {
      const FaceTag interface = around->interface;
      r.surface_flip = interface_flip(interface, a, b, ring[0], ring[q]);
      if (!r.surface_flip) return std::nullopt;
      r.tagged_faces = {{sorted_face({a, ring[0], ring[q], b}, 3), interface},
                        {sorted_face({b, ring[0], ring[q], a}, 3), interface}};
    }
    add_triangulated_tets(r, a, b, ring, polygons, triangulations.split);
    return r;
  }

  // Whether S_M may exchange its triangles (a, b, p) and (b, a, q) for two triangles over (p, q): the
  // diagonal must cross (a, b) in P (so S_M stays embedded in P, as step 4 keeps it), and the new
  // triangles' normals may deviate from S's (at their centroids in P) no more than the old ones' do.
  // Returns the new triangles as node indices of the surface, oriented like S in P.
  // Nothing if no projection of that interface holds both triangles (an edge on a closed S_M's cut).
  std::optional<SurfaceFlip> interface_flip(FaceTag interface, VertexId a, VertexId b, VertexId p, VertexId q) const {
    const int surface = projection_holding(interface, a, b, p, q);
    if (surface < 0) return std::nullopt;
    const SurfaceProjection& projection = *surfaces_[surface];
    const int na = node_index(surface, a), nb = node_index(surface, b), np = node_index(surface, p),
              nq = node_index(surface, q);
    auto uv = [&](int node) { return projection.uv[node]; };
    auto orient = [&](int x, int y, int z) { return cross2(uv(y) - uv(x), uv(z) - uv(x)); };
    if (!(orient(np, nq, na) * orient(np, nq, nb) < 0.0) || !(orient(na, nb, np) * orient(na, nb, nq) < 0.0))
      return std::nullopt;
    auto alignment = [&](int x, int y, int z) { return triangle_alignment(surface, {x, y, z}); };
    if (std::min(alignment(np, nq, na), alignment(np, nq, nb)) < std::min(alignment(na, nb, np), alignment(na, nb, nq)))
      return std::nullopt;
    SurfaceFlip flip{surface, {}, {}};
    flip.removed = {sorted_triangle({na, nb, np}), sorted_triangle({na, nb, nq})};
    flip.created = {std::array<int, 3>{np, nq, na}, std::array<int, 3>{nq, np, nb}};
    for (auto& triangle : flip.created)
      if ((orient(triangle[0], triangle[1], triangle[2]) > 0.0) != (projection.orientation > 0))
        std::swap(triangle[1], triangle[2]);
    return flip;
  }

  // The cosine between the normal of the triangle with corners x and S's normal at `at` in P (surface s):
  // 1 where the triangle lies along S.
  double alignment(int s, const std::array<Eigen::Vector3d, 3>& x, const Eigen::Vector2d& at) const {
    const ParametricSurface& surface = *surfaces_[s]->surface;
    return surface.alignment(x, surface.locate(at).triangle);
  }
  // The alignment of S_M's triangle over surface s's nodes, at its centroid in P.
  double triangle_alignment(int s, const std::array<int, 3>& nodes) const {
    const SurfaceProjection& projection = *surfaces_[s];
    std::array<Eigen::Vector3d, 3> x;
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) {
      x[k] = mesh_.points[projection.nodes[nodes[k]]];
      centroid += projection.uv[nodes[k]] / 3.0;
    }
    return alignment(s, x, centroid);
  }

  // The projection of the S_M tagged `interface` whose triangles include (a, b, p) and (a, b, q), or -1.
  int projection_holding(FaceTag interface, VertexId a, VertexId b, VertexId p, VertexId q) const {
    for (int s = 0; s < static_cast<int>(surfaces_.size()); ++s) {
      if (tag_of(s) != interface) continue;
      const int na = node_index(s, a), nb = node_index(s, b), np = node_index(s, p), nq = node_index(s, q);
      if (na < 0 || nb < 0 || np < 0 || nq < 0) continue;
      const auto& index = triangle_of_[s];
      if (index.contains(sorted_triangle({na, nb, np})) && index.contains(sorted_triangle({na, nb, nq}))) return s;
    }
    return -1;
  }

  // Vertex v's index in the nodes of projection s, or -1 if it is not one of them.
  int node_index(int s, VertexId v) const {
    if (projection_of_[v] == s) return node_index_[v];
    if (projection_of_[v] != shared_node) return -1;
    const auto found = shared_index_.find({s, v});
    return found == shared_index_.end() ? -1 : found->second;
  }

  FaceTag tag_of(int s) const { return interface_tag(surfaces_[s]->surface_index); }

  static std::array<int, 3> sorted_triangle(std::array<int, 3> triangle) {
    std::sort(triangle.begin(), triangle.end());
    return triangle;
  }

  // Tets t and its neighbour across face f, sharing the untagged face (x, y, z), replaced by the three tets
  // around the new edge from t's apex to the neighbour's: t's own vertex order with one face vertex
  // replaced by the neighbour's apex, so that each keeps its orientation.
  std::optional<Retriangulation> flip_2_3(TetId t, int f) const {
    const TetId n = mesh_.neighbours[t][f];
    if (n == no_tet || mesh_.face_tags[t][f] != no_face_tag) return std::nullopt;
    const Tet& tv = mesh_.tets[t];
    const Tet& nv = mesh_.tets[n];
    const VertexId apex = nv[mesh_.face_towards(n, t)];
    Retriangulation r;
    r.removed = {t, n};
    r.worst_removed = std::min(quality(mesh_.oriented_tet(t)), quality(mesh_.oriented_tet(n)));
    r.worst_created = std::numeric_limits<double>::infinity();
    const Tet oriented = mesh_.oriented_tet(t);
    for (VertexId replaced : tv) {
      if (replaced == tv[f]) continue;
      Tet created = oriented;
      created[local_index(oriented, replaced)] = apex;
      r.worst_created = std::min(r.worst_created, new_tet_quality(created));
      r.created.push_back(created);
      r.flag_parent.push_back(t);
    }
    return r;
  }

  // The faces of the cavity's boundary: each with the removed tet behind it and the tet (and its local
  // face) in front, or no_tet on the box.
  std::vector<BoundaryFace> cavity_boundary(std::span<const TetId> removed) const {
    std::vector<BoundaryFace> boundary;
    for (TetId t : removed)
      for (int f = 0; f < 4; ++f) {
        const TetId n = mesh_.neighbours[t][f];
        if (std::find(removed.begin(), removed.end(), n) != removed.end()) continue;
        boundary.push_back(
            {sorted_face(mesh_.tets[t], f), t, n, n == no_tet ? -1 : mesh_.face_towards(n, t), mesh_.face_tags[t][f]});
      }
    return boundary;
  }

  // `count` tet slots: the removed tets' first, then free ones, then new ones. Removed tets left over
  // become free.
  std::vector<TetId> take_slots(std::span<const TetId> removed, std::size_t count) {
    std::vector<TetId> slots(removed.begin(), removed.end());
    while (slots.size() < count) {
      if (!free_.empty()) {
        slots.push_back(free_.back());
        free_.pop_back();
        continue;
      }
      slots.push_back(mesh_.num_tets());
      mesh_.tets.emplace_back();
      mesh_.kinds.emplace_back();
      mesh_.neighbours.emplace_back();
      mesh_.face_tags.emplace_back();
      for (TetRegion* region : regions_) region->push_back(0);
    }
    for (std::size_t i = count; i < slots.size(); ++i) {
      mesh_.tets[slots[i]] = {-1, -1, -1, -1};
      mesh_.neighbours[slots[i]] = {no_tet, no_tet, no_tet, no_tet};
      free_.push_back(slots[i]);
    }
    slots.resize(count);
    return slots;
  }

  // Replaces r.removed by r.created, unless the region flags cannot follow (flag_parents): the created
  // tets inherit the tags and neighbours of the cavity's boundary faces and are each other's neighbours
  // across the faces inside it, tagged as r.tagged_faces says; S_M takes r.surface_flip.
  bool apply(const Retriangulation& r) {
    const std::vector<BoundaryFace> boundary = cavity_boundary(r.removed);
    const std::vector<TetId> parents = flag_parents(r, boundary);
    if (parents.empty()) return false;
    std::vector<std::vector<std::uint8_t>> flags(regions_.size());
    for (std::size_t k = 0; k < regions_.size(); ++k)
      for (TetId parent : parents) flags[k].push_back((*regions_[k])[parent]);

    const std::vector<TetId> slots = take_slots(r.removed, r.created.size());
    created_.insert(created_.end(), slots.begin(), slots.end());
    for (std::size_t i = 0; i < slots.size(); ++i) {
      mesh_.tets[slots[i]] = r.created[i];
      mesh_.kinds[slots[i]] = TetKind::remeshed();
      if (!incident_.empty())
        for (VertexId v : r.created[i]) incident_[v] = slots[i];
      for (std::size_t k = 0; k < regions_.size(); ++k) (*regions_[k])[slots[i]] = flags[k][i];
    }
    std::size_t linked = 0;
    for (std::size_t i = 0; i < slots.size(); ++i)
      for (int f = 0; f < 4; ++f) {
        const auto key = sorted_face(r.created[i], f);
        TetId& neighbour = mesh_.neighbours[slots[i]][f];
        FaceTag& tag = mesh_.face_tags[slots[i]][f];
        const auto outer =
            std::find_if(boundary.begin(), boundary.end(), [&](const BoundaryFace& b) { return b.key == key; });
        if (outer != boundary.end()) {
          neighbour = outer->neighbour;
          tag = outer->tag;
          if (neighbour != no_tet) mesh_.neighbours[neighbour][outer->neighbour_face] = slots[i];
          ++linked;
          continue;
        }
        neighbour = no_tet;
        for (std::size_t k = 0; k < slots.size() && neighbour == no_tet; ++k)
          for (int g = 0; g < 4; ++g)
            if (k != i && sorted_face(r.created[k], g) == key) neighbour = slots[k];
        if (neighbour == no_tet)
          throw MeshingError("a flip left a face of tet " + std::to_string(slots[i]) + " without a neighbour");
        const auto tagged = std::find_if(r.tagged_faces.begin(), r.tagged_faces.end(),
                                         [&](const auto& face) { return face.first == key; });
        tag = tagged == r.tagged_faces.end() ? no_face_tag : tagged->second;
      }
    if (linked != boundary.size()) throw MeshingError("a flip changed the boundary of the tets it replaced");
    if (r.surface_flip) flip_surface_triangles(*r.surface_flip);

    const auto m = r.removed.size();
    if (!r.split_apexes.empty()) ++stats_.crease_splits;
    else if (r.widens_cap) ++stats_.cap_flips;
    else if (r.surface_flip) ++stats_.surface_edge_flips;
    else if (m == 2) ++stats_.flips_2_3;
    else if (m == 3 && r.created.size() == 2) ++stats_.flips_3_2;
    else if (m == 4) ++stats_.flips_4_4;
    else ++stats_.edge_removals;
    stats_.tets_removed += static_cast<std::int64_t>(m);
    stats_.tets_created += static_cast<std::int64_t>(r.created.size());
    return true;
  }

  // Surface s's S_M triangles by their sorted node indices, built when first needed.
  std::map<std::array<int, 3>, int>& triangle_index(int s) {
    if (triangle_of_.empty()) triangle_of_.resize(surfaces_.size());
    auto& index = triangle_of_[s];
    if (index.empty()) {
      const auto& triangles = surfaces_[s]->triangles;
      for (int t = 0; t < static_cast<int>(triangles.size()); ++t) index.emplace(sorted_triangle(triangles[t]), t);
    }
    return index;
  }

  void flip_surface_triangles(const SurfaceFlip& flip) {
    std::vector<std::array<int, 3>>& triangles = surfaces_[flip.surface]->triangles;
    auto& index = triangle_index(flip.surface);
    for (int k = 0; k < 2; ++k) {
      const auto old = index.find(flip.removed[k]);
      if (old == index.end()) throw MeshingError("an edge flip inside S_M did not find S_M's triangle");
      const int t = old->second;
      index.erase(old);
      triangles[t] = flip.created[k];
      index.emplace(sorted_triangle(flip.created[k]), t);
    }
  }

  // Removes the free slots, keeping the live tets' order.
  void compact() {
    if (free_.empty()) return;
    std::vector<TetId> renumbered(mesh_.tets.size(), no_tet);
    TetId live = 0;
    for (TetId t = 0; t < mesh_.num_tets(); ++t)
      if (!dead(t)) renumbered[t] = live++;
    for (TetId t = 0; t < mesh_.num_tets(); ++t) {
      const TetId to = renumbered[t];
      if (to == no_tet) continue;
      mesh_.tets[to] = mesh_.tets[t];
      mesh_.kinds[to] = mesh_.kinds[t];
      mesh_.face_tags[to] = mesh_.face_tags[t];
      for (TetRegion* region : regions_) (*region)[to] = (*region)[t];
      for (int f = 0; f < 4; ++f) {
        const TetId n = mesh_.neighbours[t][f];
        mesh_.neighbours[to][f] = n == no_tet ? no_tet : renumbered[n];
      }
    }
    mesh_.tets.resize(live);
    mesh_.kinds.resize(live);
    mesh_.face_tags.resize(live);
    mesh_.neighbours.resize(live);
    for (TetRegion* region : regions_) region->resize(live);
    free_.clear();
  }

  TetMesh& mesh_;
  std::span<SurfaceProjection* const> surfaces_;
  std::span<TetRegion* const> regions_;  // per-tet flags that follow the flips
  const ImprovementOptions& options_;
  const ShapeFloors floors_;  // the shape passes' floors: a cap is flipped under a tet outside them
  // The surfaces_ are projections: one per S_M, or two for a closed one (stages/projection.hpp), whose
  // nodes on the cut are in both.
  static constexpr int shared_node = -2;
  std::vector<int> surface_of_;     // the surface (interface index) whose S_M holds each vertex, or -1
  std::vector<int> projection_of_;  // the projection holding each vertex, -1, or shared_node
  std::vector<int> node_index_;     // each vertex's index in projection_of_'s nodes, or -1
  std::map<std::pair<int, VertexId>, int> shared_index_;  // (projection, shared vertex) -> its index there
  // Per surface, S_M's triangles by their sorted node indices (triangle_index).
  std::vector<std::map<std::array<int, 3>, int>> triangle_of_;
  std::vector<TetId> incident_;  // while mending creases or caps, or untangling: a tet holding each vertex
  double mend_floor_ = 0.0;      // while mending creases: see acceptable()
  bool untangling_ = false;      // flipping around inverted tets (untangle)
  std::vector<TetId> free_;      // slots of removed tets not yet reused
  std::vector<TetId> created_;   // the slots filled by this pass's flips
  FlipStats stats_;
};

}  // namespace

// Every count of FlipStats, for the arithmetic below.
constexpr std::array flip_counts{&FlipStats::flips_2_3,     &FlipStats::flips_3_2,          &FlipStats::flips_4_4,
                                 &FlipStats::edge_removals, &FlipStats::surface_edge_flips, &FlipStats::cap_flips,
                                 &FlipStats::crease_splits, &FlipStats::crease_moves,       &FlipStats::tets_removed,
                                 &FlipStats::tets_created};

FlipStats& FlipStats::operator+=(const FlipStats& other) {
  for (auto count : flip_counts) this->*count += other.*count;
  return *this;
}

FlipStats operator-(FlipStats a, const FlipStats& b) {
  for (auto count : flip_counts) a.*count -= b.*count;
  return a;
}

std::string describe(const FlipStats& flips) {
  return std::to_string(flips.flips_2_3) + " 2-3, " + std::to_string(flips.flips_3_2) + " 3-2, " +
         std::to_string(flips.flips_4_4) + " 4-4 flips, " + std::to_string(flips.edge_removals) +
         " larger edge removals, " + std::to_string(flips.surface_edge_flips) + " edge flips inside S_M, " +
         std::to_string(flips.cap_flips) + " S_M caps flipped, " + std::to_string(flips.crease_moves) +
         " S_M nodes moved onto creases, " + std::to_string(flips.crease_splits) + " S_M edges split at creases";
}

FlipStats flip_worst_tets(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                          std::span<TetRegion* const> regions, const ImprovementOptions& options) {
  return Flipper(mesh, surfaces, regions, options).run();
}

FlipStats flip_inverted_tets(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                             std::span<TetRegion* const> regions, const ImprovementOptions& options) {
  return Flipper(mesh, surfaces, regions, options).untangle();
}

FlipStats conform_to_creases(TetMesh& mesh, std::span<SurfaceProjection* const> surfaces,
                             std::span<TetRegion* const> regions, const ImprovementOptions& options) {
  return Flipper(mesh, surfaces, regions, options).conform_to_creases();
}

}  // namespace meccano
