// The whole insertion, read top-down like the paper's four steps.
//
// Input    a meccano mesh (mesh/cube_meccano.hpp), surfaces that passed validate_surfaces, and options.
//          The stages take each surface with its rim chords split (surface/rim_chords.hpp): the same
//          geometry, a triangulation whose parameterization cannot fail for want of corners.
// Steps    1. volumetric approximation V_M of each surface (stages/volumetric_approximation.hpp);
//          2. surface approximation S_M of each surface, healed (stages/surface_approximation.hpp); once all
//             are built, any S_M that a later surface's refinement disturbed is healed again;
//          3. projection of each S_M onto its surface (stages/projection.hpp), unless S_M leaves part of S
//             uncovered: a rim vertex of S more than max_rim_gap_in_resolutions l_r from S_M's rim fails
//             the surface at once, before smoothing wastes its sweeps on tets no sweep can untangle, and
//             the insertion runs again with that S_M on the other side (a 10 degree tip is narrower than
//             the cubes at every l_r, and the other side may reach it), then at a finer l_r. The last
//             attempt allowed skips this check: smoothing then gets its chance, as before the check;
//          4. simultaneous untangling and smoothing of the whole mesh or of a band around the surfaces
//             (stages/smoothing.hpp). If tets stay inverted, flips around them change the connectivity
//             that may lock them and SUS runs again from there (with options.improve topology); if tets
//             still stay inverted, the insertion is run again with the S_M of the surfaces next to them on
//             the other side of S (when the side rule allows it); a mesh that stays tangled is an error,
//             never a result.
//          Then the worst tets are lifted (stages/improvement.hpp) unless options.improve is none; the quality
//          after smoothing is that of the result, after the improvement.
//          A surface whose insertion still fails (V_M cannot be grown within reach of S, S_M cannot be
//          healed or does not cover S, or the tets next to its S_M stay tangled on both sides) is inserted
//          again, from the input mesh, at a finer l_r, at most options.finer_retries times, together
//          with the surfaces whose S_M could touch its own: half its l_r, or finer where the gap to those
//          surfaces or to the box leaves no room for S_M at half (the gap decides the first finer l_r,
//          instead of halving attempt after attempt). l_r is an upper bound on the edges near S, so a
//          finer one still honours it. result.finer_retries says why.
//          The surfaces are taken one after the other; a later surface's refinement keeps the earlier
//          surfaces' regions in step (bisection does not change a region's point set).
// Output   the refined mesh, each surface's V_M, per-stage statistics and timings; surface_interfaces()
//          lists each surface's faces with the tets on both sides, output_groups() the named groups the
//          file writers take.
// Progress a callback receives one line per stage with counts, and one per smoothing sweep.
// Refusal before any refinement: l_r <= 0 (with surfaces), or an estimated tet count (estimate_tets) above
//          options.max_tets, are InputErrors: an absurdly small l_r fails at once instead of exhausting memory.
#pragma once

#include <meccano/io/mesh_writers.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/mesh/tet_mesh.hpp>
#include <meccano/stages/improvement.hpp>
#include <meccano/stages/projection.hpp>
#include <meccano/stages/smoothing.hpp>
#include <meccano/stages/surface_approximation.hpp>
#include <meccano/stages/volumetric_approximation.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace meccano {

enum class Stage { volumetric, approximation, projection, smoothing };
enum class Improvement { none, smooth, topology };

// Memory per tet while the pipeline runs: the mesh's 53-80 bytes (doc/design.md) plus the stages' working
// arrays, about 200; the default limit keeps a run below 16 GiB.
inline constexpr std::int64_t estimated_bytes_per_tet = 280;
inline constexpr std::int64_t default_max_tets = (std::int64_t{16} << 30) / estimated_bytes_per_tet;

// The largest rim gap (RimGap, stages/projection.hpp) projection accepts, in units of the surface's l_r.
inline constexpr double max_rim_gap_in_resolutions = 3.0;

// The tet count of an insertion, estimated before any refinement: the meccano's tets plus, per surface,
// the cubes of V_M's level (level_for_resolution) that S crosses, from its area and normals, times the
// tets per such cube of the finished mesh (V_M, the conforming closure around it, healing), fitted per
// level type on real faults and test surfaces (doc/benchmarks.md, "Predictable cost").
std::int64_t estimate_tets(const MeccanoGrid& meccano, std::int64_t meccano_tets,
                           std::span<const TriangleSurface> surfaces, double resolution);

// Throws InputError if `estimated_tets` exceeds `max_tets`, naming `what` (the cause) and the memory it
// would take.
void require_tet_estimate_within(std::int64_t estimated_tets, std::int64_t max_tets, const std::string& what);

struct InsertionOptions {
  double resolution = 0.0;  // l_r, a length in physical units
  Stage last_stage = Stage::smoothing;
  SurfaceApproximationOptions approximation;  // side rule, healing pass limit
  ProjectionOptions projection;               // Floater weights, creases followed
  // Once every S_M is on its surface, the nodes within this many edge rings of the interfaces follow their
  // moves, fading with distance (within a band: at most band_rings), so that SUS starts from far fewer
  // inverted tets (a fault at E/50: 786 instead of 32 167). Off by default: with 4 rings SUS was 0.85-1.34x
  // as fast on the cube example and eight faults, and the worst tet moved by up to +-0.03 either way
  // (doc/benchmarks.md). 0: S_M alone moves, as in the paper.
  int drag_rings = 0;
  SmoothingOptions smoothing;  // SUS mode, target and limits
  // After SUS: lift the worst tets by smoothing and flips (topology), by smoothing alone (smooth: keeps
  // every tet in the bisection hierarchy, for callers that refine the result further), or not at all.
  Improvement improve = Improvement::topology;
  ImprovementOptions improvement;                    // its `topology` is set from `improve`
  int threads = 0;                                   // OpenMP threads for this call; 0 = OpenMP's default
  std::int64_t max_tets = default_max_tets;          // refuse when estimate_tets exceeds it
  int finer_retries = 2;                             // times a failing surface may be retried at a finer l_r
  std::function<void(const std::string&)> progress;  // one line per stage and per smoothing sweep, with counts
};

struct SurfaceInsertion {
  std::string name;
  bool closed = false;      // a closed surface (surface/closed_surface.hpp): V_M is its inside, S_M a sphere
  bool rim_on_box = false;  // clipped by the box (surface/box_clipping.hpp): its rim and S_M's run on the box
  double resolution = 0.0;  // the l_r it was inserted at: options.resolution, or less after finer retries
  TetRegion volumetric;     // V_M, one flag per tet of the final mesh
  VolumetricStats volumetric_stats;
  double volumetric_seconds = 0.0;
  HealingStats healing_stats;  // of the last healing of this surface's S_M
  double approximation_seconds = 0.0;
  // S_M onto S (stages/projection.hpp): one disk, or the two halves of a closed surface's S_M.
  std::vector<SurfaceProjection> projections;
  double projection_seconds = 0.0;
  // The projection's statistics over its disks: counts of distinct nodes (those on a closed surface's cut
  // once), the largest distances, the rim gap and the inverted tets.
  ProjectionStats projection_stats() const;
};

// The nodes that followed the interfaces at the end of step 3 (InsertionOptions::drag_rings).
struct DragStats {
  int rings = 0;  // 0: none followed
  std::int64_t nodes = 0;
  std::int64_t inverted_tets = 0;  // after they followed: what SUS starts from
};

struct InsertionResult {
  TetMesh mesh;
  std::vector<SurfaceInsertion> surfaces;
  DragStats drag;
  SmoothingStats smoothing;        // over every SUS run: after untangling flips, SUS runs again from there
  double smoothing_seconds = 0.0;  // SUS and the untangling flips
  // Flips around the tets SUS left inverted (options.improve topology), and the rounds of them tried.
  FlipStats untangling_flips;
  int untangling_flip_rounds = 0;
  QualitySummary quality_before_smoothing;      // right after projection and the drag (tets may be inverted)
  std::optional<ImprovementStats> improvement;  // when the improvement ran
  double improvement_seconds = 0.0;
  QualitySummary quality_after_smoothing;  // of the result: after SUS and the improvement
  double seconds = 0.0;                    // the whole insertion
  std::int64_t estimated_tets = 0;         // estimate_tets before any refinement, for the l_r asked
  std::string side_retry;                  // why the insertion was run again with S_M on the other side (empty if not)
  std::vector<std::string> finer_retries;  // why it was run again with finer l_r for some surfaces, in order
};

InsertionResult insert_surfaces(const TetMesh& mesh, std::span<const TriangleSurface> surfaces,
                                const InsertionOptions& options);

// How move_surfaces moves an interface.
struct MoveOptions {
  int drag_rings = 6;        // rings of nodes around S_M that follow it, by a displacement fading with distance
  bool smooth = false;       // run SUS even when the move leaves no tet inverted (it runs whenever one is)
  int smoothing_sweeps = 2;  // SUS's smoothing sweeps after a move: the rest of the mesh is smooth already
};

// A moving surface's next step (issue 20) from the previous step's result, without a new insertion: the
// surfaces have the triangulations they were inserted (or last moved) with, in the same order, and only
// their points moved.
//   1. Each S_M node keeps its parameters u in P and goes to φ(u), φ the previous step's parameterization
//      over the moved surface (the parameters of S's vertices kept, their positions new). A closed
//      surface's two halves are cut from it along the same edges at the same fractions as at its
//      insertion (projection_target), so each half keeps its parametric triangles too.
//   2. The nodes within move.drag_rings edge rings of S_M follow: a node moves by the mean displacement
//      of its neighbours in the rings before (a first-ring node: by the rigid motion that best carries
//      its S_M neighbours), along the axes the box leaves it, times min(1, (R - r) / (R - r_1)), r its
//      distance from S_M along the mesh's edges, r_1 the farthest first-ring node's and R that of the
//      nearest node of the next ring: the first ring follows whole, and the tets standing on S_M keep
//      their shape under a rigid motion.
//      The tets beside the interface keep their shape instead of being squeezed or inverted (a quarter
//      of l_r inverted 10 000 of the cube example's 273 000 tets at l_r = 1/64 without it, none with it).
//   3. SUS, if the move left tets inverted (or move.smooth), with move.smoothing_sweeps smoothing sweeps;
//      then the improvement, as in insert_surfaces. In band mode their band holds the dragged rings.
// The topology (but for the flips of Improvement::topology), refinement, tags and V_M are the previous
// step's; nodes beyond the rings (and SUS's band, when it runs) keep their positions bit for bit. No
// retry: an interface that moved too far for SUS throws MeshingError, and the caller inserts the surfaces
// anew (stages/sequence.hpp). Throws InputError if a surface's triangulation differs (a parametric
// triangle of the moved surface flipped or flat). A surface clipped by the box (surface/box_clipping.hpp) is given clipped, each step: it keeps its triangulation
// while no vertex of S crosses a box plane, and its S_M's rim nodes on the box stay on their planes.
InsertionResult move_surfaces(const InsertionResult& previous, std::span<const TriangleSurface> surfaces,
                              const InsertionOptions& options, const MoveOptions& move = {});

// `domain`, the box sides, and `interface_NAME` for every surface's S_M (once built), oriented like the
// surface (out of a closed one); at the inspection stages (last_stage before smoothing) also
// `volumetric_NAME` for every surface's V_M, and in the final mesh `inside_NAME` for every closed surface:
// the tets it encloses (its V_M, whose boundary S_M now lies on S), and `negative_NAME` and `positive_NAME`
// for every surface that divides the box (divided_sides). Tags as in io/mesh_writers.hpp: surface k of n's
// interface is 7 + k whichever S_M exist, its V_M or inside 2 + k, its negative and positive sides
// 2 + n + 2k and 3 + n + 2k. The final mesh leaves V_M out: formats that write an element once per group (MSH 2.2,
// VTU) would otherwise hold its tets twice.
MeshGroups output_groups(const InsertionResult& result, Stage last_stage = Stage::smoothing);

// What a solver needs to impose a condition on an inserted surface: each face of S_M once, with the
// tets on both sides. The vertex order and `normal` agree with the surface's normals (right-hand rule);
// the normal points out of `negative` (the tet on S's negative side) into `positive`. Box-side faces
// carry box_side_tag in mesh.face_tags; every tet belongs to the one volume, `domain`.
struct InterfaceFace {
  std::array<VertexId, 3> vertices;
  Eigen::Vector3d normal;  // unit
  FaceRef negative;        // the tet behind the face and its local face
  FaceRef positive;        // the tet in front of it
};

struct SurfaceInterface {
  std::string name;
  FaceTag tag;  // interface_tag(index) in mesh.face_tags
  std::vector<InterfaceFace> faces;
};

// One entry per surface whose S_M was built (every surface once the approximation stage has run).
std::vector<SurfaceInterface> surface_interfaces(const InsertionResult& result);

// For a surface clipped by the box whose interface divides the box into two parts: the tets of each, on
// S's negative side [0] and positive side [1] (the side its normals point to). Empty for a surface that
// does not divide the box (it reaches the boundary only in part, or is closed: see inside_NAME).
std::optional<std::array<TetRegion, 2>> divided_sides(const InsertionResult& result, int s);

}  // namespace meccano
