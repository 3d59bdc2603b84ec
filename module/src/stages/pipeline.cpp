#include <meccano/stages/pipeline.hpp>

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/rim_chords.hpp>

#include "mesh/topology_helpers.hpp"

#include <omp.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <optional>
#include <span>
#include <sstream>

namespace meccano {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <class... Parts>
void report(const InsertionOptions& options, const Parts&... parts) {
  if (!options.progress) return;
  std::ostringstream line;
  (line << ... << parts);
  options.progress(line.str());
}

// A MeshingError with the surfaces it concerns, which a retry at a finer l_r may mend.
class SurfaceFailure : public MeshingError {
 public:
  SurfaceFailure(std::vector<int> failing, const std::string& message)
      : MeshingError(message), surfaces(std::move(failing)) {
    std::ranges::sort(surfaces);
    surfaces.erase(std::unique(surfaces.begin(), surfaces.end()), surfaces.end());
  }
  std::vector<int> surfaces;  // sorted, each once
};

// A surface whose S_M leaves part of S uncovered (UncoveredSurfaceError), with the side every surface's
// S_M was built on: its S_M may cover S on the other side.
class UncoveredFailure : public SurfaceFailure {
 public:
  UncoveredFailure(int failing, const std::string& message, std::vector<int> built_sides)
      : SurfaceFailure({failing}, message), sides(std::move(built_sides)) {}
  std::vector<int> sides;  // per surface, HealingStats::side
};

// The side each surface's S_M was built on.
std::vector<int> sides_of(const InsertionResult& result) {
  std::vector<int> sides;
  for (const SurfaceInsertion& inserted : result.surfaces) sides.push_back(inserted.healing_stats.side);
  return sides;
}

// Runs one surface's stage; its MeshingError becomes a SurfaceFailure naming the surface.
template <class Run>
auto for_surface(int s, const std::string& name, Run&& run) {
  try {
    return run();
  } catch (const SurfaceFailure&) {
    throw;
  } catch (const MeshingError& failure) {
    throw SurfaceFailure({s}, name + ": " + failure.what());
  }
}

// Cheap invariant check at the end of a stage: a failure here is a bug, not bad input.
void check_stage(const TetMesh& mesh, const char* stage) {
  const auto check = verify_mesh(mesh, {.physical = true});
  if (!check.ok()) throw MeshingError(std::string("mesh invalid after the ") + stage + " stage: " + check.summary());
}

void report_volumetric(const InsertionOptions& options, const std::string& name, const VolumetricStats& stats,
                       const TetMesh& mesh) {
  report(options, "volumetric ", name, ": ", stats.refinement_passes, " refinement passes, ", stats.bisections,
         " bisections, ", stats.tets_intersecting, " tets meet S; grown to ", stats.tets, " tets (",
         stats.euler_node_stars, " node stars, ", stats.cavity_tets, " cavity tets, ", stats.axis_tets,
         " axis tets); mesh ", mesh.num_tets(), " tets");
}

void report_approximation(const InsertionOptions& options, const SurfaceInsertion& inserted, const TetMesh& mesh) {
  const auto& h = inserted.healing_stats;
  report(options, "approximation ", inserted.name, ": side ", h.side > 0 ? "+" : "-", ", ", h.passes,
         " healing passes; ", h.faces, " faces, ", h.rim_nodes, " rim nodes; extension ", h.extension_faces,
         ", corbels ", h.corbels, ", reflex corners filled ", h.reflex_corners_filled, " left ", h.reflex_corners_left,
         ", tets with two faces ", h.tets_with_two_faces, ", triangles with two rim edges ",
         h.triangles_with_two_rim_edges, ", cross-surface edges ", h.cross_surface_edges, ", dividing edges ",
         h.dividing_edges, ", chord edges ", h.chord_edges, "; mesh ", mesh.num_tets(), " tets");
}

void report_projection(const InsertionOptions& options, const SurfaceInsertion& inserted) {
  const ProjectionStats p = inserted.projection_stats();
  report(options, "projection ", inserted.name, ": ", p.nodes, " nodes (", p.rim_nodes, " on the rim, ",
         p.creases.nodes, " on ", p.creases.lines, " creases) moved by up to ", p.largest_move, ", now within ",
         p.largest_distance_after, " of S; S's rim within ", p.rim_gap / inserted.resolution, " l_r of S_M's; ",
         p.inverted_tets, " tets inverted (smoothing untangles them)");
}

// The smoothing options, reporting each sweep when the caller follows the progress.
SmoothingOptions smoothing_options_reporting_sweeps(const InsertionOptions& options) {
  SmoothingOptions smoothing_options = options.smoothing;
  if (options.progress)
    smoothing_options.on_sweep =
        [&options, caller_on_sweep = options.smoothing.on_sweep](int sweep, const SweepRecord& record) {
      if (caller_on_sweep) caller_on_sweep(sweep, record);
      report(options, "smoothing sweep ", sweep, ": ", record.inverted, " tets inverted, quality min ",
             record.min_quality, " mean ", record.mean_quality,
             record.target == SmoothingTarget::equilateral ? " towards the equilateral target" : "", ", ",
             record.nodes_optimised, " nodes optimised");
    };
  return smoothing_options;
}

void report_smoothing(const InsertionOptions& options, const SmoothingStats& smoothing) {
  const SweepRecord last = smoothing.sweeps.empty() ? SweepRecord{} : smoothing.sweeps.back();
  report(options, "smoothing: ",
         smoothing.inner_nodes + smoothing.box_nodes + smoothing.surface_nodes + smoothing.rim_nodes +
             smoothing.crease_nodes,
         " free nodes (", smoothing.surface_nodes, " on surfaces, ", smoothing.rim_nodes, " on rims, ",
         smoothing.crease_nodes, " on creases), ", smoothing.colours, " colours; ", smoothing.inverted_before,
         " inverted tets before, ", smoothing.inverted_after, " after ", smoothing.sweeps.size(),
         " sweeps (untangled after ", smoothing.untangling_sweeps,
         smoothing.fallback_sweep > 0
             ? ", towards the equilateral target from sweep " + std::to_string(smoothing.fallback_sweep)
             : std::string(),
         "); quality min ", last.min_quality, " mean ", last.mean_quality);
}

void report_improvement(const InsertionOptions& options, const ImprovementOptions& improvement,
                        const ImprovementStats& improved) {
  std::ostringstream thresholds;  // what the stage ran at, as its statistics record it (and the report writes)
  if (improved.first_threshold > 0.0) thresholds << improved.first_threshold << ", then ";
  thresholds << improved.floors.mean_ratio;
  report(options, "improvement: ", improved.passes, " passes over the tets below ", thresholds.str(), " (",
         improved.tets_below_before, " before, ", improved.tets_below_after, " after), ", improved.nodes_moved, " of ",
         improved.node_updates, " node updates moved",
         improvement.topology ? "; " + std::to_string(improved.rounds) + " rounds of flips: " + describe(improved.flips)
                              : std::string(),
         "; smallest quality ", improved.min_quality_before, " -> ", improved.min_quality_after, " (equilateral)");
}

// Step 1: the volumetric approximation of each surface.
void approximate_volumes(InsertionResult& result, std::span<const TriangleSurface> surfaces,
                         const InsertionOptions& options, std::span<const double> resolutions) {
  result.surfaces.reserve(surfaces.size());
  for (int index = 0; index < static_cast<int>(surfaces.size()); ++index) {
    const TriangleSurface& surface = surfaces[index];
    const auto start = std::chrono::steady_clock::now();
    SurfaceInsertion& inserted = result.surfaces.emplace_back();
    inserted.name = surface.name;
    inserted.closed = is_closed(surface);
    inserted.rim_on_box = reaches_box(surface, result.mesh.meccano.box);
    inserted.resolution = resolutions[index];
    std::vector<TetRegion*> earlier;
    for (int s = 0; s < index; ++s) earlier.push_back(&result.surfaces[s].volumetric);
    const TriangleBVH tree(surface);
    inserted.volumetric = for_surface(index, surface.name, [&] {
      return approximate_volume(result.mesh, tree, {inserted.resolution}, inserted.volumetric_stats, earlier);
    });
    inserted.volumetric_seconds = seconds_since(start);
    report_volumetric(options, surface.name, inserted.volumetric_stats, result.mesh);
  }
}

// The V_M of every surface but s.
std::vector<TetRegion*> other_regions(InsertionResult& result, int s) {
  std::vector<TetRegion*> regions;
  for (int other = 0; other < static_cast<int>(result.surfaces.size()); ++other)
    if (other != s) regions.push_back(&result.surfaces[other].volumetric);
  return regions;
}

// The surface approximation of surface s, healed.
void heal_surface(InsertionResult& result, int s, const TriangleSurface& surface, const TriangleBVH& tree,
                  const InsertionOptions& options, SideRule side_rule) {
  SurfaceInsertion& inserted = result.surfaces[s];
  const auto start = std::chrono::steady_clock::now();
  SurfaceApproximationOptions approximation = options.approximation;
  approximation.side_rule = side_rule;
  inserted.healing_stats = for_surface(s, inserted.name, [&] {
    return approximate_surface(result.mesh, inserted.volumetric, surface, tree, s, approximation,
                               other_regions(result, s));
  });
  inserted.approximation_seconds += seconds_since(start);
  report_approximation(options, inserted, result.mesh);
}

// Step 2: the surface approximation of each surface, healed. Healing a later surface refines the
// mesh near it, which can disturb an earlier S_M close by, so all are checked again and re-healed.
void approximate_surfaces(InsertionResult& result, std::span<const TriangleSurface> surfaces,
                          std::span<const TriangleBVH> trees, const InsertionOptions& options,
                          std::span<const SideRule> side_rules) {
  const int count = static_cast<int>(surfaces.size());
  for (int round = 0; round < 3; ++round) {
    bool healed_any = false;
    for (int s = 0; s < count; ++s) {
      const SurfaceInsertion& inserted = result.surfaces[s];
      if (round > 0 && check_surface_approximation(result.mesh, inserted.volumetric, s, inserted.rim_on_box).healed())
        continue;
      heal_surface(result, s, surfaces[s], trees[s], options, side_rules[s]);
      healed_any = true;
    }
    if (!healed_any) break;
  }
  for (int s = 0; s < count; ++s) {
    const auto check =
        check_surface_approximation(result.mesh, result.surfaces[s].volumetric, s, result.surfaces[s].rim_on_box);
    if (!check.healed())
      throw SurfaceFailure({s}, "the surface approximation of " + result.surfaces[s].name +
                                    " is disturbed by the other surfaces: " + check.describe());
  }
}

// Step 3: every S_M node moves onto its surface. Tets may be tangled until step 4. With
// `require_coverage`, an S_M that leaves part of S uncovered throws UncoveredFailure first.
void project_onto_surfaces(InsertionResult& result, std::span<const TriangleSurface> surfaces,
                           std::span<const TriangleBVH> trees, const InsertionOptions& options, bool require_coverage) {
  for (int s = 0; s < static_cast<int>(surfaces.size()); ++s) {
    SurfaceInsertion& inserted = result.surfaces[s];
    const auto start = std::chrono::steady_clock::now();
    ProjectionOptions projection = options.projection;
    if (require_coverage)
      projection.max_rim_gap = std::min(projection.max_rim_gap, max_rim_gap_in_resolutions * inserted.resolution);
    inserted.projections = for_surface(s, inserted.name, [&] {
      try {
        if (inserted.closed)
          return project_closed_onto_surface(result.mesh, inserted.volumetric, s, surfaces[s], trees[s], projection);
        std::vector<SurfaceProjection> disk;
        disk.push_back(project_onto_surface(result.mesh, inserted.volumetric, s, inserted.healing_stats.side,
                                            surfaces[s], trees[s], projection));
        return disk;
      } catch (const UncoveredSurfaceError& uncovered) {  // for_surface passes a SurfaceFailure on as it is
        throw UncoveredFailure(s, inserted.name + ": " + uncovered.what(), sides_of(result));
      }
    });
    inserted.projection_seconds = seconds_since(start);
    report_projection(options, inserted);
  }
}

// Every node within `rings` edge rings of a moved node (`moved`, with its `displacement`) but not moved
// itself follows it, along the axes the box leaves it: by the mean full displacement of its neighbours
// in the rings before (with `rigid_first_ring`, a first-ring node by the rigid motion that best carries
// its moved neighbours, where they fix one), times min(1, (R - r) / (R - r_1)): r its distance from the
// moved nodes along the mesh's edges, r_1 the largest such distance in the first ring and R the distance
// of the nearest node of ring rings + 1 (which, like every node beyond R, stays put; if the rings hold
// the whole mesh, (rings + 1) / rings times the farthest dragged node's distance). The tets beside the
// interface then keep their shape instead of being squeezed or inverted, and SUS has less to do.
// The first ring follows whole (and rigidly, for a moved interface), so the tets standing on the moved
// nodes keep their shape exactly under a rigid motion: faded from r = 0, they were sheared a little by
// every step of a moving interface, and their paper's measure fell by about 0.0013 a step until the step
// was inserted anew; moved by the mean of their neighbours' displacements, a turned interface still
// sheared them (doc/comparison.md, "The first ring carried whole"). After a projection, whose moves onto
// S are no rigid motion, the rigid fit inverted more tets than the mean. The fade goes by distance, not
// by ring: by ring, the two ends of a tet's edge moved by shares 1/(rings + 1) apart whatever its
// length, which crushed the metre-long tets of crease splits on faults. Returns the number of nodes
// that moved.
std::int64_t drag_neighbours(TetMesh& mesh, std::vector<std::uint8_t> moved, std::vector<Eigen::Vector3d> displacement,
                             int rings, bool rigid_first_ring) {
  const VertexTets stars = vertex_to_tets(mesh);
  std::vector<double> distance(mesh.points.size(), std::numeric_limits<double>::infinity());
  std::vector<VertexId> frontier, dragged;
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    if (moved[v]) {
      frontier.push_back(v);
      distance[v] = 0.0;
    }
  double reach = std::numeric_limits<double>::infinity();  // R
  double first_ring = 0.0;                                 // r_1
  for (int ring = 1; ring <= rings + 1 && !frontier.empty(); ++ring) {
    std::vector<VertexId> next;
    for (const VertexId v : frontier)
      for (const TetId t : stars.of(v))
        for (const VertexId w : mesh.tets[t])
          if (!moved[w]) {
            moved[w] = 2;  // found in this ring
            next.push_back(w);
          }
    std::ranges::sort(next);
    next.erase(std::unique(next.begin(), next.end()), next.end());
    for (const VertexId w : next) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int count = 0;
      std::vector<VertexId> leaders;  // with rigid_first_ring: a first-ring node's neighbours on S_M
      for (const TetId t : stars.of(w))
        for (const VertexId u : mesh.tets[t])
          if (moved[u] == 1) {
            sum += displacement[u];
            distance[w] = std::min(distance[w], distance[u] + (mesh.points[w] - mesh.points[u]).norm());
            ++count;
            if (ring == 1 && rigid_first_ring) leaders.push_back(u);
          }
      displacement[w] = sum / count;
      if (!leaders.empty()) {
        // The rigid motion that carries the leaders, from their positions before the move.
        auto carried = [&] {
          std::ranges::sort(leaders);
          leaders.erase(std::unique(leaders.begin(), leaders.end()), leaders.end());
          std::vector<Eigen::Vector3d> from, to;
          for (const VertexId u : leaders) {
            to.push_back(mesh.points[u]);
            from.push_back(mesh.points[u] - displacement[u]);
          }
          return rigid_displacement(from, to, mesh.points[w]);
        };
        std::optional<Eigen::Vector3d> rigid = carried();
        if (!rigid) {  // on one S_M edge, or a line, they fix no rotation: their own S_M neighbours join
          const std::vector<VertexId> inner = leaders;
          for (const VertexId u : inner)
            for (const TetId t : stars.of(u))
              for (const VertexId x : mesh.tets[t])
                if (distance[x] == 0.0) leaders.push_back(x);
          rigid = carried();
        }
        if (rigid) displacement[w] = *rigid;
      }
      if (ring == 1) first_ring = std::max(first_ring, distance[w]);
      if (ring > rings) reach = std::min(reach, distance[w]);
    }
    for (const VertexId w : next) moved[w] = 1;
    if (ring <= rings) dragged.insert(dragged.end(), next.begin(), next.end());
    frontier = std::move(next);
  }
  if (reach == std::numeric_limits<double>::infinity() && !dragged.empty()) {  // the rings hold the whole mesh
    double farthest = 0.0;
    for (const VertexId w : dragged) farthest = std::max(farthest, distance[w]);
    reach = farthest * (rings + 1) / rings;
  }
  if (!(first_ring < reach)) first_ring = 0.0;  // a single ring, or a next ring nearer than the first's farthest
  std::int64_t followed = 0;
  for (const VertexId w : dragged) {
    if (!(distance[w] < reach)) continue;
    ++followed;
    Eigen::Vector3d d = std::min(1.0, (reach - distance[w]) / (reach - first_ring)) * displacement[w];
    const std::uint8_t planes = mesh.meccano.box_planes(mesh.grid[w]);
    for (int axis = 0; axis < 3; ++axis)
      if (planes & (3u << (2 * axis))) d[axis] = 0.0;
    mesh.points[w] += d;
  }
  return followed;
}

// The rings drag_rings_after_projection moves: within a band only nodes SUS may move follow.
int rings_to_drag(const InsertionOptions& options) {
  return options.smoothing.mode == SmoothingMode::band ? std::min(options.drag_rings, options.smoothing.band_rings)
                                                       : options.drag_rings;
}

// The end of step 3: the nodes within `rings` of the interfaces follow their nodes' moves onto S
// (drag_neighbours), from `before`, the positions before the projection.
void drag_rings_after_projection(InsertionResult& result, const std::vector<Eigen::Vector3d>& before, int rings,
                                 const InsertionOptions& options) {
  std::vector<std::uint8_t> moved(result.mesh.points.size(), 0);
  std::vector<Eigen::Vector3d> displacement(result.mesh.points.size(), Eigen::Vector3d::Zero());
  for (const SurfaceInsertion& inserted : result.surfaces)
    for (const SurfaceProjection& projection : inserted.projections)
      for (const VertexId v : projection.nodes) {
        displacement[v] = result.mesh.points[v] - before[v];
        moved[v] = 1;
      }
  result.drag.rings = rings;
  result.drag.nodes = drag_neighbours(result.mesh, std::move(moved), std::move(displacement), rings, false);
  result.drag.inverted_tets = count_inverted(result.mesh);
  report(options, "drag: ", result.drag.nodes, " nodes within ", rings, " rings of the interfaces follow them; ",
         result.drag.inverted_tets, " tets inverted");
}

// Step 4: untangling and smoothing, every surface's nodes moving within it.
void untangle_and_smooth(InsertionResult& result, std::span<SurfaceProjection* const> projections,
                         const InsertionOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  result.smoothing = smooth_mesh(result.mesh, projections, smoothing_options_reporting_sweeps(options));
  result.smoothing_seconds = seconds_since(start);
  report_smoothing(options, result.smoothing);
}

// Each surface's V_M, which the flips carry over to the tets they make.
std::vector<TetRegion*> volumetric_regions(InsertionResult& result) {
  std::vector<TetRegion*> regions;
  for (SurfaceInsertion& inserted : result.surfaces) regions.push_back(&inserted.volumetric);
  return regions;
}

// SUS's statistics over `earlier` and a run that continued it from where it ended: the node counts and
// the end state are the later run's, the sweeps are counted from the first.
SmoothingStats continued(const SmoothingStats& earlier, SmoothingStats later) {
  const int offset = static_cast<int>(earlier.sweeps.size());
  if (later.inverted_before == 0) later.untangling_sweeps = offset;
  else if (later.untangled()) later.untangling_sweeps += offset;
  later.fallback_sweep = earlier.fallback_sweep > 0 ? earlier.fallback_sweep
                         : later.fallback_sweep > 0 ? later.fallback_sweep + offset
                                                    : 0;
  later.inverted_before = earlier.inverted_before;
  later.sweeps.insert(later.sweeps.begin(), earlier.sweeps.begin(), earlier.sweeps.end());
  return later;
}

// Where SUS leaves tets inverted, their connectivity can lock them: a tet standing on an S_M triangle that
// untangling squeezed flat against a crease edge of S gains volume from no node move (doc/robustness.md,
// "Box margins and resolutions off the benchmark's grid"). Flips around the inverted tets, S_M's edges
// included, change that connectivity, and SUS runs again from there; at most max_untangling_flip_rounds
// times, and only with --improve topology, since flips end the bisection hierarchy.
void untangle_by_flips(InsertionResult& result, std::span<SurfaceProjection* const> projections,
                       const InsertionOptions& options) {
  constexpr int max_untangling_flip_rounds = 2;
  for (int round = 0; round < max_untangling_flip_rounds && !result.smoothing.untangled(); ++round) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<TetRegion*> regions = volumetric_regions(result);
    const FlipStats flips = flip_inverted_tets(result.mesh, projections, regions, options.improvement);
    result.untangling_flips += flips;
    ++result.untangling_flip_rounds;
    const double flip_seconds = seconds_since(start);
    report(options, "untangling flips: ", describe(flips), "; tets inverted ", result.smoothing.inverted_after, " -> ",
           count_inverted(result.mesh));
    if (flips.operations() == 0) return;
    SmoothingStats earlier = std::move(result.smoothing);
    const double earlier_seconds = result.smoothing_seconds + flip_seconds;
    // The meccano target has stalled once already: untangling aims at the equilateral tet after one sweep.
    InsertionOptions again = options;
    again.smoothing.fallback_sweeps = std::min(options.smoothing.fallback_sweeps, 1);
    untangle_and_smooth(result, projections, again);
    result.smoothing = continued(earlier, std::move(result.smoothing));
    result.smoothing_seconds += earlier_seconds;
  }
}

void lift_worst_tets(InsertionResult& result, std::span<SurfaceProjection* const> projections,
                     const InsertionOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  ImprovementOptions improvement = options.improvement;
  improvement.topology = options.improve == Improvement::topology;
  if (options.progress) improvement.progress = options.progress;
  const std::vector<TetRegion*> regions = volumetric_regions(result);
  const ImprovementStats& improved =
      result.improvement.emplace(improve_worst_tets(result.mesh, projections, improvement, options.smoothing, regions));
  result.improvement_seconds = seconds_since(started);
  report_improvement(options, improvement, improved);
}

// Step 4 and the improvement after it. False, and the mesh as SUS left it, if tets stay inverted.
bool untangle_smooth_and_improve(InsertionResult& result, const InsertionOptions& options) {
  std::vector<SurfaceProjection*> projections;
  for (SurfaceInsertion& inserted : result.surfaces)
    for (SurfaceProjection& projection : inserted.projections) projections.push_back(&projection);
  untangle_and_smooth(result, projections, options);
  if (!result.smoothing.untangled() && options.improve == Improvement::topology)
    untangle_by_flips(result, projections, options);
  if (!result.smoothing.untangled()) return false;
  if (!result.smoothing.sweeps.empty()) check_stage(result.mesh, "smoothing");  // else it moved nothing
  if (options.improve != Improvement::none) {
    lift_worst_tets(result, projections, options);
    check_stage(result.mesh, "improvement");
  }
  result.quality_after_smoothing = summarize_quality(result.mesh);
  return true;
}

InsertionResult run_stages(TetMesh mesh, std::span<const TriangleSurface> surfaces, const InsertionOptions& options,
                           std::span<const SideRule> side_rules, std::span<const double> resolutions,
                           bool require_coverage) {
  InsertionResult result;
  result.mesh = std::move(mesh);
  if (static_cast<int>(surfaces.size()) > max_interfaces)
    throw InputError("at most " + std::to_string(max_interfaces) + " surfaces can be inserted");

  approximate_volumes(result, surfaces, options, resolutions);
  check_stage(result.mesh, "volumetric");
  if (options.last_stage == Stage::volumetric || surfaces.empty()) return result;

  std::vector<TriangleBVH> trees;
  for (const TriangleSurface& surface : surfaces) trees.emplace_back(surface);
  approximate_surfaces(result, surfaces, trees, options, side_rules);
  check_stage(result.mesh, "approximation");
  if (options.last_stage == Stage::approximation) return result;

  const int rings = rings_to_drag(options);
  const std::vector<Eigen::Vector3d> before_projection =
      rings > 0 ? result.mesh.points : std::vector<Eigen::Vector3d>{};
  project_onto_surfaces(result, surfaces, trees, options, require_coverage);
  if (rings > 0) drag_rings_after_projection(result, before_projection, rings, options);
  const auto check = verify_mesh(result.mesh, {.physical = false});
  if (!check.ok()) throw MeshingError("mesh invalid after the projection stage: " + check.summary());
  result.quality_before_smoothing = summarize_quality(result.mesh);
  if (options.last_stage == Stage::projection) return result;

  untangle_smooth_and_improve(result, options);  // if tets stay inverted, the caller may retry or reports it
  return result;
}

// Sets OpenMP's thread count for the calling thread's parallel regions and restores it on exit.
class ThreadCount {
 public:
  explicit ThreadCount(int threads) : previous_(omp_get_max_threads()) {
    if (threads > 0) omp_set_num_threads(threads);
  }
  ~ThreadCount() { omp_set_num_threads(previous_); }
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;

 private:
  int previous_;
};

std::string tets_still_inverted(const InsertionResult& result) {
  const int rounds = result.untangling_flip_rounds;
  return std::to_string(result.smoothing.inverted_after) + " tets are still inverted after " +
         std::to_string(result.smoothing.sweeps.size()) + " sweeps" +
         (rounds > 0 ? " and " + std::to_string(rounds) + (rounds == 1 ? " round" : " rounds") + " of untangling flips"
                     : "");
}

std::string untangling_failure(const InsertionResult& result) {
  return "smoothing could not untangle the mesh: " + tets_still_inverted(result);
}

// What an untangling failure means, and what may mend it besides the finer l_r the final message
// suggests anyway.
std::string untangling_explanation(const InsertionOptions& options) {
  return options.smoothing.mode == SmoothingMode::band
             ? "smoothing could not untangle the mesh, which the whole-mesh mode (--smoothing whole, "
               "SmoothingMode::whole_mesh) may do"
             : "smoothing could not untangle the mesh";
}

// A run of the stages that failed, for the final message: where it ran and why it failed, one line, and
// what that kind of failure means (empty if the reason says it), which the message gives once however
// many runs failed alike.
struct FailedAttempt {
  std::string settings;
  std::string reason;
  std::string explanation;
};

const char* side_rule_name(SideRule rule) {
  switch (rule) {
    case SideRule::positive_first: return "positive";
    case SideRule::negative_first: return "negative";
    case SideRule::positive_only: return "positive-only";
    case SideRule::negative_only: return "negative-only";
  }
  return "";
}

// "0.05" when every surface has the same value, else "lower 0.025, upper 0.05".
template <class Value, class Text>
std::string per_surface(std::span<const TriangleSurface> surfaces, std::span<const Value> values, Text text) {
  if (std::ranges::all_of(values, [&](const Value& value) { return value == values.front(); }))
    return text(values.front());
  std::string listed;
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    listed += (s > 0 ? ", " : "") + surfaces[s].name + " " + text(values[s]);
  return listed;
}

// "l_r = 0.05, side positive" (the rule's --side name), per surface where they differ.
std::string attempt_settings(std::span<const TriangleSurface> surfaces, std::span<const double> resolutions,
                             std::span<const SideRule> rules) {
  const auto number = [](double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  };
  return "l_r = " + per_surface(surfaces, resolutions, number) + ", side " +
         per_surface(surfaces, rules, [](SideRule rule) { return std::string(side_rule_name(rule)); });
}

// The message of an insertion that failed for good: one line per attempt, the explanations of the kinds
// of failure met, once each, and `outcome`: why no further attempt was made.
std::string final_failure(std::span<const FailedAttempt> failed, const std::string& outcome) {
  std::ostringstream message;
  message << "the insertion failed (" << failed.size() << (failed.size() == 1 ? " attempt):" : " attempts):");
  std::vector<std::string> explanations;
  for (std::size_t k = 0; k < failed.size(); ++k) {
    message << "\n  attempt " << k + 1 << " (" << failed[k].settings << "): " << failed[k].reason;
    if (!failed[k].explanation.empty() && std::ranges::find(explanations, failed[k].explanation) == explanations.end())
      explanations.push_back(failed[k].explanation);
  }
  message << '\n';
  for (const std::string& explanation : explanations) message << explanation << "; ";
  message << outcome;
  return message.str();
}

// The surfaces with an S_M node in an inverted tet, in order.
std::vector<int> surfaces_next_to_inverted_tets(const InsertionResult& result) {
  const TetMesh& mesh = result.mesh;
  std::vector<int> surface_of(mesh.points.size(), -1);
  for (int s = 0; s < static_cast<int>(result.surfaces.size()); ++s)
    for (const SurfaceProjection& projection : result.surfaces[s].projections)
      for (VertexId v : projection.nodes) surface_of[v] = s;
  std::vector<std::uint8_t> next(result.surfaces.size(), 0);
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    if (is_inverted(mesh, t))
      for (VertexId v : mesh.tets[t])
        if (surface_of[v] >= 0) next[surface_of[v]] = 1;
  std::vector<int> surfaces;
  for (int s = 0; s < static_cast<int>(next.size()); ++s)
    if (next[s]) surfaces.push_back(s);
  return surfaces;
}

// The side rules of a second attempt: each failing surface (`next`), if its rule lets it change sides,
// builds S_M on the other side than `sides` (the side each S_M was built on) only. Empty if no surface
// may change.
std::vector<SideRule> other_side_rules(std::span<const int> sides, std::span<const int> next,
                                       std::span<const SideRule> rules) {
  std::vector<SideRule> retry(rules.begin(), rules.end());
  bool changed = false;
  for (int s : next) {
    if (rules[s] != SideRule::positive_first && rules[s] != SideRule::negative_first) continue;
    retry[s] = sides[s] > 0 ? SideRule::negative_only : SideRule::positive_only;
    changed = true;
  }
  return changed ? retry : std::vector<SideRule>{};
}

// An untangling failure concerns the surfaces next to inverted tets (`next`), or all if none is.
SurfaceFailure untangling_surface_failure(std::vector<int> next, int count, const std::string& message) {
  if (next.empty())
    for (int s = 0; s < count; ++s) next.push_back(s);
  return SurfaceFailure(std::move(next), message);
}

// The stages at the given resolutions. A surface whose S_M cannot be untangled on one side of S, or
// leaves part of S uncovered there (checked when `require_coverage`), may do better on the other: the
// stages run again from the input mesh with those surfaces' S_M on their other side, as healing itself
// does. Throws SurfaceFailure when that fails too. Each failed run is added to `failed`.
InsertionResult insert_on_either_side(const TetMesh& mesh, std::span<const TriangleSurface> surfaces,
                                      const InsertionOptions& options, std::span<const double> resolutions,
                                      bool require_coverage, std::vector<FailedAttempt>& failed) {
  const int count = static_cast<int>(surfaces.size());
  std::vector<SideRule> rules(surfaces.size(), options.approximation.side_rule);
  for (int s = 0; s < count; ++s)
    if (is_closed(surfaces[s])) rules[s] = SideRule::positive_only;  // S_M lies outside a closed S
  auto run = [&](std::span<const SideRule> sides) {
    try {
      return run_stages(mesh, surfaces, options, sides, resolutions, require_coverage);
    } catch (const SurfaceFailure& failure) {
      failed.push_back({attempt_settings(surfaces, resolutions, sides), failure.what(), ""});
      throw;
    }
  };
  auto untangling_failed = [&](const InsertionResult& tangled, std::span<const SideRule> sides) {
    failed.push_back({attempt_settings(surfaces, resolutions, sides), tets_still_inverted(tangled),
                      untangling_explanation(options)});
    return untangling_failure(tangled);
  };
  std::string failure;
  std::vector<int> next;
  std::vector<SideRule> retry;
  const char* which = "next to inverted tets";
  try {
    InsertionResult result = run(rules);
    if (options.last_stage != Stage::smoothing || surfaces.empty() || result.smoothing.untangled()) return result;
    failure = untangling_failed(result, rules);
    next = surfaces_next_to_inverted_tets(result);
    retry = other_side_rules(sides_of(result), next, rules);
    if (retry.empty()) throw untangling_surface_failure(std::move(next), count, failure);
  } catch (const UncoveredFailure& uncovered) {
    failure = uncovered.what();
    next = uncovered.surfaces;
    retry = other_side_rules(uncovered.sides, next, rules);
    if (retry.empty()) throw;
    which = "whose S_M leaves part of S uncovered";
  }
  report(options, "retrying with S_M on the other side of the surfaces ", which, " (", failure, ")");
  InsertionResult result;
  try {
    result = run(retry);
  } catch (const SurfaceFailure& other_side) {
    next.insert(next.end(), other_side.surfaces.begin(), other_side.surfaces.end());
    throw SurfaceFailure(std::move(next), failure + "; on the other side: " + other_side.what());
  }
  if (!result.smoothing.untangled())
    throw untangling_surface_failure(surfaces_next_to_inverted_tets(result), count,
                                     failure + "; on the other side: " + untangling_failed(result, retry));
  result.side_retry = failure;
  return result;
}

}  // namespace

namespace {

// The length of a surface's rim: its edges used by one triangle.
double rim_length(const TriangleSurface& surface) {
  const auto edges = detail::edges_with_triangles(surface.triangles);
  double length = 0.0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 1) length += (surface.points[edges[i].first.second] - surface.points[edges[i].first.first]).norm();
    i = j;
  }
  return length;
}

}  // namespace

std::int64_t estimate_tets(const MeccanoGrid& meccano, std::int64_t meccano_tets,
                           std::span<const TriangleSurface> surfaces, double resolution) {
  // V_M covers S with the cubes of its level: a plane with unit normal n crosses
  // |n_x| / (h_y h_z) + |n_y| / (h_x h_z) + |n_z| / (h_x h_y) cubes of sides h per unit area, and the
  // rim adds about one cube per cube width. Tets per cube crossed and per rim cube, by level type (the
  // levels 3k, 3k+1, 3k+2 cut a cube into 6, 12 and 24 tets): fitted on 13 real and synthetic faults and
  // two test surfaces at E/25 to E/100, all within 34 % (doc/benchmarks.md, "Predictable cost").
  static constexpr std::array<double, 3> tets_per_cube = {27.5, 33.7, 61.1};
  static constexpr std::array<double, 3> tets_per_rim_cube = {85.6, 111.6, 159.5};
  const int level = level_for_resolution(meccano, resolution);
  const Eigen::Vector3d h = std::ldexp(1.0, -(level / 3)) * meccano.cell_size;
  const Eigen::Vector3d per_area(1.0 / (h.y() * h.z()), 1.0 / (h.x() * h.z()), 1.0 / (h.x() * h.y()));
  double cubes = 0.0, rim_cubes = 0.0;
  for (const TriangleSurface& surface : surfaces) {
    for (const auto& [a, b, c] : surface.triangles) {
      const Eigen::Vector3d area =
          0.5 * (surface.points[b] - surface.points[a]).cross(surface.points[c] - surface.points[a]);
      cubes += area.cwiseAbs().dot(per_area);
    }
    rim_cubes += rim_length(surface) / std::cbrt(h.prod());
  }
  const double total =
      static_cast<double>(meccano_tets) + tets_per_cube[level % 3] * cubes + tets_per_rim_cube[level % 3] * rim_cubes;
  return total < 0x1p62 ? static_cast<std::int64_t>(total) : std::int64_t{1} << 62;
}

void require_tet_estimate_within(std::int64_t estimated_tets, std::int64_t max_tets, const std::string& what) {
  if (estimated_tets <= max_tets) return;
  std::ostringstream message;
  message.precision(3);
  message << what << " would make about " << static_cast<double>(estimated_tets) << " tets (about "
          << static_cast<double>(estimated_tets) * estimated_bytes_per_tet / (1 << 30) << " GiB of memory), above the "
          << "limit of " << max_tets << " tets; use a coarser setting or raise the limit (--max-tets, "
          << "InsertionOptions::max_tets)";
  throw InputError(message.str());
}

// How close each surface comes to every other one and to the box sides: the room its V_M has.
struct Clearances {
  std::vector<std::vector<double>> between;  // surface distances, symmetric
  std::vector<double> to_box;
};

Clearances clearances(std::span<const TriangleSurface> surfaces, const Box& box) {
  const std::size_t count = surfaces.size();
  Clearances clearance{std::vector<std::vector<double>>(count, std::vector<double>(count, 0.0)),
                       std::vector<double>(count, std::numeric_limits<double>::infinity())};
  for (std::size_t s = 0; s < count; ++s) {
    // A surface clipped by the box meets it by design: its S_M may reach the box, so it needs no room there.
    if (!reaches_box(surfaces[s], box))
      for (const Eigen::Vector3d& p : surfaces[s].points)
        clearance.to_box[s] = std::min({clearance.to_box[s], (p - box.min).minCoeff(), (box.max - p).minCoeff()});
    const TriangleBVH tree(surfaces[s]);
    for (std::size_t other = 0; other < s; ++other)
      clearance.between[s][other] = clearance.between[other][s] = surface_distance(surfaces[other], tree);
  }
  return clearance;
}

// The room two surfaces at these l_r need between them for their S_M to stay apart: each S_M lies
// within growth_band × its reach of its surface, on one side of it. Measured on stress case 50 of seed 1
// (two surfaces 0.0052 apart): S_M healed at a reach of 0.0039 (6.3 M tets) and not at 0.0068.
double room_needed(const MeccanoGrid& meccano, double resolution, double other_resolution) {
  return growth_band * std::max(growth_reach(meccano, resolution), growth_reach(meccano, other_resolution));
}

// The failing surfaces and those whose S_M could touch theirs: a finer l_r for one alone would leave
// the other's S_M in place.
std::vector<int> surfaces_to_refine(const MeccanoGrid& meccano, const Clearances& clearance,
                                    std::span<const double> resolutions, std::vector<int> failing) {
  const std::size_t count = failing.size();
  for (std::size_t k = 0; k < count; ++k) {
    const int s = failing[k];
    for (int other = 0; other < static_cast<int>(resolutions.size()); ++other)
      if (std::ranges::find(failing, other) == failing.end() &&
          clearance.between[s][other] < room_needed(meccano, resolutions[s], resolutions[other]))
        failing.push_back(other);
  }
  std::ranges::sort(failing);
  return failing;
}

// The next l_r of a surface to refine: half its l_r, or the coarsest finer one that leaves its S_M room
// between it and the surfaces refined with it, and the box: the gap decides the first finer l_r,
// instead of halving attempt after attempt.
double finer_resolution(const MeccanoGrid& meccano, const Clearances& clearance, std::span<const int> refined, int s,
                        double resolution) {
  double gap = clearance.to_box[s];
  for (int other : refined)
    if (other != s) gap = std::min(gap, clearance.between[s][other]);
  double finer = resolution / 2.0;
  for (int level = level_for_resolution(meccano, finer); room_needed(meccano, finer, finer) >= gap; ++level) {
    if (level >= finest_level) break;               // the surfaces practically touch: the tet limit decides
    finer = longest_edge_at_level(meccano, level);  // the coarsest l_r of the next level
  }
  return finer;
}

// The surfaces as the stages take them: with their rim chords split (surface/rim_chords.hpp), so that
// S's parameterization is one-to-one whatever the corners, and closed ones with their normals pointing
// out (surface/closed_surface.hpp), so that S_M is built outside them.
std::vector<TriangleSurface> prepared_for_stages(std::span<const TriangleSurface> surfaces) {
  std::vector<TriangleSurface> prepared;
  prepared.reserve(surfaces.size());
  for (const TriangleSurface& surface : surfaces)
    prepared.push_back(is_closed(surface) ? oriented_outward(surface) : split_rim_chords(surface));
  return prepared;
}

// The insertion at l_r, and where it fails, again with the failing surfaces at a finer l_r.
InsertionResult insert_surfaces(const TetMesh& mesh, std::span<const TriangleSurface> input_surfaces,
                                const InsertionOptions& options) {
  const auto pipeline_start = std::chrono::steady_clock::now();
  const std::vector<TriangleSurface> prepared_surfaces = prepared_for_stages(input_surfaces);
  const std::span<const TriangleSurface> surfaces(prepared_surfaces);
  std::int64_t estimated_tets = mesh.num_tets();
  if (!surfaces.empty()) {
    if (!(options.resolution > 0.0))
      throw InputError("the resolution l_r must be positive (got " + std::to_string(options.resolution) + ")");
    std::ostringstream what;
    what << "the resolution l_r = " << options.resolution;
    estimated_tets = estimate_tets(mesh.meccano, mesh.num_tets(), surfaces, options.resolution);
    require_tet_estimate_within(estimated_tets, options.max_tets, what.str());
  }
  const ThreadCount threads(options.threads);
  std::vector<double> resolutions(surfaces.size(), options.resolution);
  std::vector<std::string> failures;  // why each finer retry was made, for the result
  std::vector<FailedAttempt> failed;  // every run of the stages that failed, for the final message
  Clearances clearance;               // computed at the first failure
  for (int retry = 0;; ++retry) {
    std::vector<int> failing;
    try {
      // The last attempt skips the coverage check: smoothing then gets its chance, as no finer l_r will.
      InsertionResult result =
          insert_on_either_side(mesh, surfaces, options, resolutions, retry < options.finer_retries, failed);
      result.finer_retries = std::move(failures);
      result.estimated_tets = estimated_tets;
      result.seconds = seconds_since(pipeline_start);
      return result;
    } catch (const SurfaceFailure& failure) {
      failures.emplace_back(failure.what());
      failing = failure.surfaces;
    }
    if (retry == options.finer_retries)
      throw MeshingError(
          final_failure(failed, "more finer retries (--finer-retries, InsertionOptions::finer_retries; " +
                                    std::to_string(options.finer_retries) + " here) may succeed"));
    std::int64_t estimate = mesh.num_tets();
    std::ostringstream finer;
    finer.precision(6);
    if (clearance.to_box.empty()) clearance = clearances(surfaces, mesh.meccano.box);
    const std::vector<int> refined = surfaces_to_refine(mesh.meccano, clearance, resolutions, failing);
    const std::vector<double> previous = resolutions;
    for (int s : refined) {
      resolutions[s] = finer_resolution(mesh.meccano, clearance, refined, s, previous[s]);
      finer << (finer.tellp() > 0 ? ", " : "") << surfaces[s].name << " at l_r = " << resolutions[s];
      // A gap to the box that sets a much finer l_r is often a rim that should have reached the box: say so,
      // as the run that follows may be long.
      const bool box_gap_decides = std::ranges::all_of(
          refined, [&](int other) { return other == s || clearance.to_box[s] <= clearance.between[s][other]; });
      if (box_gap_decides && resolutions[s] < previous[s] / 2.0)
        finer << " (set by its gap of " << clearance.to_box[s] << " to the box"
              << (is_closed(surfaces[s]) ? "" : "; snap_rim_to_box, --snap-to-box, would set a rim that close onto it")
              << ")";
    }
    for (std::size_t s = 0; s < surfaces.size(); ++s)
      estimate += estimate_tets(mesh.meccano, 0, surfaces.subspan(s, 1), resolutions[s]);
    if (estimate > options.max_tets)
      throw MeshingError(final_failure(failed, "a finer l_r would exceed the tet limit"));
    report(options, "retrying with ", finer.str(), " (", failures.back(), ")");
  }
}

ProjectionStats SurfaceInsertion::projection_stats() const {
  if (projections.size() == 1) return projections.front().stats;
  ProjectionStats combined;
  std::vector<VertexId> nodes, rim;
  for (const SurfaceProjection& disk : projections) {
    const ProjectionStats& p = disk.stats;
    nodes.insert(nodes.end(), disk.nodes.begin(), disk.nodes.end());
    for (std::size_t i = 0; i < disk.nodes.size(); ++i)
      if (disk.on_rim[i]) rim.push_back(disk.nodes[i]);
    combined.largest_move = std::max(combined.largest_move, p.largest_move);
    combined.largest_distance_after = std::max(combined.largest_distance_after, p.largest_distance_after);
    combined.rim_gap = std::max(combined.rim_gap, p.rim_gap);
    combined.inverted_tets = std::max(combined.inverted_tets, p.inverted_tets);
    combined.creases.lines += p.creases.lines;
    combined.creases.crossings += p.creases.crossings;
    combined.creases.nodes += p.creases.nodes;
    combined.creases.refused += p.creases.refused;
    combined.creases.straddling += p.creases.straddling;
    combined.creases.sharpest = std::max(combined.creases.sharpest, p.creases.sharpest);
  }
  for (std::vector<VertexId>* ids : {&nodes, &rim}) {
    std::ranges::sort(*ids);
    ids->erase(std::unique(ids->begin(), ids->end()), ids->end());
  }
  combined.nodes = static_cast<std::int64_t>(nodes.size());
  combined.rim_nodes = static_cast<std::int64_t>(rim.size());
  return combined;
}

MeshGroups output_groups(const InsertionResult& result, Stage last_stage) {
  MeshGroups groups;
  const MeshGroups standard = standard_groups(result.mesh);
  groups.volumes = standard.volumes;
  for (const FaceGroup& group : standard.surfaces)
    if (group.name.rfind("interface_", 0) != 0) groups.surfaces.push_back(group);  // box sides
  for (int s = 0; s < static_cast<int>(result.surfaces.size()); ++s) {
    const SurfaceInsertion& inserted = result.surfaces[s];
    if (last_stage != Stage::smoothing || inserted.closed) {
      TetGroup volume{
          (last_stage != Stage::smoothing ? "volumetric_" : "inside_") + inserted.name, domain_tag + 1 + s, {}};
      for (TetId t = 0; t < result.mesh.num_tets(); ++t)
        if (inserted.volumetric[t]) volume.tets.push_back(t);
      groups.volumes.push_back(std::move(volume));
    }
    if (last_stage == Stage::smoothing)
      if (const auto sides = divided_sides(result, s)) {
        const int count = static_cast<int>(result.surfaces.size());
        for (int side = 0; side < 2; ++side) {
          TetGroup& volume = groups.volumes.emplace_back(TetGroup{
              (side == 0 ? "negative_" : "positive_") + inserted.name, domain_tag + 1 + count + 2 * s + side, {}});
          for (TetId t = 0; t < result.mesh.num_tets(); ++t)
            if ((*sides)[side][t]) volume.tets.push_back(t);
        }
      }
    if (inserted.healing_stats.side != 0)
      groups.surfaces.push_back(
          {"interface_" + inserted.name, interface_tag(s),
           approximation_faces(result.mesh, inserted.volumetric, s, inserted.healing_stats.side).faces});
  }
  return groups;
}

std::vector<SurfaceInterface> surface_interfaces(const InsertionResult& result) {
  std::vector<SurfaceInterface> interfaces;
  const TetMesh& mesh = result.mesh;
  for (int s = 0; s < static_cast<int>(result.surfaces.size()); ++s) {
    const SurfaceInsertion& inserted = result.surfaces[s];
    if (inserted.healing_stats.side == 0) continue;
    const ApproximationFaces oriented = approximation_faces(mesh, inserted.volumetric, s, inserted.healing_stats.side);
    SurfaceInterface& interface = interfaces.emplace_back();
    interface.name = inserted.name;
    interface.tag = interface_tag(s);
    interface.faces.reserve(oriented.faces.size());
    for (std::size_t i = 0; i < oriented.faces.size(); ++i) {
      const FaceRef behind = oriented.faces[i];
      const TetId front = mesh.neighbours[behind.tet][behind.local_face];
      const auto& v = oriented.triangles[i];
      const Eigen::Vector3d normal =
          (mesh.points[v[1]] - mesh.points[v[0]]).cross(mesh.points[v[2]] - mesh.points[v[0]]).normalized();
      interface.faces.push_back({v, normal, behind, {front, mesh.face_towards(front, behind.tet)}});
    }
  }
  return interfaces;
}

std::optional<std::array<TetRegion, 2>> divided_sides(const InsertionResult& result, int s) {
  const SurfaceInsertion& inserted = result.surfaces[s];
  if (inserted.closed || !inserted.rim_on_box || inserted.healing_stats.side == 0) return std::nullopt;
  const TetMesh& mesh = result.mesh;
  const FaceTag tag = interface_tag(s);
  // The face-connected parts of the box with S_M's faces as walls.
  std::vector<int> part(mesh.tets.size(), -1);
  int parts = 0;
  std::vector<TetId> stack;
  for (TetId seed = 0; seed < mesh.num_tets() && parts <= 2; ++seed) {
    if (part[seed] >= 0) continue;
    part[seed] = parts;
    stack.push_back(seed);
    while (!stack.empty()) {
      const TetId t = stack.back();
      stack.pop_back();
      for (int f = 0; f < 4; ++f) {
        const TetId across = mesh.neighbours[t][f];
        if (across == no_tet || mesh.face_tags[t][f] == tag || part[across] >= 0) continue;
        part[across] = parts;
        stack.push_back(across);
      }
    }
    ++parts;
  }
  if (parts != 2) return std::nullopt;
  const FaceRef behind = approximation_faces(mesh, inserted.volumetric, s, inserted.healing_stats.side).faces.front();
  const int negative = part[behind.tet];
  std::array<TetRegion, 2> sides{TetRegion(mesh.tets.size(), 0), TetRegion(mesh.tets.size(), 0)};
  for (TetId t = 0; t < mesh.num_tets(); ++t) sides[part[t] == negative ? 0 : 1][t] = 1;
  return sides;
}

namespace {

// φ of the moved surface: the previous step's parameterization (the parameters of S's vertices in P) over
// the surface's new positions. Throws InputError unless the parametric triangles of `moved` still tile P
// as the previous ones did, which holds when the triangulation is the same.
std::unique_ptr<ParametricSurface> moved_parameterization(const ParametricSurface& previous,
                                                          const TriangleSurface& moved) {
  const SquareParameterization& parameterization = previous.parameterization();
  const auto defect = [&](const std::string& what) {
    return InputError("surface " + moved.name + ": its triangulation is not the one of the previous step (" + what +
                      "); only its points may move");
  };
  if (moved.points.size() != parameterization.uv.size() ||
      static_cast<int>(moved.triangles.size()) != previous.triangle_count())
    throw defect(std::to_string(moved.points.size()) + " points and " + std::to_string(moved.triangles.size()) +
                 " triangles, against " + std::to_string(parameterization.uv.size()) + " and " +
                 std::to_string(previous.triangle_count()));
  for (std::size_t t = 0; t < moved.triangles.size(); ++t) {
    const auto& [a, b, c] = moved.triangles[t];
    const Eigen::Vector2d& ua = parameterization.uv[a];
    if (parameterization.orientation * cross2(parameterization.uv[b] - ua, parameterization.uv[c] - ua) <= 0.0)
      throw defect("triangle " + std::to_string(t + 1) + " is flipped or flat in the previous parameterization");
  }
  return std::make_unique<ParametricSurface>(DiskView(moved), parameterization);
}

}  // namespace

InsertionResult move_surfaces(const InsertionResult& previous, std::span<const TriangleSurface> surfaces,
                              const InsertionOptions& options, const MoveOptions& move) {
  const auto start = std::chrono::steady_clock::now();
  if (surfaces.size() != previous.surfaces.size())
    throw InputError(std::to_string(surfaces.size()) + " surfaces to move, but the previous step inserted " +
                     std::to_string(previous.surfaces.size()));
  const ThreadCount threads(options.threads);
  InsertionResult result;
  result.mesh = previous.mesh;
  result.estimated_tets = previous.estimated_tets;
  std::vector<std::uint8_t> moved_node(result.mesh.points.size(), 0);
  std::vector<Eigen::Vector3d> displacement(result.mesh.points.size(), Eigen::Vector3d::Zero());
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const auto moving = std::chrono::steady_clock::now();
    const SurfaceInsertion& was = previous.surfaces[s];
    SurfaceInsertion& moved = result.surfaces.emplace_back();
    moved.name = was.name;
    moved.resolution = was.resolution;
    moved.volumetric = was.volumetric;
    moved.volumetric_stats = was.volumetric_stats;
    moved.healing_stats = was.healing_stats;
    moved.closed = was.closed;
    moved.rim_on_box = was.rim_on_box;
    const TriangleBVH tree(surfaces[s]);
    for (const SurfaceProjection& from : was.projections) {  // one disk, or a closed surface's two halves
      SurfaceProjection& to = moved.projections.emplace_back();
      to.surface_index = from.surface_index;
      to.surface = moved_parameterization(*from.surface, projection_target(from, surfaces[s]));
      to.nodes = from.nodes;
      to.uv = from.uv;
      to.on_rim = from.on_rim;
      to.triangles = from.triangles;
      to.orientation = from.orientation;
      to.creases = from.creases;
      to.cut_crossings = from.cut_crossings;
      to.cut_triangles = from.cut_triangles;
      to.stats.rim_nodes = from.stats.rim_nodes;
      to.stats.creases = from.stats.creases;
      move_nodes_onto_surface(result.mesh, to, tree);
    }
    for (const SurfaceProjection& to : moved.projections)
      for (const VertexId v : to.nodes) {
        displacement[v] = result.mesh.points[v] - previous.mesh.points[v];
        moved_node[v] = 1;
      }
    moved.projection_seconds = seconds_since(moving);
  }
  result.drag.rings = move.drag_rings;
  result.drag.nodes =
      drag_neighbours(result.mesh, std::move(moved_node), std::move(displacement), move.drag_rings, true);
  const std::int64_t inverted = result.drag.inverted_tets = count_inverted(result.mesh);
  for (SurfaceInsertion& moved : result.surfaces) {
    for (SurfaceProjection& projection : moved.projections) projection.stats.inverted_tets = inverted;
    const ProjectionStats stats = moved.projection_stats();
    report(options, "moved ", moved.name, ": ", stats.nodes, " S_M nodes by up to ", stats.largest_move, "; ", inverted,
           " tets inverted");
  }
  result.quality_before_smoothing = summarize_quality(result.mesh);
  // In a band, the improvement (and SUS, if it runs) reaches every node that followed the interface.
  InsertionOptions after_move = options;
  if (after_move.smoothing.mode == SmoothingMode::band)
    after_move.smoothing.band_rings = std::max(options.smoothing.band_rings, move.drag_rings + 1);
  if (inverted == 0 && !move.smooth) after_move.smoothing.max_sweeps = 0;  // nothing for SUS to untangle
  after_move.smoothing.smoothing_sweeps = move.smoothing_sweeps;
  if (!untangle_smooth_and_improve(result, after_move))
    throw MeshingError("the moved interface leaves " + tets_still_inverted(result));
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace meccano
