#include <meccano/stages/surface_approximation.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/narrow_rim.hpp>

#include <meccano/error.hpp>
#include <meccano/mesh/bisection.hpp>

#include "mesh/topology_helpers.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>
#include <sstream>

namespace meccano {
namespace {

using detail::Edge;
using detail::make_edge;
using detail::TopologyScratch;
using detail::triangle_topology;
using detail::TriangleTopology;
using detail::UnionFind;

bool edge_is_axis_parallel(const TetMesh& mesh, VertexId a, VertexId b) {
  int differing = 0;
  for (int k = 0; k < 3; ++k) differing += mesh.grid[a][k] != mesh.grid[b][k];
  return differing == 1;
}

bool on_box_boundary(const TetMesh& mesh, VertexId v) { return mesh.meccano.box_planes(mesh.grid[v]) != 0; }

// Squared length in computational coordinates; the lengths of a triangle's edges differ by factors
// of at least sqrt(2) when they differ at all, far above rounding.
double squared_grid_length(const TetMesh& mesh, const Edge& e) {
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = static_cast<double>(mesh.grid[e.first][k] - mesh.grid[e.second][k]);
    sum += d * d;
  }
  return sum;
}

void set_face_tag(TetMesh& mesh, TetId t, int f, FaceTag tag) {
  mesh.face_tags[t][f] = tag;
  const TetId across = mesh.neighbours[t][f];
  if (across != no_tet) mesh.face_tags[across][mesh.face_towards(across, t)] = tag;
}

bool is_volume_boundary_face(const TetMesh& mesh, const TetRegion& volumetric, TetId t, int f) {
  const TetId across = mesh.neighbours[t][f];
  return volumetric[t] && (across == no_tet || !volumetric[across]);
}

std::array<VertexId, 3> face_nodes(const TetMesh& mesh, TetId t, int f) {
  const auto& v = mesh.tets[t];
  return {v[face_vertices[f][0]], v[face_vertices[f][1]], v[face_vertices[f][2]]};
}


// Labels of the components of a set of faces joined across shared edges (only edges whose two faces
// both pass `joined`), and the label of the largest.
template <class Joined>
std::vector<std::size_t> edge_components(const std::vector<std::array<VertexId, 3>>& faces, Joined joined) {
  std::vector<std::pair<Edge, std::size_t>> edges;
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) edges.push_back({make_edge(faces[i][k], faces[i][(k + 1) % 3]), i});
  std::sort(edges.begin(), edges.end());
  UnionFind components(faces.size());
  for (std::size_t i = 0; i + 1 < edges.size(); ++i)
    if (edges[i].first == edges[i + 1].first && joined(edges[i].second, edges[i + 1].second))
      components.join(edges[i].second, edges[i + 1].second);
  std::vector<std::size_t> label(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i) label[i] = components.find(i);
  return label;
}

// S_M as read from the face tags: its faces (by their V_M tet), edges, rim and per-node flags.
struct Interface {
  std::vector<FaceRef> faces;
  std::vector<std::array<VertexId, 3>> nodes;
  std::vector<std::pair<Edge, int>> edge_faces;  // sorted by edge
  std::vector<Edge> rim_edges;                   // sorted
  std::vector<std::uint8_t> on_rim;              // per vertex
  std::vector<std::uint8_t> on_interface;        // per vertex
  std::vector<std::uint8_t> on_other_interface;  // per vertex: on a face tagged for another surface

  bool is_rim_edge(VertexId a, VertexId b) const {
    return std::binary_search(rim_edges.begin(), rim_edges.end(), make_edge(a, b));
  }
  template <class Visit>
  void for_each_face_on_edge(const Edge& e, Visit visit) const {
    auto it = std::lower_bound(edge_faces.begin(), edge_faces.end(), std::pair<Edge, int>{e, -1});
    for (; it != edge_faces.end() && it->first == e; ++it) visit(it->second);
  }
};

Interface read_interface(const TetMesh& mesh, const TetRegion& volumetric, FaceTag tag) {
  Interface s;
  s.on_rim.assign(mesh.points.size(), 0);
  s.on_interface.assign(mesh.points.size(), 0);
  s.on_other_interface.assign(mesh.points.size(), 0);
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      const FaceTag face_tag = mesh.face_tags[t][f];
      if (!is_interface_tag(face_tag)) continue;
      const auto nodes = face_nodes(mesh, t, f);
      if (face_tag != tag) {
        for (VertexId v : nodes) s.on_other_interface[v] = 1;
      } else if (volumetric[t]) {
        s.faces.push_back({t, f});
        s.nodes.push_back(nodes);
        for (VertexId v : nodes) s.on_interface[v] = 1;
      }
    }
  s.edge_faces = detail::edges_with_triangles(s.nodes);
  for (std::size_t i = 0; i < s.edge_faces.size();) {
    std::size_t j = i + 1;
    while (j < s.edge_faces.size() && s.edge_faces[j].first == s.edge_faces[i].first) ++j;
    if (j - i == 1) {
      s.rim_edges.push_back(s.edge_faces[i].first);
      s.on_rim[s.edge_faces[i].first.first] = s.on_rim[s.edge_faces[i].first.second] = 1;
    }
    i = j;
  }
  return s;
}

// The boundary faces of V_M off the box, with whether each is in S_M.
struct VolumeBoundary {
  std::vector<FaceRef> faces;
  std::vector<std::array<VertexId, 3>> nodes;
  std::vector<std::uint8_t> on_box;
};

VolumeBoundary read_volume_boundary(const TetMesh& mesh, const TetRegion& volumetric) {
  VolumeBoundary b;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f)
      if (is_volume_boundary_face(mesh, volumetric, t, f)) {
        b.faces.push_back({t, f});
        b.nodes.push_back(face_nodes(mesh, t, f));
        b.on_box.push_back(mesh.neighbours[t][f] == no_tet);
      }
  return b;
}

// Keeps the largest component of S_M and fills its holes (all components of the rest of ∂V_M but the
// largest, unless they reach the box). Returns {faces removed, faces added}.
std::pair<std::int64_t, std::int64_t> keep_one_component_without_holes(TetMesh& mesh, const TetRegion& volumetric,
                                                                       FaceTag tag) {
  const VolumeBoundary boundary = read_volume_boundary(mesh, volumetric);
  const std::size_t n = boundary.faces.size();
  std::vector<std::uint8_t> in_interface(n);
  for (std::size_t i = 0; i < n; ++i)
    in_interface[i] = mesh.face_tags[boundary.faces[i].tet][boundary.faces[i].local_face] == tag;
  const auto label =
      edge_components(boundary.nodes, [&](std::size_t a, std::size_t b) { return in_interface[a] == in_interface[b]; });
  // Component sizes, per side of the partition.
  std::vector<std::int64_t> size(n, 0);
  std::vector<std::uint8_t> reaches_box(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    ++size[label[i]];
    if (boundary.on_box[i]) reaches_box[label[i]] = 1;
  }
  std::array<std::size_t, 2> largest{n, n};  // per value of in_interface
  for (std::size_t i = 0; i < n; ++i) {
    auto& best = largest[in_interface[i]];
    if (best == n || size[label[i]] > size[best]) best = label[i];
  }
  std::int64_t removed = 0, added = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const FaceRef& face = boundary.faces[i];
    if (in_interface[i] && label[i] != largest[1]) {
      set_face_tag(mesh, face.tet, face.local_face, no_face_tag);
      ++removed;
    } else if (!in_interface[i] && label[i] != largest[0] && !reaches_box[label[i]]) {
      set_face_tag(mesh, face.tet, face.local_face, tag);
      ++added;
    }
  }
  return {removed, added};
}

// Adds the boundary face of V_M across every oblique rim edge until the rim is axis-parallel.
std::int64_t make_rim_axis_parallel(TetMesh& mesh, const TetRegion& volumetric, FaceTag tag) {
  std::int64_t added = 0;
  for (;;) {
    const Interface s = read_interface(mesh, volumetric, tag);
    std::int64_t added_now = 0;
    for (const Edge& e : s.rim_edges) {
      if (edge_is_axis_parallel(mesh, e.first, e.second)) continue;
      int face = -1;
      s.for_each_face_on_edge(e, [&](int i) { face = i; });
      for (TetId u : tets_around_edge(mesh, s.faces[face].tet, e.first, e.second)) {
        if (!volumetric[u]) continue;
        for (int g = 0; g < 4; ++g) {
          const VertexId opposite = mesh.tets[u][g];
          if (opposite == e.first || opposite == e.second) continue;
          if (!is_volume_boundary_face(mesh, volumetric, u, g) || mesh.neighbours[u][g] == no_tet) continue;
          if (mesh.face_tags[u][g] == tag) continue;
          set_face_tag(mesh, u, g, tag);
          ++added_now;
        }
      }
    }
    if (added_now == 0) return added;
    added += added_now;
  }
}

// The S_M faces of the squares of `seeds`: the seeds and every S_M face reachable from them across
// oblique edges (per face of s, 1 if taken).
std::vector<std::uint8_t> faces_of_squares(const TetMesh& mesh, const Interface& s, std::vector<int> seeds) {
  std::vector<std::uint8_t> taken(s.faces.size(), 0);
  for (int f : seeds) taken[f] = 1;
  while (!seeds.empty()) {
    const int f = seeds.back();
    seeds.pop_back();
    for (int k = 0; k < 3; ++k) {
      const VertexId a = s.nodes[f][k], b = s.nodes[f][(k + 1) % 3];
      if (edge_is_axis_parallel(mesh, a, b)) continue;
      s.for_each_face_on_edge(make_edge(a, b), [&](int g) {
        if (!taken[g]) {
          taken[g] = 1;
          seeds.push_back(g);
        }
      });
    }
  }
  return taken;
}

// Untags the given S_M faces together with their squares, so that the rim stays axis-parallel.
void remove_with_squares(TetMesh& mesh, const Interface& s, const std::vector<int>& seeds) {
  const std::vector<std::uint8_t> removed = faces_of_squares(mesh, s, seeds);
  for (std::size_t f = 0; f < s.faces.size(); ++f)
    if (removed[f]) set_face_tag(mesh, s.faces[f].tet, s.faces[f].local_face, no_face_tag);
}

bool all_on_rim(const Interface& s, int face) {
  return s.on_rim[s.nodes[face][0]] && s.on_rim[s.nodes[face][1]] && s.on_rim[s.nodes[face][2]];
}

// Corbels: two S_M faces sharing an edge, all of their nodes on the rim. Returns one face of each.
std::vector<int> find_corbels(const Interface& s) {
  std::vector<int> corbels;
  for (std::size_t i = 0; i + 1 < s.edge_faces.size(); ++i)
    if (s.edge_faces[i].first == s.edge_faces[i + 1].first) {
      const int a = s.edge_faces[i].second, b = s.edge_faces[i + 1].second;
      if (all_on_rim(s, a) && all_on_rim(s, b)) {
        corbels.push_back(a);
        corbels.push_back(b);
      }
    }
  return corbels;
}

// The corbels (pairs of faces, as find_corbels gives them) whose removal keeps S_M in one piece. Where S_M
// narrows to a strip one square wide (S narrower than V_M's cubes), every square of the strip is a corbel,
// and removing one would cut off the strip beyond it, which the component clean-up then drops: S_M would
// leave that part of S uncovered. Such a corbel is left to the dividing-edge rule, which splits its square
// (its diagonal joins two rim nodes) and so gives it a node off the rim.
std::vector<int> corbels_keeping_one_piece(const TetMesh& mesh, const Interface& s, const std::vector<int>& corbels) {
  const std::vector<std::uint8_t> removed = faces_of_squares(mesh, s, corbels);
  const auto label = edge_components(s.nodes, [&](std::size_t a, std::size_t b) { return !removed[a] && !removed[b]; });
  std::vector<std::int64_t> size(s.faces.size(), 0);
  for (std::size_t f = 0; f < s.faces.size(); ++f) size[label[f]] += removed[f] ? 0 : 1;
  const auto largest = static_cast<std::size_t>(std::max_element(size.begin(), size.end()) - size.begin());
  // The nodes of the parts that the removal would cut off.
  std::vector<std::uint8_t> cut_off(mesh.points.size(), 0);
  bool any_cut_off = false;
  for (std::size_t f = 0; f < s.faces.size(); ++f)
    if (!removed[f] && label[f] != largest) {
      for (VertexId v : s.nodes[f]) cut_off[v] = 1;
      any_cut_off = true;
    }
  if (!any_cut_off) return corbels;
  std::vector<int> kept;
  for (std::size_t i = 0; i + 1 < corbels.size(); i += 2) {
    const std::vector<std::uint8_t> squares = faces_of_squares(mesh, s, {corbels[i], corbels[i + 1]});
    bool joins = false;
    for (std::size_t f = 0; f < s.faces.size() && !joins; ++f)
      if (squares[f])
        for (VertexId v : s.nodes[f]) joins = joins || cut_off[v] != 0;
    if (!joins) kept.insert(kept.end(), {corbels[i], corbels[i + 1]});
  }
  return kept;
}

// Angle at corner k of a face, in computational coordinates (exact shapes: 45 or 90 degrees on ∂V_M).
double corner_angle(const TetMesh& mesh, const std::array<VertexId, 3>& face, int k) {
  auto position = [&](VertexId v) {
    return Eigen::Vector3d(static_cast<double>(mesh.grid[v][0]), static_cast<double>(mesh.grid[v][1]),
                           static_cast<double>(mesh.grid[v][2]));
  };
  const Eigen::Vector3d p = position(face[k]);
  const Eigen::Vector3d a = position(face[(k + 1) % 3]) - p, b = position(face[(k + 2) % 3]) - p;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Reflex rim corners: rim nodes in 5 or more S_M faces whose fan turns by more than a straight angle.
// The paper's rule counts faces only; on a staircase S_M a rim node that crosses a step has 5 or more
// faces on three planes while its fan is flat (180 degrees): that is no defect. A reflex fan is what
// projection onto the smooth rim of S squeezes.
std::vector<VertexId> reflex_rim_corners(const TetMesh& mesh, const Interface& s) {
  std::vector<std::pair<VertexId, double>> corners;  // (rim node, angle of one of its faces there)
  for (const auto& face : s.nodes)
    for (int k = 0; k < 3; ++k)
      if (s.on_rim[face[k]]) corners.push_back({face[k], corner_angle(mesh, face, k)});
  std::sort(corners.begin(), corners.end());
  std::vector<VertexId> nodes;
  constexpr double straight = 3.141592653589793 + 1e-9;
  for (std::size_t i = 0; i < corners.size();) {
    std::size_t j = i;
    double fan = 0;
    while (j < corners.size() && corners[j].first == corners[i].first) fan += corners[j++].second;
    if (j - i >= 5 && fan > straight) nodes.push_back(corners[i].first);
    i = j;
  }
  return nodes;
}

std::vector<TetId> tets_with_two_faces(const TetMesh& mesh, const Interface& s) {
  std::vector<TetId> tets;
  for (const FaceRef& f : s.faces) {
    tets.push_back(f.tet);
    tets.push_back(mesh.neighbours[f.tet][f.local_face]);
  }
  std::sort(tets.begin(), tets.end());
  std::vector<TetId> doubled;
  for (std::size_t i = 0; i + 1 < tets.size(); ++i)
    if (tets[i] == tets[i + 1] && (doubled.empty() || doubled.back() != tets[i])) doubled.push_back(tets[i]);
  return doubled;
}

// Faces of M with two or more rim edges; returns the longest edge of each (the one to split).
std::vector<Edge> triangles_with_two_rim_edges(const TetMesh& mesh, const Interface& s) {
  std::vector<Edge> splits;
  for (const Edge& e : s.rim_edges) {
    int face = -1;
    s.for_each_face_on_edge(e, [&](int i) { face = i; });
    for (TetId u : tets_around_edge(mesh, s.faces[face].tet, e.first, e.second))
      for (VertexId c : mesh.tets[u]) {
        if (c == e.first || c == e.second) continue;
        if (!s.is_rim_edge(e.first, c) && !s.is_rim_edge(e.second, c)) continue;
        const std::array<Edge, 3> sides{e, make_edge(e.first, c), make_edge(e.second, c)};
        splits.push_back(*std::max_element(sides.begin(), sides.end(), [&](const Edge& x, const Edge& y) {
          return squared_grid_length(mesh, x) < squared_grid_length(mesh, y);
        }));
      }
  }
  return splits;
}

// Edges joining a node of S_M to a node of the box boundary or of another S_M; dividing edges (off the
// rim, between two rim nodes); and, beyond the paper, chord edges: edges between two S_M nodes, not both
// on the rim, that are not edges of S_M. Projection lays a chord on S, and the tets around an edge must
// turn all the way round it, but those around a chord all lie on one side of S_M: some would be
// inverted for good (a tet with four nodes on S_M, or two faces in it, has a chord). A chord's midpoint
// is off S_M, since no face of S_M contains the chord. Counted separately for the statistics.
struct EdgeDefects {
  std::vector<Edge> cross_surface;
  std::vector<Edge> dividing;
  std::vector<Edge> chords;
  std::int64_t unfixable_nodes = 0;  // S_M nodes on the box or on another S_M themselves
};

// `rim_on_box`: S is clipped by the box, so S_M's rim nodes may lie on it (stages/projection.hpp, "Box"),
// and edges from S_M to box nodes are the neighbourhood of that rim, not defects.
EdgeDefects find_edge_defects(const TetMesh& mesh, const Interface& s, const VertexTets& incidence, bool rim_on_box) {
  EdgeDefects d;
  auto is_interface_edge = [&](VertexId a, VertexId b) {
    bool found = false;
    s.for_each_face_on_edge(make_edge(a, b), [&](int) { found = true; });
    return found;
  };
  for (VertexId a = 0; a < mesh.num_vertices(); ++a) {
    if (!s.on_interface[a]) continue;
    const bool a_elsewhere = (on_box_boundary(mesh, a) && !(rim_on_box && s.on_rim[a])) || s.on_other_interface[a];
    d.unfixable_nodes += a_elsewhere;
    for (TetId t : incidence.of(a))
      for (VertexId b : mesh.tets[t]) {
        if (b == a) continue;
        if (!a_elsewhere && ((!rim_on_box && on_box_boundary(mesh, b)) || s.on_other_interface[b]))
          d.cross_surface.push_back(make_edge(a, b));
        if (a > b || !s.on_interface[b]) continue;
        if (s.on_rim[a] && s.on_rim[b]) {
          if (!s.is_rim_edge(a, b)) d.dividing.push_back(make_edge(a, b));
        } else if (!is_interface_edge(a, b)) {
          d.chords.push_back(make_edge(a, b));
        }
      }
  }
  for (auto* list : {&d.cross_surface, &d.dividing, &d.chords}) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
  }
  return d;
}

// Splits edges given by their end nodes, finding a tet that contains each through a hint per vertex
// (a tet containing it, kept current through the child callback) and a walk around the vertex.
class EdgeSplitter {
 public:
  EdgeSplitter(TetMesh& mesh, std::vector<TetRegion*> regions)
      : mesh_(mesh), follow_(region_follows_children(std::move(regions))), hint_(mesh.points.size(), no_tet) {
    for (TetId t = 0; t < mesh.num_tets(); ++t)
      for (VertexId v : mesh.tets[t]) hint_[v] = t;
    on_child_ = [this](TetId parent, TetId child) {
      follow_(parent, child);
      hint_.resize(mesh_.points.size(), no_tet);
      for (VertexId v : mesh_.tets[child]) hint_[v] = child;
      for (VertexId v : mesh_.tets[parent]) hint_[v] = parent;
    };
  }

  // Returns whether the edge still existed and was split.
  bool split(const Edge& e) {
    const TetId t = tet_with_edge(e.first, e.second);
    if (t == no_tet) return false;
    split_edge(mesh_, t, e.first, e.second, on_child_);
    return true;
  }

  void bisect(const std::vector<TetId>& tets) { refine_marked(mesh_, tets, on_child_); }

 private:
  TetId tet_with_edge(VertexId a, VertexId b) {
    std::vector<TetId> stack{hint_[a]}, seen{hint_[a]};
    while (!stack.empty()) {
      const TetId t = stack.back();
      stack.pop_back();
      const auto& v = mesh_.tets[t];
      if (std::find(v.begin(), v.end(), b) != v.end()) return t;
      for (int i = 0; i < 4; ++i) {
        const TetId u = mesh_.neighbours[t][i];
        if (v[i] == a || u == no_tet || std::find(seen.begin(), seen.end(), u) != seen.end()) continue;
        seen.push_back(u);
        stack.push_back(u);
      }
    }
    return no_tet;
  }

  TetMesh& mesh_;
  ChildCallback follow_;
  ChildCallback on_child_;
  std::vector<TetId> hint_;
};

// The disk checks shared by healing and check_surface_approximation.
void check_disk(const TetMesh& mesh, const Interface& s, SurfaceApproximationCheck& c) {
  c.faces = static_cast<std::int64_t>(s.faces.size());
  if (s.faces.empty()) return;
  TopologyScratch scratch;
  const TriangleTopology topology = triangle_topology(s.nodes, scratch);
  c.connected = topology.components == 1;
  c.non_manifold_edges = topology.overloaded_edges;
  c.pinched_nodes = topology.pinched_vertices;
  c.euler = topology.euler();
  c.rim_loops = detail::count_boundary_loops(scratch);
  for (const Edge& e : s.rim_edges) c.oblique_rim_edges += !edge_is_axis_parallel(mesh, e.first, e.second);
}

SurfaceApproximationCheck inspect(const TetMesh& mesh, const Interface& s, bool rim_on_box) {
  SurfaceApproximationCheck c;
  check_disk(mesh, s, c);
  c.corbels = static_cast<std::int64_t>(find_corbels(s).size() / 2);
  c.reflex_rim_corners = static_cast<std::int64_t>(reflex_rim_corners(mesh, s).size());
  c.tets_with_two_faces = static_cast<std::int64_t>(tets_with_two_faces(mesh, s).size());
  c.triangles_with_two_rim_edges = static_cast<std::int64_t>(triangles_with_two_rim_edges(mesh, s).size());
  const EdgeDefects defects = find_edge_defects(mesh, s, vertex_to_tets(mesh), rim_on_box);
  c.cross_surface_edges = static_cast<std::int64_t>(defects.cross_surface.size());
  c.dividing_edges = static_cast<std::int64_t>(defects.dividing.size());
  c.chord_edges = static_cast<std::int64_t>(defects.chords.size());
  c.nodes_on_box_or_other_surface = defects.unfixable_nodes;
  return c;
}

// The boundary faces of V_M around `node` that S_M lacks, completed to whole squares (faces across
// their oblique edges), off the box. Filling them makes `node` an interior node of S_M.
std::vector<FaceRef> missing_squares_at(const TetMesh& mesh, const TetRegion& volumetric, const VertexTets& incidence,
                                        VertexId node, FaceTag tag) {
  std::vector<FaceRef> missing;
  auto wanted = [&](TetId t, int f) {
    return is_volume_boundary_face(mesh, volumetric, t, f) && mesh.neighbours[t][f] != no_tet &&
           mesh.face_tags[t][f] != tag && std::none_of(missing.begin(), missing.end(), [&](const FaceRef& m) {
             return m.tet == t && m.local_face == f;
           });
  };
  for (TetId t : incidence.of(node))
    for (int f = 0; f < 4; ++f)
      if (mesh.tets[t][f] != node && wanted(t, f)) missing.push_back({t, f});
  // Complete squares: add the boundary faces across oblique edges of the faces found so far.
  for (std::size_t i = 0; i < missing.size(); ++i) {
    const auto nodes = face_nodes(mesh, missing[i].tet, missing[i].local_face);
    for (int k = 0; k < 3; ++k) {
      const VertexId a = nodes[k], b = nodes[(k + 1) % 3];
      if (edge_is_axis_parallel(mesh, a, b)) continue;
      for (TetId u : tets_around_edge(mesh, missing[i].tet, a, b))
        for (int g = 0; g < 4; ++g)
          if (mesh.tets[u][g] != a && mesh.tets[u][g] != b && wanted(u, g)) missing.push_back({u, g});
    }
  }
  return missing;
}

// The longest edge of V_M's tets (those of its level L, or finer).
double longest_tet_edge(const TetMesh& mesh, const TetRegion& volumetric) {
  double longest = 0.0;
  for (TetId t = 0; t < static_cast<TetId>(volumetric.size()); ++t)
    if (volumetric[t] != 0) longest = std::max(longest, mesh.longest_edge(t));
  return longest;
}

// Which side of S a point is on: +1, -1, or 0 when the point is beyond the rim of S, i.e. its closest
// point on S lies on the rim and it is farther beside S than above or below it (more than 45 degrees
// from the normal). Beyond the rim the side would only be decided by a tangent plane, and faces there
// would add to S_M a ragged lip that healing then has to erode.
class SideClassifier {
 public:
  // Where S is clipped by the box, its rim edges on the box are no rim for this purpose: S went on beyond
  // the box, and the nodes of V_M beside them, on the box, have the side of S's normal there. Nor are the
  // rim edges whose two ends are where S is narrower than `cube_width` (surface/narrow_rim.hpp): around a
  // strip or tip that fits in V_M's cubes nearly every node lies beyond the rim, and S_M would miss that
  // part of S. A tip's own vertex has no rim point across it, so the nodes in front of a tip still get
  // no side, and S_M does not grow past it.
  SideClassifier(const TriangleSurface& surface, const TriangleBVH& tree, const Box& box, double cube_width)
      : surface_(surface), tree_(tree) {
    TopologyScratch scratch;
    triangle_topology(surface.triangles, scratch);
    const std::vector<double> widths = rim_widths(surface, cube_width);
    auto narrow = [&](VertexId v) { return widths[v] < cube_width; };
    for (const Edge& e : scratch.boundary)
      if ((box_sides(surface.points[e.first], box) & box_sides(surface.points[e.second], box)) == 0 &&
          !(narrow(e.first) && narrow(e.second)))
        rim_edges_.push_back(e);
    rim_vertex_.assign(surface.points.size(), 0);
    for (const Edge& e : rim_edges_) rim_vertex_[e.first] = rim_vertex_[e.second] = 1;
  }

  int classify(const Eigen::Vector3d& x) const {
    const ClosestPoint closest = tree_.closest_point(x);
    if (!on_rim(closest)) return tree_.side(x);
    const auto& t = surface_.triangles[closest.triangle];
    const Eigen::Vector3d normal = (surface_.points[t[1]] - surface_.points[t[0]])
                                       .cross(surface_.points[t[2]] - surface_.points[t[0]])
                                       .normalized();
    const Eigen::Vector3d offset = x - closest.point;
    const double along = offset.dot(normal);
    if (std::abs(along) < std::sqrt(0.5) * offset.norm()) return 0;
    return along >= 0 ? +1 : -1;
  }

 private:
  bool on_rim(const ClosestPoint& c) const {
    const auto& t = surface_.triangles[c.triangle];
    switch (c.feature) {
      case Feature::vertex: return rim_vertex_[t[c.feature_index]] != 0;
      case Feature::edge:
        return std::binary_search(rim_edges_.begin(), rim_edges_.end(),
                                  make_edge(t[c.feature_index], t[(c.feature_index + 1) % 3]));
      case Feature::face: return false;
    }
    return false;
  }

  const TriangleSurface& surface_;
  const TriangleBVH& tree_;
  std::vector<Edge> rim_edges_;  // sorted
  std::vector<std::uint8_t> rim_vertex_;
};

void clear_tag(TetMesh& mesh, FaceTag tag) {
  for (auto& tags : mesh.face_tags)
    for (FaceTag& t : tags)
      if (t == tag) t = no_face_tag;
}

// The side of a node not classified yet.
constexpr std::int8_t unknown_side = 2;

// Classifies the boundary nodes of V_M into `node_side` (the others are left unknown) and tags the
// boundary faces off the box with three nodes on `side`; returns an empty string, or the reason why
// there are none.
std::string tag_faces_on_side(TetMesh& mesh, const TetRegion& volumetric, const SideClassifier& sides, FaceTag tag,
                              int side, std::vector<std::int8_t>& node_side, HealingStats& stats) {
  const VolumeBoundary boundary = read_volume_boundary(mesh, volumetric);
  std::vector<VertexId> nodes;
  for (const auto& f : boundary.nodes) nodes.insert(nodes.end(), f.begin(), f.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  node_side.assign(mesh.points.size(), unknown_side);
  const auto count = static_cast<std::int64_t>(nodes.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t i = 0; i < count; ++i)
    node_side[nodes[i]] = static_cast<std::int8_t>(sides.classify(mesh.points[nodes[i]]));
  for (std::size_t i = 0; i < boundary.faces.size(); ++i) {
    const auto& f = boundary.nodes[i];
    if (!boundary.on_box[i] && node_side[f[0]] == side && node_side[f[1]] == side && node_side[f[2]] == side) {
      set_face_tag(mesh, boundary.faces[i].tet, boundary.faces[i].local_face, tag);
      ++stats.initial_faces;
    }
  }
  if (stats.initial_faces > 0) return {};
  const bool touches_box =
      std::any_of(boundary.on_box.begin(), boundary.on_box.end(), [](std::uint8_t b) { return b; });
  return touches_box ? "V_M reaches the box boundary on this side of S: the surface is too close to the box "
                       "for this resolution"
                     : "no boundary face of V_M has its three nodes on this side of S";
}

// Reflex rim corners already dealt with, sorted.
struct ReflexCornerHistory {
  std::vector<VertexId> left;    // could not be filled
  std::vector<VertexId> filled;  // filled once
};

// A reflex rim corner (5 or more faces, fan over 180 degrees) is filled with the squares S_M lacks
// there when those lie on this side of S or beyond its rim. Otherwise it is left as it is: the
// paper removes it, but the notch a removal cuts has reflex corners of its own and grows until it
// has eaten S_M (doc/results.md); a reflex fan only costs some squeezing at one rim node.
// A node is filled once at most: a fill can make corbels whose removal brings the corner back.
// Returns the number of faces added.
std::int64_t fill_reflex_corners(TetMesh& mesh, const TetRegion& volumetric,
                                 const std::vector<VertexId>& reflex_corners,
                                 const std::function<std::int8_t(VertexId)>& side_of, FaceTag tag, int side,
                                 ReflexCornerHistory& history, HealingStats& stats) {
  if (reflex_corners.empty()) return 0;
  std::int64_t filled_now = 0;
  const VertexTets incidence = vertex_to_tets(mesh);
  for (VertexId node : reflex_corners) {
    if (std::binary_search(history.left.begin(), history.left.end(), node)) continue;
    const auto missing = missing_squares_at(mesh, volumetric, incidence, node, tag);
    const bool filled_before = std::binary_search(history.filled.begin(), history.filled.end(), node);
    const bool can_fill = !filled_before && !missing.empty() &&
                          std::all_of(missing.begin(), missing.end(),
                                      [&](const FaceRef& f) {
      const auto nodes_of_face = face_nodes(mesh, f.tet, f.local_face);
      return std::all_of(nodes_of_face.begin(), nodes_of_face.end(), [&](VertexId v) { return side_of(v) != -side; });
                          });
    if (can_fill) {
      for (const FaceRef& f : missing) set_face_tag(mesh, f.tet, f.local_face, tag);
      filled_now += static_cast<std::int64_t>(missing.size());
      ++stats.reflex_corners_filled;
      history.filled.insert(std::upper_bound(history.filled.begin(), history.filled.end(), node), node);
    } else {
      history.left.insert(std::upper_bound(history.left.begin(), history.left.end(), node), node);
    }
  }
  return filled_now;
}

// The end of healing when S_M has no defect left to split: an empty string if it is a disk (a sphere
// for a closed S).
std::string accept_disk(const TetMesh& mesh, const Interface& s, bool closed, std::size_t reflex_corners_left,
                        HealingStats& stats) {
  SurfaceApproximationCheck check;
  check_disk(mesh, s, check);
  if (closed && !check.is_sphere()) return "S_M is not a sphere: " + check.describe();
  if (!closed && !check.is_disk()) return "S_M is not a disk: " + check.describe();
  stats.faces = check.faces;
  stats.rim_nodes = static_cast<std::int64_t>(s.rim_edges.size());
  stats.reflex_corners_left = static_cast<std::int64_t>(reflex_corners_left);
  return {};
}

// Bisects the tets with two faces of S_M and splits the defective edges, counting them in `stats`.
void split_defects(TetMesh& mesh, const std::vector<TetRegion*>& regions, const std::vector<TetId>& doubled,
                   std::vector<Edge> splits, const EdgeDefects& defects, HealingStats& stats) {
  stats.tets_with_two_faces += static_cast<std::int64_t>(doubled.size());
  stats.chord_edges += static_cast<std::int64_t>(defects.chords.size());
  stats.triangles_with_two_rim_edges += static_cast<std::int64_t>(splits.size());
  stats.cross_surface_edges += static_cast<std::int64_t>(defects.cross_surface.size());
  stats.dividing_edges += static_cast<std::int64_t>(defects.dividing.size());
  splits.insert(splits.end(), defects.cross_surface.begin(), defects.cross_surface.end());
  splits.insert(splits.end(), defects.dividing.begin(), defects.dividing.end());
  splits.insert(splits.end(), defects.chords.begin(), defects.chords.end());
  std::sort(splits.begin(), splits.end());
  splits.erase(std::unique(splits.begin(), splits.end()), splits.end());
  EdgeSplitter splitter(mesh, regions);
  if (!doubled.empty()) splitter.bisect(doubled);
  for (const Edge& e : splits) splitter.split(e);
}

// What S is: closed (S_M a sphere), or clipped by the box (its rim, and S_M's, run on the box).
struct SurfaceKind {
  bool closed = false;
  bool rim_on_box = false;
};

// One healing attempt on one side; returns an empty string on success, else the reason of failure.
std::string heal_side(TetMesh& mesh, TetRegion& volumetric, const SideClassifier& sides, FaceTag tag, int side,
                      SurfaceKind kind, const SurfaceApproximationOptions& options,
                      const std::vector<TetRegion*>& other_regions, HealingStats& stats) {
  clear_tag(mesh, tag);
  std::vector<std::int8_t> node_side;
  if (std::string failure = tag_faces_on_side(mesh, volumetric, sides, tag, side, node_side, stats); !failure.empty())
    return failure;
  // Sides of nodes created by refinement are computed when first needed.
  auto side_of = [&](VertexId v) {
    if (static_cast<std::size_t>(v) >= node_side.size()) node_side.resize(mesh.points.size(), unknown_side);
    if (node_side[v] == unknown_side) node_side[v] = static_cast<std::int8_t>(sides.classify(mesh.points[v]));
    return node_side[v];
  };

  std::vector<TetRegion*> regions = other_regions;
  regions.push_back(&volumetric);
  ReflexCornerHistory reflex_history;
  for (stats.passes = 1; stats.passes <= options.max_healing_passes; ++stats.passes) {
    const auto [stray, holes] = keep_one_component_without_holes(mesh, volumetric, tag);
    stats.stray_faces += stray;
    stats.hole_faces += holes;
    stats.extension_faces += make_rim_axis_parallel(mesh, volumetric, tag);
    const Interface s = read_interface(mesh, volumetric, tag);
    if (s.faces.empty()) return "S_M became empty";

    if (const auto corbels = corbels_keeping_one_piece(mesh, s, find_corbels(s)); !corbels.empty()) {
      stats.corbels += static_cast<std::int64_t>(corbels.size() / 2);
      remove_with_squares(mesh, s, corbels);
      continue;
    }
    const std::vector<VertexId> reflex_corners = reflex_rim_corners(mesh, s);
    if (const std::int64_t filled =
            fill_reflex_corners(mesh, volumetric, reflex_corners, side_of, tag, side, reflex_history, stats);
        filled > 0) {
      stats.filled_faces += filled;
      continue;
    }

    const std::vector<TetId> doubled = tets_with_two_faces(mesh, s);
    std::vector<Edge> splits = triangles_with_two_rim_edges(mesh, s);
    const EdgeDefects defects = find_edge_defects(mesh, s, vertex_to_tets(mesh), kind.rim_on_box);
    if (defects.unfixable_nodes > 0)
      return std::to_string(defects.unfixable_nodes) +
             " node(s) of S_M lie on the box boundary or on another surface's S_M (the surface is too close "
             "to them for this resolution)";
    if (doubled.empty() && splits.empty() && defects.cross_surface.empty() && defects.dividing.empty() &&
        defects.chords.empty())
      return accept_disk(mesh, s, kind.closed, reflex_corners.size(), stats);
    split_defects(mesh, regions, doubled, std::move(splits), defects, stats);
  }
  return "healing did not converge in " + std::to_string(options.max_healing_passes) + " passes";
}

}  // namespace

std::string SurfaceApproximationCheck::describe() const {
  std::ostringstream out;
  out << faces << " faces, " << (connected ? "connected" : "disconnected") << ", Euler characteristic " << euler << ", "
      << rim_loops << " rim loop(s), " << pinched_nodes << " pinched node(s), " << non_manifold_edges
      << " non-manifold edge(s), " << oblique_rim_edges << " oblique rim edge(s), " << corbels << " corbel(s), "
      << reflex_rim_corners << " reflex rim corner(s) (allowed), " << tets_with_two_faces << " tet(s) with two faces, "
      << triangles_with_two_rim_edges << " triangle(s) with two rim edges, " << cross_surface_edges
      << " cross-surface edge(s), " << dividing_edges << " dividing edge(s), " << chord_edges << " chord edge(s), "
      << nodes_on_box_or_other_surface << " node(s) on the box or another surface";
  return out.str();
}

HealingStats approximate_surface(TetMesh& mesh, TetRegion& volumetric, const TriangleSurface& surface,
                                 const TriangleBVH& tree, int index, const SurfaceApproximationOptions& options,
                                 const std::vector<TetRegion*>& other_regions) {
  const FaceTag tag = interface_tag(index);
  const SurfaceKind kind{is_closed(surface), reaches_box(surface, mesh.meccano.box)};
  const SideClassifier sides(surface, tree, mesh.meccano.box, longest_tet_edge(mesh, volumetric));
  const bool closed = kind.closed;
  std::vector<int> sides_to_try;
  switch (closed ? SideRule::positive_only : options.side_rule) {
    case SideRule::positive_first: sides_to_try = {+1, -1}; break;
    case SideRule::negative_first: sides_to_try = {-1, +1}; break;
    case SideRule::positive_only: sides_to_try = {+1}; break;
    case SideRule::negative_only: sides_to_try = {-1}; break;
  }
  std::string failures;
  for (int side : sides_to_try) {
    HealingStats stats;
    stats.side = side;
    stats.attempts = side == sides_to_try.front() ? 1 : 2;
    const std::string failure = heal_side(mesh, volumetric, sides, tag, side, kind, options, other_regions, stats);
    if (failure.empty()) {
      stats.first_side_failure = failures;
      return stats;
    }
    failures += (failures.empty() ? "" : "; ") + std::string(side > 0 ? "positive" : "negative") + " side: " + failure;
  }
  clear_tag(mesh, tag);
  throw MeshingError(std::string("the surface approximation S_M could not be healed into a ") +
                     (closed ? "sphere" : "disk") + " (" + failures + ")");
}

ApproximationFaces approximation_faces(const TetMesh& mesh, const TetRegion& volumetric, int index, int side) {
  ApproximationFaces result;
  const Interface s = read_interface(mesh, volumetric, interface_tag(index));
  for (const FaceRef& f : s.faces) {
    // The V_M tet's outward normal points away from V_M, i.e. to the side S_M lies on.
    const FaceRef oriented = side > 0 ? f
                                      : FaceRef{mesh.neighbours[f.tet][f.local_face],
                                                mesh.face_towards(mesh.neighbours[f.tet][f.local_face], f.tet)};
    result.faces.push_back(oriented);
    result.triangles.push_back(mesh.outward_face(oriented.tet, oriented.local_face));
  }
  return result;
}

SurfaceApproximationCheck check_surface_approximation(const TetMesh& mesh, const TetRegion& volumetric, int index,
                                                      bool rim_on_box) {
  return inspect(mesh, read_interface(mesh, volumetric, interface_tag(index)), rim_on_box);
}

}  // namespace meccano
