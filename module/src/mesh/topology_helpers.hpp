// Small helpers shared by the stages that reason about the topology of regions and surfaces of the
// mesh and of S (stages/volumetric_approximation.cpp, stages/surface_approximation.cpp,
// stages/smoothing.cpp, surface/creases.cpp, stages/pipeline.cpp, surface/validation.cpp,
// stages/parameterization.cpp, inspect/mesh_file_check.cpp).
// Internal: not installed.
#pragma once

#include <meccano/mesh/tet_mesh.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

namespace meccano::detail {

using Edge = std::pair<VertexId, VertexId>;
inline Edge make_edge(VertexId a, VertexId b) { return a < b ? Edge{a, b} : Edge{b, a}; }

// Every edge of a set of triangles with a triangle holding it, sorted by edge: an edge of one triangle (on
// the rim) comes once, an edge shared by two triangles twice, in consecutive entries.
inline std::vector<std::pair<Edge, int>> edges_with_triangles(std::span<const std::array<VertexId, 3>> triangles) {
  std::vector<std::pair<Edge, int>> edges;
  edges.reserve(3 * triangles.size());
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t)
    for (int k = 0; k < 3; ++k) edges.push_back({make_edge(triangles[t][k], triangles[t][(k + 1) % 3]), t});
  std::sort(edges.begin(), edges.end());
  return edges;
}

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) { reset(n); }
  void reset(std::size_t n) {
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(std::size_t a, std::size_t b) { parent_[find(a)] = find(b); }
  int components() {
    int count = 0;
    for (std::size_t i = 0; i < parent_.size(); ++i) count += find(i) == i;
    return count;
  }

 private:
  std::vector<std::size_t> parent_;
};

// Counts that decide what a set of triangles is topologically (a disk, a sphere, something else). It is
// a disk when it is one component, no edge is overloaded, no vertex pinched, it has boundary edges and
// the Euler characteristic is 1 (then its boundary is one loop: count_boundary_loops, for messages);
// each caller reports the counts that fail in its own words.
struct TriangleTopology {
  std::int64_t vertices = 0, edges = 0, faces = 0;
  std::int64_t boundary_edges = 0;    // in one triangle
  std::int64_t overloaded_edges = 0;  // in more than two
  std::int64_t pinched_vertices = 0;  // whose triangles form more than one open fan
  int components = 0;                 // joined across shared edges
  std::int64_t euler() const { return vertices - edges + faces; }
};

// Buffers reused between calls, so that repeated small queries (a node's link) allocate nothing.
struct TopologyScratch {
  std::vector<std::pair<Edge, std::size_t>> edges;  // (edge, triangle)
  std::vector<std::pair<VertexId, int>> fans;       // (vertex, +1 per triangle, -1 per interior edge)
  std::vector<Edge> boundary;                       // edges in one triangle, sorted
  std::vector<VertexId> vertices;                   // sorted, distinct
  std::vector<std::uint8_t> on_boundary;            // per entry of `vertices`
  UnionFind components{0};
  UnionFind loops{0};
};

// A vertex with d triangles and i interior edges (in exactly two triangles) has d - i open fans when
// its triangles lie in a 2-manifold, and 0 when they close around it. `vertices`, if given, receives
// the sorted distinct vertices.
inline TriangleTopology triangle_topology(std::span<const std::array<VertexId, 3>> triangles, TopologyScratch& scratch,
                                          std::vector<VertexId>* vertices = nullptr) {
  TriangleTopology t;
  t.faces = static_cast<std::int64_t>(triangles.size());
  auto& edges = scratch.edges;
  auto& fans = scratch.fans;
  edges.clear();
  fans.clear();
  scratch.boundary.clear();
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      edges.push_back({make_edge(triangles[i][k], triangles[i][(k + 1) % 3]), i});
      fans.push_back({triangles[i][k], 1});
    }
  std::sort(edges.begin(), edges.end());
  scratch.components.reset(triangles.size());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    ++t.edges;
    if (j - i == 1) scratch.boundary.push_back(edges[i].first);
    t.overloaded_edges += j - i > 2;
    if (j - i == 2) {
      fans.push_back({edges[i].first.first, -1});
      fans.push_back({edges[i].first.second, -1});
    }
    for (std::size_t k = i + 1; k < j; ++k) scratch.components.join(edges[i].second, edges[k].second);
    i = j;
  }
  t.components = scratch.components.components();
  t.boundary_edges = static_cast<std::int64_t>(scratch.boundary.size());
  std::sort(fans.begin(), fans.end());
  auto& distinct = scratch.vertices;
  distinct.clear();
  for (std::size_t i = 0; i < fans.size();) {
    std::size_t j = i;
    int open = 0;
    while (j < fans.size() && fans[j].first == fans[i].first) open += fans[j++].second;
    ++t.vertices;
    t.pinched_vertices += open > 1;
    distinct.push_back(fans[i].first);
    i = j;
  }
  if (vertices) *vertices = distinct;
  return t;
}

// The components of the boundary edges of the triangles of the last triangle_topology call on `scratch`.
// Apart from it because the hot caller (V_M's node-link test) need not count them: a connected manifold
// with boundary edges and Euler characteristic 1 has one boundary loop.
inline int count_boundary_loops(TopologyScratch& scratch) {
  const auto& distinct = scratch.vertices;
  auto index = [&](VertexId v) {
    return static_cast<std::size_t>(std::lower_bound(distinct.begin(), distinct.end(), v) - distinct.begin());
  };
  scratch.loops.reset(distinct.size());
  scratch.on_boundary.assign(distinct.size(), 0);
  for (const Edge& e : scratch.boundary) {
    scratch.loops.join(index(e.first), index(e.second));
    scratch.on_boundary[index(e.first)] = scratch.on_boundary[index(e.second)] = 1;
  }
  int loops = 0;
  for (std::size_t v = 0; v < distinct.size(); ++v) loops += scratch.on_boundary[v] && scratch.loops.find(v) == v;
  return loops;
}

}  // namespace meccano::detail
