#include <meccano/stages/volumetric_approximation.hpp>

#include <meccano/error.hpp>
#include <meccano/mesh/cube_meccano.hpp>

#include "mesh/topology_helpers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace meccano {
namespace {


using detail::TopologyScratch;
using detail::triangle_topology;
using detail::TriangleTopology;

// Whether the link of `node` in the region is a disk: the triangles opposite `node` in the region's
// tets around it must be connected, have Euler characteristic 1 (eq. 2: n_E - n_F + n_T counts the
// link's vertices, edges and triangles), have a boundary, and form a single fan around each vertex.
// The link lies in the boundary of the node's star in M, a 2-manifold, so every link edge is in at
// most two link triangles and a link vertex with d triangles and i interior edges has one closed fan
// when i = d and d - i open fans otherwise. `scratch` is reused between calls to avoid allocation.
struct LinkScratch {
  std::vector<std::array<VertexId, 3>> triangles;
  TopologyScratch topology;
};

bool link_is_disk(const TetMesh& mesh, const TetRegion& region, const VertexTets& incidence, VertexId node,
                  LinkScratch& scratch) {
  auto& triangles = scratch.triangles;
  triangles.clear();
  for (TetId t : incidence.of(node)) {
    if (!region[t]) continue;
    std::array<VertexId, 3> opposite{};
    int k = 0;
    for (VertexId v : mesh.tets[t])
      if (v != node) opposite[k++] = v;
    triangles.push_back(opposite);
  }
  if (triangles.empty()) return false;
  const TriangleTopology link = triangle_topology(triangles, scratch.topology);
  return link.overloaded_edges == 0 && link.boundary_edges > 0 && link.components == 1 && link.pinched_vertices == 0 &&
         link.euler() == 1;
}

// Flags, for each node in `nodes`, whether its link in the region is not a disk (in parallel).
std::vector<std::uint8_t> non_disk_links(const TetMesh& mesh, const TetRegion& region, const VertexTets& incidence,
                                         const std::vector<VertexId>& nodes) {
  std::vector<std::uint8_t> bad(nodes.size(), 0);
  const auto count = static_cast<std::int64_t>(nodes.size());
#pragma omp parallel
  {
    LinkScratch scratch;
#pragma omp for schedule(dynamic, 512)
    for (std::int64_t i = 0; i < count; ++i) bad[i] = !link_is_disk(mesh, region, incidence, nodes[i], scratch);
  }
  return bad;
}

bool face_is_axis_parallel(const TetMesh& mesh, TetId t, int f) {
  const auto& v = mesh.tets[t];
  const auto& local = face_vertices[f];
  for (int axis = 0; axis < 3; ++axis) {
    const std::int64_t c = mesh.grid[v[local[0]]][axis];
    if (mesh.grid[v[local[1]]][axis] == c && mesh.grid[v[local[2]]][axis] == c) return true;
  }
  return false;
}

bool is_boundary_face(const TetMesh& mesh, const TetRegion& region, TetId t, int f) {
  const TetId across = mesh.neighbours[t][f];
  return across == no_tet || !region[across];
}

std::vector<VertexId> boundary_nodes(const TetMesh& mesh, const TetRegion& region) {
  std::vector<std::uint8_t> on_boundary(mesh.points.size(), 0);
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    if (!region[t]) continue;
    for (int f = 0; f < 4; ++f)
      if (is_boundary_face(mesh, region, t, f))
        for (int local : face_vertices[f]) on_boundary[mesh.tets[t][local]] = 1;
  }
  std::vector<VertexId> nodes;
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    if (on_boundary[v]) nodes.push_back(v);
  return nodes;
}

// Components of the complement (face-connected tets outside the region).
std::vector<int> complement_components(const TetMesh& mesh, const TetRegion& region, int& count) {
  std::vector<int> component(mesh.tets.size(), -1);
  count = 0;
  std::vector<TetId> stack;
  for (TetId seed = 0; seed < mesh.num_tets(); ++seed) {
    if (region[seed] || component[seed] >= 0) continue;
    component[seed] = count;
    stack.push_back(seed);
    while (!stack.empty()) {
      const TetId t = stack.back();
      stack.pop_back();
      for (TetId u : mesh.neighbours[t])
        if (u != no_tet && !region[u] && component[u] < 0) {
          component[u] = count;
          stack.push_back(u);
        }
    }
    ++count;
  }
  return component;
}

// Adds to the region every complement component that does not reach the box boundary (or, if none
// does, every component but the largest): V_M must not enclose cavities.
std::int64_t fill_cavities(const TetMesh& mesh, TetRegion& region) {
  int count = 0;
  const std::vector<int> component = complement_components(mesh, region, count);
  if (count <= 1) return 0;
  std::vector<std::uint8_t> outside(count, 0);
  std::vector<std::int64_t> size(count, 0);
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    if (component[t] < 0) continue;
    ++size[component[t]];
    for (TetId u : mesh.neighbours[t])
      if (u == no_tet) outside[component[t]] = 1;
  }
  if (std::none_of(outside.begin(), outside.end(), [](std::uint8_t o) { return o != 0; }))
    outside[std::max_element(size.begin(), size.end()) - size.begin()] = 1;
  std::int64_t added = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    if (component[t] >= 0 && !outside[component[t]]) {
      region[t] = 1;
      ++added;
    }
  return added;
}

// The stars of the boundary nodes whose link is not a disk.
std::vector<TetId> stars_of_non_disk_nodes(const TetMesh& mesh, const TetRegion& region, std::int64_t& nodes) {
  const VertexTets incidence = vertex_to_tets(mesh);
  const std::vector<VertexId> candidates = boundary_nodes(mesh, region);
  const std::vector<std::uint8_t> bad = non_disk_links(mesh, region, incidence, candidates);
  std::vector<TetId> tets;
  nodes = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (bad[i]) {
      ++nodes;
      for (TetId t : incidence.of(candidates[i]))
        if (!region[t]) tets.push_back(t);
    }
  return tets;
}

// The tets across boundary faces that do not lie on a coordinate plane.
std::vector<TetId> tets_across_oblique_faces(const TetMesh& mesh, const TetRegion& region) {
  std::vector<TetId> across;
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    if (!region[t]) continue;
    for (int f = 0; f < 4; ++f)
      if (is_boundary_face(mesh, region, t, f) && !face_is_axis_parallel(mesh, t, f))
        across.push_back(mesh.neighbours[t][f]);  // never no_tet: box sides are axis-parallel
  }
  return across;
}

// The stars of all boundary nodes: one layer around the region.
std::vector<TetId> layer_around(const TetMesh& mesh, const TetRegion& region) {
  const VertexTets incidence = vertex_to_tets(mesh);
  std::vector<TetId> tets;
  for (VertexId node : boundary_nodes(mesh, region))
    for (TetId t : incidence.of(node))
      if (!region[t]) tets.push_back(t);
  return tets;
}

// Everything check_ball checks but the node links (BallCheck::non_disk_links stays 0).
BallCheck boundary_topology(const TetMesh& mesh, const TetRegion& region,
                            std::vector<VertexId>* boundary_vertices = nullptr);

bool intersects(const TetMesh& mesh, const TriangleBVH& surface, TetId t) {
  return surface.intersects_tetrahedron(mesh.tet_points(t));
}

}  // namespace

double growth_reach(const MeccanoGrid& meccano, double resolution) {
  const int level = level_for_resolution(meccano, resolution);
  return std::max(resolution, longest_edge_at_level(meccano, level - level % 3));
}

ChildCallback region_follows_children(std::vector<TetRegion*> regions) {
  return [regions = std::move(regions)](TetId parent, TetId /*child1*/) {
    for (TetRegion* region : regions) region->push_back((*region)[parent]);
  };
}

TetRegion approximate_volume(TetMesh& mesh, const TriangleBVH& surface, const VolumetricOptions& options,
                             VolumetricStats& stats, std::vector<TetRegion*> other_regions) {
  if (!(options.resolution > 0.0))
    throw InputError("the resolution l_r must be positive (got " + std::to_string(options.resolution) + ")");

  // Step 1: refine the tets meeting S until they are shorter than l_r.
  stats.level = level_for_resolution(mesh.meccano, options.resolution);
  TetRegion region(mesh.tets.size(), 0);
  const auto initial = mesh.num_tets();
#pragma omp parallel for schedule(dynamic, 256)
  for (TetId t = 0; t < initial; ++t) region[t] = intersects(mesh, surface, t);
  stats.intersection_tests += initial;

  const ChildCallback follow_others = region_follows_children(other_regions);
  std::vector<TetId> marked, retest;
  std::vector<std::uint8_t> queued;
  for (;;) {
    marked.clear();
    for (TetId t = 0; t < mesh.num_tets(); ++t)
      if (region[t] && mesh.level(t) < stats.level) marked.push_back(t);
    if (marked.empty()) break;
    ++stats.refinement_passes;
    retest.clear();
    queued.assign(mesh.tets.size(), 0);
    auto queue = [&](TetId t) {
      if (!queued[t]) {
        queued[t] = 1;
        retest.push_back(t);
      }
    };
    stats.bisections += refine_marked(mesh, marked, [&](TetId parent, TetId child) {
      follow_others(parent, child);
      region.push_back(region[parent]);
      queued.push_back(0);
      if (region[parent]) {
        queue(parent);
        queue(child);
      }
    });
    const auto count = static_cast<std::int64_t>(retest.size());
#pragma omp parallel for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < count; ++i) region[retest[i]] = intersects(mesh, surface, retest[i]);
    stats.intersection_tests += count;
  }
  stats.tets_intersecting = std::count(region.begin(), region.end(), 1);
  if (stats.tets_intersecting == 0) throw MeshingError("the surface meets no tet of the mesh");
  grow_into_ball(mesh, region, options, stats, std::move(other_regions), &surface);
  return region;
}

namespace {

// The growth of V_M into a ball (grow_into_ball). A tet the growth wants that is coarser than V_M's
// level, or (given S) has a node beyond the reach, is bisected instead of added:
// adding coarse tets would pull far-away, coarse parts of the mesh into V_M (each brings new oblique
// faces and pinched nodes further out), and far nodes would become nodes of S_M far from S. The
// reach is at least the diagonal of the level's cubes, which the axis-parallel growth completes:
// with l_r alone, a level finer than the cubes' (tets shorter than l_r in cubes wider than it)
// bisected its way out to l_r / 16 all around S, for up to 3 times the tets and tangles that took
// five times the smoothing (doc/benchmarks.md, "Predictable cost").
// Where the growth must cross the offset at the reach, bisection alone never ends: a tet straddling
// it keeps a child that straddles it, and the front refines without limit. So a tet 16 times finer
// than V_M's is added when its nodes are within the band 1.125 × reach of S, and the growth fails if
// it needs one that reaches beyond the band.
class BallGrowth {
 public:
  BallGrowth(TetMesh& mesh, TetRegion& region, const VolumetricOptions& options, VolumetricStats& stats,
             std::vector<TetRegion*> other_regions, const TriangleBVH* surface)
      : mesh_(mesh),
        region_(region),
        stats_(stats),
        surface_(surface),
        follow_others_(region_follows_children(std::move(other_regions))),
        target_level_(level_for_resolution(mesh.meccano, options.resolution)),
        reach_(growth_reach(mesh.meccano, options.resolution)),
        band_(reach_ * growth_band) {
    stats.reach = reach_;
  }

  // Adds the `wanted` tets or bisects them; how many it added or bisected.
  std::int64_t grow(const std::vector<TetId>& wanted) {
    std::vector<TetId> coarse;
    std::int64_t added = 0;
    for (TetId t : wanted) {
      if (region_[t]) continue;
      const int level = mesh_.level(t);
      const double farthest = surface_ && level >= target_level_ ? farthest_node(t) : 0.0;
      if (level < target_level_ || (farthest >= reach_ && level < target_level_ + finest_growth_levels)) {
        coarse.push_back(t);
        continue;
      }
      if (farthest >= band_) throw beyond_band(t, farthest);
      stats_.band_tets += farthest >= reach_;
      region_[t] = 1;
      ++added;
    }
    if (!coarse.empty()) bisect(coarse);
    return added + static_cast<std::int64_t>(coarse.size());
  }

 private:
  // The distance from tet t's farthest node to S.
  double farthest_node(TetId t) {
    distance_to_surface_.resize(mesh_.points.size(), std::numeric_limits<double>::quiet_NaN());
    double farthest = 0.0;
    for (VertexId v : mesh_.tets[t]) {
      if (std::isnan(distance_to_surface_[v]))
        distance_to_surface_[v] = std::sqrt(surface_->closest_point(mesh_.points[v]).squared_distance);
      farthest = std::max(farthest, distance_to_surface_[v]);
    }
    return farthest;
  }

  void bisect(std::vector<TetId>& coarse) {
    std::sort(coarse.begin(), coarse.end());
    coarse.erase(std::unique(coarse.begin(), coarse.end()), coarse.end());
    stats_.bisections += refine_marked(mesh_, coarse, [&](TetId parent, TetId child) {
      follow_others_(parent, child);
      region_.push_back(region_[parent]);
    });
    ++stats_.growth_refinements;
  }

  // The failure of a growth that wants tet t, whose farthest node lies beyond the band.
  MeshingError beyond_band(TetId t, double farthest) const {
    const Eigen::Vector3d at = mesh_.points[mesh_.tets[t][0]];
    return MeshingError("the volumetric approximation cannot be grown into a ball within reach of the surface "
                        "near (" +
                        std::to_string(at.x()) + ", " + std::to_string(at.y()) + ", " + std::to_string(at.z()) +
                        "): the ball must reach " + std::to_string(farthest / reach_) + " times the reach " +
                        std::to_string(reach_) + " from it; a smaller l_r resolves this part of the surface");
  }

  TetMesh& mesh_;
  TetRegion& region_;
  VolumetricStats& stats_;
  const TriangleBVH* surface_;
  const ChildCallback follow_others_;
  const int target_level_;
  const double reach_;
  const double band_;
  std::vector<double> distance_to_surface_;  // per vertex; NaN: not computed yet
};

}  // namespace

void grow_into_ball(TetMesh& mesh, TetRegion& region, const VolumetricOptions& options, VolumetricStats& stats,
                    std::vector<TetRegion*> other_regions, const TriangleBVH* surface) {
  // Steps 2 and 3: grow into a ball with axis-parallel boundary faces.
  BallGrowth growth(mesh, region, options, stats, std::move(other_regions), surface);
  // Cheapest checks first: the link test visits every boundary node, so it runs once the boundary is
  // axis-parallel and free of cavities.
  for (stats.growth_passes = 1; stats.growth_passes <= options.max_growth_passes; ++stats.growth_passes) {
    if (const auto across = tets_across_oblique_faces(mesh, region); !across.empty()) {
      stats.axis_tets += growth.grow(across);
      continue;
    }
    if (const auto n = fill_cavities(mesh, region); n > 0) {
      stats.cavity_tets += n;
      continue;
    }
    std::int64_t bad_nodes = 0;
    if (const auto stars = stars_of_non_disk_nodes(mesh, region, bad_nodes); bad_nodes > 0) {
      stats.euler_node_stars += bad_nodes;
      growth.grow(stars);
      continue;
    }
    if (boundary_topology(mesh, region).is_ball()) {  // links were just found to be disks
      stats.tets = std::count(region.begin(), region.end(), 1);
      return;
    }
    // Every link is a disk but the boundary is not a sphere (a handle): thicken V_M by one layer.
    ++stats.thickening_layers;
    growth.grow(layer_around(mesh, region));
  }
  throw MeshingError("the volumetric approximation could not be grown into a topological ball in " +
                     std::to_string(options.max_growth_passes) + " passes");
}

BallCheck check_ball(const TetMesh& mesh, const TetRegion& region) {
  std::vector<VertexId> vertices;
  BallCheck check = boundary_topology(mesh, region, &vertices);
  const VertexTets incidence = vertex_to_tets(mesh);
  const auto bad = non_disk_links(mesh, region, incidence, vertices);
  check.non_disk_links = std::count(bad.begin(), bad.end(), 1);
  return check;
}

namespace {

BallCheck boundary_topology(const TetMesh& mesh, const TetRegion& region, std::vector<VertexId>* boundary_vertices) {
  BallCheck check;
  std::vector<TetId> members;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    if (region[t]) members.push_back(t);
  check.nonempty = !members.empty();
  if (!check.nonempty) return check;

  // Face-connectivity of the region.
  std::vector<std::uint8_t> seen(mesh.tets.size(), 0);
  std::vector<TetId> stack{members.front()};
  seen[members.front()] = 1;
  std::size_t reached = 0;
  while (!stack.empty()) {
    const TetId t = stack.back();
    stack.pop_back();
    ++reached;
    for (TetId u : mesh.neighbours[t])
      if (u != no_tet && region[u] && !seen[u]) {
        seen[u] = 1;
        stack.push_back(u);
      }
  }
  check.connected = reached == members.size();

  // The boundary surface: its faces, edges (with the faces on them) and vertices.
  std::vector<std::array<VertexId, 3>> faces;
  for (TetId t : members)
    for (int f = 0; f < 4; ++f)
      if (is_boundary_face(mesh, region, t, f)) {
        faces.push_back(mesh.outward_face(t, f));
        check.non_axis_faces += !face_is_axis_parallel(mesh, t, f);
      }
  std::vector<VertexId> vertices;
  TopologyScratch scratch;
  const TriangleTopology boundary = triangle_topology(faces, scratch, &vertices);
  check.non_manifold_edges = boundary.boundary_edges + boundary.overloaded_edges;
  check.boundary_components = boundary.components;
  check.boundary_euler = boundary.euler();
  if (boundary_vertices) *boundary_vertices = std::move(vertices);
  return check;
}

}  // namespace

}  // namespace meccano
