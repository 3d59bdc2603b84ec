// meccano-immerse: the command-line front end of the module.
// Exit status: 0 success, 1 failure (bad input data, meshing failed, cannot write), 2 usage error.

#include <meccano/error.hpp>
#include <meccano/inspect/mesh_file_check.hpp>
#include <meccano/inspect/mesh_file_measure.hpp>
#include <meccano/io/atomic_file.hpp>
#include <meccano/io/mesh_writers.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/report/insertion_report.hpp>
#include <meccano/report/quality_csv.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/stages/sequence.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/validation.hpp>

#include "arguments.hpp"
#include "tool_support.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <omp.h>
#include <unistd.h>

namespace {

constexpr const char* usage_text = R"(Usage: meccano-immerse --box X0,Y0,Z0,X1,Y1,Z1 [options] --output FILE
       meccano-immerse sequence --box X0,Y0,Z0,X1,Y1,Z1 --resolution L --step FILE[:NAME][,...]
                                --step ... [options] --output PATTERN
       meccano-immerse check FILE.msh [--report FILE.json] [--quiet]
       meccano-immerse measure FILE.msh [--surface FILE[:NAME] ...] [--report FILE.json] [--quiet]

Builds the meccano tetrahedral mesh of a box (equal cells as close to cubes as possible, 6 Kuhn tets
per cell, refined uniformly by Kossaczky bisection) and inserts immersed surfaces into it.

Options:
  --box X0,Y0,Z0,X1,Y1,Z1  the box (required)
  --cells NX,NY,NZ         cell counts, 1 to 1024 each (default: equal cells as close to cubes as
                           possible)
  --level K                uniform bisection levels: 6·2^K tets per cell (default 0). K sets the size of
                           the tets far from the surfaces, which --resolution leaves alone: edges of about
                           1.26·h·2^(-K/3) on average (the longest √3·h/2^k at K = 3k), h the cell edge
                           (by default about the box's shortest extent). A solver's accuracy away from
                           the surfaces depends on K: the default leaves 6 tets per cell there
  --surface FILE[:NAME]    a triangulated surface, open (a disk) or closed (a sphere strictly inside
                           the box: its inside becomes the 3D group inside_NAME) (.obj, .stl, .off,
                           .msh, .ts GOCAD TSurf); NAME defaults to its 1-based position (may repeat).
                           An open surface that reaches the box is clipped to it: each part inside
                           must be a disk (NAME_1, NAME_2, ... by area when there are several), and
                           one that divides the box adds the 3D groups negative_NAME, positive_NAME.
                           Coordinates are taken as in the file: a TSurf's z is its own (a ZPOSITIVE
                           Depth file keeps its positive depths), so give the box in the same terms
  --weld-tolerance D       weld the vertices of each surface file closer than D (absolute, in the
                           file's units) and drop the triangles this collapses or makes repeat another;
                           the surface's progress line counts both (default: 1 m in a .ts file's
                           AXIS_UNIT, or 1e-6 of its bounding-box diagonal when the unit is missing or
                           unknown; 1e-10 of the diagonal for the other formats, which then drop
                           nothing)
  --snap-to-box D          set the rim of each surface onto the box where it runs within D of a box
                           plane without reaching it (absolute, in the file's units; default 0, off):
                           for a fault whose top edge follows the ground only roughly, with the box
                           top at the ground. Only whole rim edges move, each vertex along the
                           plane's normal; the surface's progress line counts them and the largest move
  --split-parts            insert each part of a surface file (its triangles joined through shared
                           edges) as its own surface NAME_1, NAME_2, ... in file order; without it a
                           .ts file of several parts is an error that names them
  --resolution L           l_r: tets meeting a surface are refined until their longest edge is below L
                           (required with --surface)
  --stage STAGE            stop after this stage and write its result (default: smoothing, the whole
                           method); the earlier stages are for inspection:
                           volumetric     the refined mesh with the 3D group volumetric_NAME holding
                                          each surface's volumetric approximation V_M
                           approximation  also the 2D group interface_NAME: the healed surface
                                          approximation S_M (nodes not moved yet)
                           projection     S_M's nodes moved onto the surfaces; tets may be inverted
                                          (this output only)
                           smoothing      untangled and smoothed: the result
  --crease-angle DEG       S_M follows every crease of a surface sharper than DEG degrees (the angle
                           between the normals of the two triangles of an edge): a path of interface
                           edges runs along it and its nodes stay on it (default 12; 180: none)
  --side RULE              the side of each surface S_M is built on (S's normals point to the
                           positive side): positive (default) or negative first, the other side if
                           healing or untangling fails there; positive-only or negative-only never
                           switch
  --smoothing MODE         whole (default: every node may move, as in the paper) or band (only nodes
                           within --band-rings edge rings of the surfaces)
  --band-rings N           rings of the band (default 3)
  --drag-rings N           once S_M is on S, the nodes within N edge rings of it follow its nodes' moves,
                           fading with their distance, so that SUS starts with far fewer inverted tets
                           (at most --band-rings in a band); 4 made SUS about 1.2x as fast on faults.
                           Default 0: S_M alone moves, as in the paper
  --target TARGET          the shape SUS aims for: meccano (default: each tet's computational
                           counterpart, the paper's choice) or equilateral
  --max-sweeps N           at most N smoothing sweeps (default 100); the run fails if tets are still
                           inverted then
  --fallback-sweeps N      with the meccano target, tets still inverted after N sweeps are untangled
                           towards the equilateral target, and the smoothing then aims at the meccano
                           target again (default 20; 0: never)
  --improve MODE           after SUS, the tets whose equilateral mean ratio is below the threshold:
                           topology (default): their nodes are optimised again (the worst tet of each
                           star never getting worse) in rounds with 2-3 flips and edge removals (3-2,
                           4-4 and larger rings, and edge flips inside the interface where S allows
                           them, also of interface triangles wider than 120 degrees under a tet
                           outside the --improve-angles floors); tets made by a flip leave the
                           bisection hierarchy. Tets SUS leaves inverted are flipped around the same
                           way and SUS runs again, before S_M tries the other side. smooth: the node
                           optimisation alone. none: SUS's mesh as it is
  --improve-threshold Q    the equilateral mean ratio below which a tet is improved (default 0.40;
                           higher costs more time)
  --improve-first-threshold Q
                           when below --improve-threshold, the improvement runs first at Q, then at
                           --improve-threshold: the worst tets are lifted first (default 0.35; 0: once;
                           once too when no tet is below Q)
  --improve-angles MIN,MAX after the mean ratio, the nodes of tets with a dihedral angle below MIN or
                           above MAX degrees (or a mean ratio below the threshold) raise their star's
                           worst shape against these floors (default 15,150; 0,180: no shape passes)
  --threads N              OpenMP threads (default: all cores); the result does not depend on it
  --report FILE.json       timings, counts and quality before and after smoothing (keys: tets, nodes,
                           inverted, quality.before_smoothing / after_smoothing with meccano and
                           equilateral min, mean, std, after_smoothing being the result's, after the
                           improvement; min_dihedral_deg; seconds per stage and total; improvement:
                           passes, tets below the threshold and smallest quality before and after,
                           shape_passes, tets_outside_floors_before / after,
                           rounds, operations by kind, tets removed and created, remeshed_tets;
                           smoothing.untangling_flips when they ran: rounds, operations by kind)
  --histograms FILE.csv    quality histograms before and after smoothing, both measures (plot them
                           with scripts/plot_quality.py)
  --output FILE            the mesh with the 3D group `domain`, the 2D groups xmin, xmax, ymin, ymax,
                           zmin, zmax, and the groups of the stage (may repeat), in the format of the
                           file's extension:
                           .msh   Gmsh MSH 4.1 ASCII (or 2.2, see --msh-version)
                           .vtu   VTK XML for ParaView: cell data `group` (tags named in the field
                                  data), quality_meccano and quality_equilateral
                           .mesh  Medit, references named in comment lines (# Triangles ref 7 ...)
  --msh-version V          4.1 (default) or 2.2 for older readers; applies to the .msh outputs that
                           follow it
  --finer-retries N        a surface whose insertion fails (V_M not within reach of it, S_M not
                           healed, or tets next to it still inverted on both sides) is inserted again
                           at half its l_r, or finer if its gap to another surface or the box needs
                           it, at most N times (default 2; 0: never); the report's finer_retries and
                           each surface's resolution say what happened
  --max-tets N             refuse to run when the estimated tet count exceeds N (default: 16 GiB at
                           about 280 bytes per tet, 61 million tets): a tiny --resolution fails at once
                           instead of exhausting memory
  --quiet                  no progress output
  --help                   this text

sequence inserts the surfaces of a moving interface step after step, each --step giving the positions
of one step's surfaces (FILE[:NAME] separated by commas; every step names the same surfaces in the same
order), into the meccano mesh of --box, --cells and --level, and writes each step's mesh to every
--output PATTERN with {step} replaced by 0, 1, ... (.msh or .vtu: Medit files hold no node data). Each
mesh carries the node data `previous_node`: for every node, the node of the previous step's mesh at the
same position, bit for bit, or -1 (in .msh files the previous file's node tag, in .vtu files its
0-based point index; -1 everywhere at step 0), so that a solver can carry its solution over. SUS works
in a band around the surfaces by default (--smoothing band), so that the mesh away from them stays
node for node the same. The options of the one-shot command apply, but for --surface, --split-parts,
--stage and --histograms. Every step is read and validated before any meshing; the files appear
together once every step is done. Progress: one line per step. --report FILE.json writes one object per
step under `steps` (step, seconds, tets, nodes, nodes_unchanged, quality with meccano and equilateral
min/mean/std, inverted, min_dihedral_deg, max_dihedral_deg, and the step's whole report under
`insertion`) and the total `seconds`. A step whose surfaces keep their triangulations is made from the
previous step's mesh: its interface moves onto them and the rings of nodes around it follow (mode
"moved"); it is inserted into the meccano mesh anew (mode "inserted", with `inserted_because`) when a
triangulation changed (a surface clipped by the box changes it when a vertex crosses a box plane), when
a vertex moved farther than --max-move l_r (default 1), when a surface's area differs from its area at
the last insertion by more than --max-area-change of it (default 0.1: a growing surface stretches the
refinement made for it), or when the moved mesh stays tangled or its worst tet falls more than
--max-quality-loss (default 0.02, either mean ratio) below what the insertions gave. A move that
leaves tets tangled is tried again with two rings and SUS; one that loses quality is not, unless
--retry-after-quality-loss (that second move has not kept the quality where the first lost it).
--from-scratch inserts every step anew.

check FILE.msh checks the invariants of a tet mesh of a box in any Gmsh MSH file (2.2 or 4.1, ASCII or
binary; this tool's, Gmsh's, ...): conformity, orientation, volume, the box sides xmin ... zmax (if the
file has those groups), every interface_* group (interior faces forming a consistently oriented disk,
or a closed surface of Euler characteristic 2) and every inside_* group (bounded by its interface). It prints one line per check (--quiet: nothing), writes them as JSON with --report, and exits 0
if every check passes, 1 if one fails or the file cannot be read.

measure FILE.msh measures a tet mesh in any Gmsh MSH file the same way whatever made it (this tool,
reference-gmsh, TetGen, ...): nodes, tets, inverted tets, the equilateral mean ratio (min, mean, std,
tets below 0.1, 0.2, 0.3), the dihedral angle range, and per 2D group interface_NAME its faces and
area. Each --surface FILE[:NAME] (NAME as above: its 1-based position by default) is compared with
interface_NAME: node distance to S (max, mean), two-sided Hausdorff distance (sampled at 1/8 of each
triangle's edges), normal deviation (max, area-weighted mean; faces pointing against S's normal are
counted apart as flipped) and area ratio. It prints them (--quiet: nothing), writes them as JSON with
--report (keys: file, nodes, tets, inverted, quality.equilateral.{min, mean, std, below_0.1, below_0.2,
below_0.3}, quality.min_dihedral_deg / max_dihedral_deg, interfaces[].{name, faces, area, surface,
node_distance.{max, mean}, hausdorff, normal_deviation_deg.{max, mean}, flipped_faces, area_ratio}),
and exits 0, or 1 if a file cannot be read or a surface has no interface_NAME group in the mesh.

Examples:
  meccano-immerse --box 0,0,0,1,1,1 --level 9 --output cube.msh
  meccano-immerse --box 0,0,0,2,1,1 --level 6 --output bar.msh      (two unit cells)
  meccano-immerse --box 0,0,0,1,1,1 --surface patch.obj:fault --resolution 0.03 --output fault.msh \
                  --output fault.vtu                                (and a ParaView file)
  meccano-immerse --box 0,0,0,1,1,1 --level 6 --msh-version 2.2 --output cube22.msh --output cube.mesh
  meccano-immerse --box 0,0,0,1,1,1 --surface patch.obj:fault --resolution 0.03 \
                  --stage volumetric --output fault_vm.msh
  meccano-immerse --box 605286,3617565,-7777,610241,3624984,773 --surface shell_beds.ts:fault \
                  --resolution 350 --output fault.msh               (a GOCAD TSurf fault in UTM metres)
  meccano-immerse --box 0,0,0,1,1,1 --surface faults.ts:f --split-parts --resolution 0.03 \
                  --output faults.msh                               (surfaces f_1, f_2, ... per part)
  meccano-immerse sequence --box 0,0,0,1,1,1 --level 6 --resolution 0.03 --step patch_0.obj:fault \
                  --step patch_1.obj:fault --step patch_2.obj:fault --output out/fault_{step}.msh \
                  --report steps.json                               (a moving fault, 3 steps)
  meccano-immerse check fault.msh --report fault_check.json
  meccano-immerse measure fault.msh --surface patch.obj:fault --report fault_measure.json
)";

using meccano::tools::ArgumentParser;
using meccano::tools::parse_choice;
using meccano::tools::UsageError;

struct Output {
  std::string path;
  meccano::MeshWriteOptions format;
};

struct Options {
  meccano::Box box;
  std::optional<std::array<int, 3>> cells;
  int level = 0;
  std::vector<Output> outputs;
  std::vector<std::pair<std::string, std::string>> surfaces;  // file, name
  meccano::SurfaceReadOptions reading;
  bool split_parts = false;
  double snap_to_box = 0.0;
  std::optional<double> resolution;
  std::optional<meccano::Stage> stage;
  meccano::SideRule side_rule = meccano::SideRule::positive_first;
  double crease_angle = meccano::default_crease_angle;
  meccano::SmoothingOptions smoothing;
  meccano::Improvement improve = meccano::InsertionOptions{}.improve;
  double improve_threshold = meccano::ImprovementOptions{}.threshold;
  double improve_first_threshold = meccano::ImprovementOptions{}.first_threshold;
  std::array<double, 2> improve_angles{meccano::ImprovementOptions{}.min_dihedral,
                                       meccano::ImprovementOptions{}.max_dihedral};
  std::optional<int> threads;
  std::int64_t max_tets = meccano::default_max_tets;
  int finer_retries = meccano::InsertionOptions{}.finer_retries;
  int drag_rings = meccano::InsertionOptions{}.drag_rings;
  std::optional<std::string> report;
  std::optional<std::string> histograms;
  bool quiet = false;
};

// An integer option's handler: stores the value, refused below `minimum`.
template <class Int>
ArgumentParser::ValueHandler store_integer(const std::string& option, Int& target, Int minimum) {
  return [option, &target, minimum](const std::string& text) {
    target = meccano::tools::parse_integer<Int>(option, text);
    if (target < minimum)
      throw UsageError(option +
                       (minimum == 0 ? " must not be negative" : " must be at least " + std::to_string(minimum)));
  };
}

// The box, its meccano mesh and the resolution near the surfaces.
void declare_mesh_options(ArgumentParser& parser, Options& options) {
  parser.required_value({"--box"}, [&](const std::string& text) {
    const auto v = meccano::tools::parse_numbers("--box", text, 6);
    options.box = meccano::tools::box_from_numbers("--box", {v[0], v[1], v[2], v[3], v[4], v[5]});
  });
  parser.value({"--cells"}, [&](const std::string& text) {
    const auto v = meccano::tools::parse_numbers("--cells", text, 3);
    std::array<int, 3> cells{};
    for (int k = 0; k < 3; ++k) {
      if (!(v[k] == std::floor(v[k]) && v[k] >= 1 && v[k] <= meccano::max_cells_per_axis))
        throw UsageError("--cells takes three integers from 1 to " + std::to_string(meccano::max_cells_per_axis));
      cells[k] = static_cast<int>(v[k]);
    }
    options.cells = cells;
  });
  parser.value({"--level"}, [&](const std::string& text) {
    options.level = meccano::tools::parse_integer("--level", text);
    if (options.level < 0 || options.level > 40) throw UsageError("--level must be between 0 and 40");
  });
  parser.value({"--weld-tolerance"}, [&](const std::string& text) {
    options.reading.weld_tolerance = meccano::tools::parse_non_negative("--weld-tolerance", text);
  });
  parser.value({"--snap-to-box"}, [&](const std::string& text) {
    options.snap_to_box = meccano::tools::parse_non_negative("--snap-to-box", text);
  });
  parser.value({"--resolution"}, [&](const std::string& text) {
    const double l = meccano::tools::parse_numbers("--resolution", text, 1)[0];
    if (!(l > 0)) throw UsageError("--resolution must be positive");
    options.resolution = l;
  });
}

// The surfaces to insert, for the one-shot command.
void declare_surface_options(ArgumentParser& parser, Options& options) {
  parser.value({"--surface"}, [&](const std::string& text) {
    options.surfaces.push_back(meccano::tools::parse_surface_argument(text, options.surfaces.size() + 1));
  });
  parser.flag({"--split-parts"}, [&] { options.split_parts = true; });
}

// How the surfaces are inserted: the stages, their choices and limits.
void declare_method_options(ArgumentParser& parser, Options& options) {
  parser.value({"--stage"}, [&](const std::string& text) {
    options.stage =
        parse_choice<meccano::Stage>("--stage", text,
                                     {{"volumetric", meccano::Stage::volumetric},
                                      {"approximation", meccano::Stage::approximation},
                                      {"projection", meccano::Stage::projection},
                                      {"smoothing", meccano::Stage::smoothing}},
                                     "the stages available are: volumetric, approximation, projection, smoothing");
  });
  parser.value({"--crease-angle"}, [&](const std::string& text) {
    const double angle = meccano::tools::parse_numbers("--crease-angle", text, 1)[0];
    if (!(angle > 0.0 && angle <= 180.0)) throw UsageError("--crease-angle must be above 0 and at most 180 degrees");
    options.crease_angle = angle;
  });
  parser.value({"--side"}, [&](const std::string& text) {
    options.side_rule =
        parse_choice<meccano::SideRule>("--side", text,
                                        {{"positive", meccano::SideRule::positive_first},
                                         {"negative", meccano::SideRule::negative_first},
                                         {"positive-only", meccano::SideRule::positive_only},
                                         {"negative-only", meccano::SideRule::negative_only}},
                                        "the rules are positive, negative, positive-only and negative-only");
  });
  parser.value({"--smoothing"}, [&](const std::string& text) {
    options.smoothing.mode = parse_choice<meccano::SmoothingMode>(
        "--smoothing", text, {{"whole", meccano::SmoothingMode::whole_mesh}, {"band", meccano::SmoothingMode::band}},
        "the modes are whole and band");
  });
  parser.value({"--band-rings"}, store_integer("--band-rings", options.smoothing.band_rings, 1));
  parser.value({"--drag-rings"}, store_integer("--drag-rings", options.drag_rings, 0));
  parser.value({"--target"}, [&](const std::string& text) {
    options.smoothing.target = parse_choice<meccano::SmoothingTarget>(
        "--target", text,
        {{"meccano", meccano::SmoothingTarget::meccano}, {"equilateral", meccano::SmoothingTarget::equilateral}},
        "the targets are meccano and equilateral");
  });
  parser.value({"--improve"}, [&](const std::string& text) {
    options.improve = parse_choice<meccano::Improvement>("--improve", text,
                                                         {{"topology", meccano::Improvement::topology},
                                                          {"smooth", meccano::Improvement::smooth},
                                                          {"none", meccano::Improvement::none}},
                                                         "the modes are topology, smooth and none");
  });
  parser.value({"--improve-threshold"}, [&](const std::string& text) {
    options.improve_threshold = meccano::tools::parse_numbers("--improve-threshold", text, 1)[0];
    if (!(options.improve_threshold > 0.0 && options.improve_threshold <= 1.0))
      throw UsageError("--improve-threshold must be above 0 and at most 1");
  });
  parser.value({"--improve-first-threshold"}, [&](const std::string& text) {
    options.improve_first_threshold = meccano::tools::parse_numbers("--improve-first-threshold", text, 1)[0];
    if (!(options.improve_first_threshold >= 0.0 && options.improve_first_threshold <= 1.0))
      throw UsageError("--improve-first-threshold must be at least 0 and at most 1");
  });
  parser.value({"--improve-angles"}, [&](const std::string& text) {
    const auto angles = meccano::tools::parse_numbers("--improve-angles", text, 2);
    // A regular tet's dihedral angle, 70.53°, must meet both floors.
    if (!(angles[0] >= 0.0 && angles[0] < 70.5 && angles[1] > 70.6 && angles[1] <= 180.0))
      throw UsageError("--improve-angles takes MIN,MAX in degrees with 0 <= MIN < 70.5 < MAX <= 180");
    options.improve_angles = {angles[0], angles[1]};
  });
  parser.value({"--max-sweeps"}, store_integer("--max-sweeps", options.smoothing.max_sweeps, 1));
  parser.value({"--finer-retries"}, store_integer("--finer-retries", options.finer_retries, 0));
  parser.value({"--fallback-sweeps"}, store_integer("--fallback-sweeps", options.smoothing.fallback_sweeps, 0));
  parser.value({"--threads"}, [&](const std::string& text) {
    options.threads = meccano::tools::parse_integer("--threads", text);
    if (*options.threads < 1) throw UsageError("--threads must be at least 1");
  });
  parser.value({"--max-tets"}, store_integer<std::int64_t>("--max-tets", options.max_tets, 1));
}

// What the run writes, and how much it says. An --msh-version applies to the outputs after it, so
// `msh_version_unused` tells whether the last one had none.
void declare_output_options(ArgumentParser& parser, Options& options, meccano::MeshWriteOptions& output_format,
                            bool& msh_version_unused) {
  parser.value({"--report"}, [&](const std::string& path) { options.report = path; });
  parser.value({"--histograms"}, [&](const std::string& path) { options.histograms = path; });
  parser.required_value({"--output", "-o"}, [&](const std::string& path) {
    const auto format = meccano::mesh_format_of(path);
    if (!format)
      throw UsageError("--output " + path +
                       ": unknown format; the extensions are .msh (Gmsh), .vtu (ParaView) and "
                       ".mesh (Medit)");
    if (*format == meccano::MeshFormat::msh) msh_version_unused = false;
    options.outputs.push_back({path, output_format});
  });
  parser.value({"--msh-version"}, [&](const std::string& text) {
    output_format.msh_version = parse_choice<meccano::MshVersion>(
        "--msh-version", text, {{"4.1", meccano::MshVersion::v41}, {"2.2", meccano::MshVersion::v22}},
        "the versions are 4.1 and 2.2");
    msh_version_unused = true;
  });
  parser.flag({"--quiet", "-q"}, [&] { options.quiet = true; });
}

// What no single option can tell: the options that need or exclude one another.
void check_option_combinations(const Options& options) {
  if (!options.surfaces.empty() && !options.resolution) throw UsageError("--surface needs --resolution");
  if (options.surfaces.empty() && (options.resolution || options.stage || options.histograms))
    throw UsageError("--resolution, --stage and --histograms need at least one --surface");
  if (options.histograms && options.stage && *options.stage != meccano::Stage::smoothing)
    throw UsageError("--histograms compares the mesh before and after smoothing: it needs --stage smoothing");
  if (options.surfaces.empty() && (options.reading.weld_tolerance || options.split_parts || options.snap_to_box > 0))
    throw UsageError("--weld-tolerance, --split-parts and --snap-to-box need at least one --surface");
  // Distinct names stay distinct with --split-parts, which splits every surface: in a part's NAME_K,
  // K is what follows the last '_'.
  meccano::tools::check_distinct_names(options.surfaces);
}

Options parse_options(int argc, char** argv) {
  Options options;
  meccano::MeshWriteOptions output_format;  // for the outputs that follow
  bool msh_version_unused = false;
  ArgumentParser parser;
  parser.help(usage_text);
  declare_mesh_options(parser, options);
  declare_surface_options(parser, options);
  declare_method_options(parser, options);
  declare_output_options(parser, options, output_format, msh_version_unused);
  parser.parse({argv + 1, argv + argc});
  if (msh_version_unused) throw UsageError("--msh-version applies to the .msh outputs after it, and none follows");
  check_option_combinations(options);
  return options;
}

using meccano::tools::Progress;

// ", 3 vertices welded, 1 degenerate triangle dropped": what welding did to a surface file, if anything.
std::string welding_summary(const meccano::SurfaceReadReport& report) {
  std::string summary;
  const auto add = [&summary](int count, const char* one, const char* many) {
    if (count > 0) summary += ", " + std::to_string(count) + " " + (count == 1 ? one : many);
  };
  add(report.welded_vertices, "vertex welded", "vertices welded");
  add(report.degenerate_triangles, "degenerate triangle dropped", "degenerate triangles dropped");
  add(report.duplicate_triangles, "duplicate triangle dropped", "duplicate triangles dropped");
  return summary;
}

// The surfaces of `files` ((file, name) pairs), named; with --split-parts, one per part of each file.
std::vector<meccano::TriangleSurface> read_surfaces(const std::vector<std::pair<std::string, std::string>>& files,
                                                    const Options& options, const Progress& progress) {
  std::vector<meccano::TriangleSurface> surfaces;
  for (const auto& [file, name] : files) {
    meccano::SurfaceReadReport report;
    if (!options.split_parts) {
      meccano::TriangleSurface& surface = surfaces.emplace_back(meccano::read_surface(file, options.reading, &report));
      surface.name = name;
      progress.say("surface ", name, ": ", file, ", ", surface.triangles.size(), " triangles, ", surface.points.size(),
                   " points", welding_summary(report));
      continue;
    }
    std::vector<meccano::TriangleSurface> parts = meccano::read_surface_parts(file, options.reading, &report);
    progress.say("surface ", name, ": ", file, ", ", parts.size(), parts.size() == 1 ? " part" : " parts",
                 welding_summary(report));
    for (std::size_t k = 0; k < parts.size(); ++k) {
      meccano::TriangleSurface& part = surfaces.emplace_back(std::move(parts[k]));
      part.name = name + "_" + std::to_string(k + 1);
      progress.say("surface ", part.name, ": part ", k + 1, " of ", file, ", ", part.triangles.size(), " triangles, ",
                   part.points.size(), " points");
    }
  }
  return surfaces;
}

// Surfaces that reach the box boundary clipped to the box: the part inside, each of its disks a surface;
// first, with --snap-to-box, their rims set onto the box where they run near it.
std::vector<meccano::TriangleSurface> clipped_to_box(std::vector<meccano::TriangleSurface> surfaces,
                                                     const Options& options, const Progress& progress) {
  const meccano::Box& box = options.box;
  std::vector<meccano::TriangleSurface> inside;
  for (meccano::TriangleSurface& surface : surfaces) {
    if (options.snap_to_box > 0) {
      const meccano::RimSnap snap = meccano::snap_rim_to_box(surface, box, options.snap_to_box);
      if (snap.vertices > 0)
        progress.say("surface ", surface.name, ": ", snap.vertices,
                     " rim vertices set onto the box (--snap-to-box), moved by up to ", snap.largest_move);
    }
    if (!meccano::reaches_box(surface, box)) {
      inside.push_back(std::move(surface));
      continue;
    }
    for (meccano::TriangleSurface& part : meccano::clip_to_box(surface, box)) {
      progress.say("surface ", part.name, ": clipped by the box, ", part.triangles.size(), " triangles inside");
      inside.push_back(std::move(part));
    }
  }
  return inside;
}

// The cells of the box's meccano, once its tet count is known to be within --max-tets.
std::array<int, 3> meccano_cells(const Options& options, const Progress& progress) {
  const auto cells = options.cells ? *options.cells : meccano::cells_for_box(options.box);
  // In floating point: 1024 cells a side at level 40 would overflow 64 bits, and the limit must still refuse it.
  const double tets = 6.0 * cells[0] * cells[1] * cells[2] * std::ldexp(1.0, options.level);
  const std::int64_t expected_tets = tets < 0x1p62 ? static_cast<std::int64_t>(tets) : std::int64_t{1} << 62;
  progress.say("meccano: ", cells[0], "x", cells[1], "x", cells[2], " cells, level ", options.level, ", ",
               expected_tets, " tets");
  meccano::require_tet_estimate_within(expected_tets, options.max_tets, "the meccano mesh (--cells, --level)");
  return cells;
}

// The method's options as the command line set them; no progress callback.
meccano::InsertionOptions insertion_options(const Options& options) {
  meccano::InsertionOptions insertion;
  insertion.resolution = options.resolution.value_or(0.0);
  insertion.last_stage = options.stage.value_or(meccano::Stage::smoothing);
  insertion.approximation.side_rule = options.side_rule;
  insertion.projection.crease_angle = options.crease_angle;
  insertion.smoothing = options.smoothing;
  insertion.drag_rings = options.drag_rings;
  insertion.improve = options.improve;
  insertion.improvement.threshold = options.improve_threshold;
  insertion.improvement.first_threshold = options.improve_first_threshold;
  insertion.improvement.min_dihedral = options.improve_angles[0];
  insertion.improvement.max_dihedral = options.improve_angles[1];
  insertion.max_tets = options.max_tets;
  insertion.finer_retries = options.finer_retries;
  return insertion;
}

int run(const Options& options) {
  // Every file the run writes, checked before any work: a mistyped path must not cost a meshing run.
  for (const auto& output : options.outputs) meccano::require_writable(output.path);
  for (const auto& path : {options.histograms, options.report})
    if (path) meccano::require_writable(*path);
  const Progress progress(options.quiet);
  if (options.threads) omp_set_num_threads(*options.threads);
  const auto cells = meccano_cells(options, progress);
  // Read and validate every surface before any meshing: bad input must not cost a meshing run.
  std::vector<meccano::TriangleSurface> surfaces =
      clipped_to_box(read_surfaces(options.surfaces, options, progress), options, progress);
  meccano::validate_surfaces(surfaces, options.box);
  if (!surfaces.empty()) progress.say("surfaces valid: disks and spheres, inside the box, disjoint");

  meccano::TetMesh mesh = meccano::make_cube_meccano(options.box, cells, options.level);
  progress.say("meccano: ", mesh.num_tets(), " tets, ", mesh.num_vertices(), " nodes");

  meccano::InsertionOptions insertion = insertion_options(options);
  // Without a callback the stages build no progress lines at all.
  if (!options.quiet) insertion.progress = [&progress](const std::string& line) { progress.say(line); };
  const meccano::InsertionResult result = meccano::insert_surfaces(mesh, surfaces, insertion);

  // A tangled mesh is written only as the projection stage's inspection output.
  const auto check =
      meccano::verify_mesh(result.mesh, {.physical = insertion.last_stage != meccano::Stage::projection});
  if (!check.ok()) throw meccano::MeshingError("the mesh fails its invariant checks: " + check.summary());

  // The files appear together once all are written: a failed run leaves none, and leaves a file that
  // was already there as it was.
  meccano::StagedFiles files;
  const auto groups = meccano::output_groups(result, insertion.last_stage);
  for (const auto& output : options.outputs)
    files.write(output.path,
                [&](const std::string& path) { meccano::write_mesh(result.mesh, groups, path, output.format); });
  if (options.histograms) {
    const std::pair<std::string, const meccano::QualitySummary*> labelled[] = {
        {"before_smoothing", &result.quality_before_smoothing}, {"after_smoothing", &result.quality_after_smoothing}};
    files.write(*options.histograms,
                [&](const std::string& path) { meccano::write_quality_histograms_csv(path, labelled); });
  }
  if (options.report) {
    const std::string report = meccano::insertion_report_json(result, insertion.last_stage);
    files.write(*options.report, [&](const std::string& path) {
      meccano::write_file_atomically(path, [&report](std::ostream& out) { out << report; });
    });
  }
  files.commit();
  for (const auto& output : options.outputs)
    progress.say("wrote ", output.path, ": ", result.mesh.num_tets(), " tets, ", result.mesh.num_vertices(), " nodes");
  if (options.histograms) progress.say("wrote ", *options.histograms);
  if (options.report) progress.say("wrote ", *options.report);
  return 0;
}

// meccano-immerse sequence: the one-shot command's options that apply, and the surfaces of each step.
struct SequenceOptions {
  Options common;  // the outputs are patterns holding {step}
  meccano::SequenceOptions sequence;
  std::vector<std::vector<std::pair<std::string, std::string>>> steps;  // per step: (file, name) per surface
};

// FILE[:NAME],FILE[:NAME],...: the surfaces of one --step.
std::vector<std::pair<std::string, std::string>> parse_step_argument(const std::string& text) {
  std::vector<std::pair<std::string, std::string>> surfaces;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = text.find(',', begin);
    const std::string item = text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    if (item.empty()) throw UsageError("--step " + text + ": an empty surface between commas");
    surfaces.push_back(meccano::tools::parse_surface_argument(item, surfaces.size() + 1));
    if (comma == std::string::npos) return surfaces;
    begin = comma + 1;
  }
}

void check_sequence_options(const SequenceOptions& parsed) {
  const Options& options = parsed.common;
  if (parsed.steps.empty()) throw UsageError("sequence needs at least one --step");
  if (!options.resolution) throw UsageError("sequence needs --resolution");
  if (options.stage || options.histograms)
    throw UsageError("sequence writes each step's finished mesh: --stage and --histograms are for one insertion");
  for (const Output& output : options.outputs) {
    if (output.path.find("{step}") == std::string::npos)
      throw UsageError("--output " + output.path + ": a sequence's output must hold {step}, replaced by the step");
    if (meccano::mesh_format_of(output.path) == meccano::MeshFormat::medit)
      throw UsageError("--output " + output.path +
                       ": a Medit file holds no node data, and each step carries previous_node: use .msh or .vtu");
  }
  const auto names = [](const std::vector<std::pair<std::string, std::string>>& surfaces) {
    std::string list;
    for (const auto& surface : surfaces) list += (list.empty() ? "" : ",") + surface.second;
    return list;
  };
  meccano::tools::check_distinct_names(parsed.steps.front());
  for (std::size_t k = 1; k < parsed.steps.size(); ++k)
    if (names(parsed.steps[k]) != names(parsed.steps.front()))
      throw UsageError("--step " + std::to_string(k) + " names the surfaces " + names(parsed.steps[k]) +
                       ", step 0 names " + names(parsed.steps.front()) +
                       ": every step names the same surfaces in the same order");
}

SequenceOptions parse_sequence_options(const std::vector<std::string>& args) {
  SequenceOptions parsed;
  Options& options = parsed.common;
  // Away from the surfaces the mesh then stays the meccano's, node for node, from one step to the next.
  options.smoothing.mode = meccano::SmoothingMode::band;
  meccano::MeshWriteOptions output_format;
  bool msh_version_unused = false;
  ArgumentParser parser("sequence: ");
  parser.help(usage_text);
  declare_mesh_options(parser, options);
  parser.value({"--step"}, [&](const std::string& text) { parsed.steps.push_back(parse_step_argument(text)); });
  parser.flag({"--from-scratch"}, [&] { parsed.sequence.always_insert = true; });
  parser.value({"--max-quality-loss"}, [&](const std::string& text) {
    parsed.sequence.max_quality_loss = meccano::tools::parse_non_negative("--max-quality-loss", text);
  });
  parser.value({"--max-move"}, [&](const std::string& text) {
    parsed.sequence.max_move_in_resolutions = meccano::tools::parse_non_negative("--max-move", text);
  });
  parser.value({"--max-area-change"}, [&](const std::string& text) {
    parsed.sequence.max_area_change = meccano::tools::parse_non_negative("--max-area-change", text);
  });
  parser.flag({"--retry-after-quality-loss"}, [&] { parsed.sequence.retry_after_quality_loss = true; });
  declare_method_options(parser, options);
  declare_output_options(parser, options, output_format, msh_version_unused);
  parser.parse(args);
  if (msh_version_unused) throw UsageError("--msh-version applies to the .msh outputs after it, and none follows");
  check_sequence_options(parsed);
  return parsed;
}

// The pattern with every {step} replaced by the step's number.
std::string step_path(const std::string& pattern, int step) {
  constexpr std::string_view placeholder = "{step}";
  std::string path;
  std::size_t copied = 0;
  for (auto at = pattern.find(placeholder); at != std::string::npos; at = pattern.find(placeholder, copied)) {
    path += pattern.substr(copied, at - copied) + std::to_string(step);
    copied = at + placeholder.size();
  }
  return path + pattern.substr(copied);
}

// meccano-immerse sequence ...: 0 once every step is written.
int run_sequence(const std::vector<std::string>& args) {
  const SequenceOptions parsed = parse_sequence_options(args);
  const Options& options = parsed.common;
  const int steps = static_cast<int>(parsed.steps.size());
  for (int k = 0; k < steps; ++k)
    for (const Output& output : options.outputs) meccano::require_writable(step_path(output.path, k));
  if (options.report) meccano::require_writable(*options.report);
  const Progress progress(options.quiet);
  if (options.threads) omp_set_num_threads(*options.threads);
  const auto cells = meccano_cells(options, progress);
  // Every step read and validated before any meshing: bad input must not cost a meshing run.
  std::vector<std::vector<meccano::TriangleSurface>> surfaces;
  for (int k = 0; k < steps; ++k) {
    try {
      surfaces.push_back(
          clipped_to_box(read_surfaces(parsed.steps[k], options, Progress(true)), options, Progress(true)));
      meccano::validate_surfaces(surfaces.back(), options.box);
    } catch (const meccano::InputError& error) {
      throw meccano::InputError("step " + std::to_string(k) + ": " + error.what());
    }
  }
  progress.say("steps: ", steps, ", each of ", surfaces.front().size(),
               surfaces.front().size() == 1 ? " surface" : " surfaces", ", all valid");

  meccano::TetMesh mesh = meccano::make_cube_meccano(options.box, cells, options.level);
  progress.say("meccano: ", mesh.num_tets(), " tets, ", mesh.num_vertices(), " nodes");
  meccano::SurfaceSequence sequence(std::move(mesh), insertion_options(options), parsed.sequence);
  meccano::StagedFiles files;
  meccano::JsonWriter report;
  report.begin_object().key("steps").begin_array();
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) {
    const meccano::SequenceStep* step = nullptr;
    try {
      step = &sequence.advance(std::move(surfaces[k]));
    } catch (const meccano::MeshingError& error) {
      throw meccano::MeshingError("step " + std::to_string(k) + ": " + error.what());
    }
    const meccano::InsertionResult& result = step->result;
    const auto check = meccano::verify_mesh(result.mesh);
    if (!check.ok())
      throw meccano::MeshingError("step " + std::to_string(k) +
                                  ": the mesh fails its invariant checks: " + check.summary());
    const meccano::NodeField previous_node{
        "previous_node", {step->previous_node.begin(), step->previous_node.end()}, true};
    const auto groups = meccano::output_groups(result);
    for (const Output& output : options.outputs)
      files.write(step_path(output.path, k), [&](const std::string& path) {
        meccano::write_mesh(result.mesh, groups, path, output.format, {&previous_node, 1});
      });
    meccano::write_sequence_step(report, *step);
    const meccano::QualitySummary& quality = result.quality_after_smoothing;
    progress.say("step ", k, ": ", step->kind == meccano::StepKind::moved ? "moved" : "inserted",
                 step->inserted_because.empty() ? "" : " (" + step->inserted_because + ")", "; ",
                 result.mesh.num_tets(), " tets, ", result.mesh.num_vertices(), " nodes, ", step->nodes_unchanged,
                 " unchanged (", 100.0 * static_cast<double>(step->nodes_unchanged) / result.mesh.num_vertices(),
                 " %); quality min ", quality.meccano.min, " meccano, ", quality.equilateral.min, " equilateral; ",
                 step->seconds, " s");
  }
  report.end_array();
  report.key("seconds").value(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  report.end_object();
  if (options.report) {
    const std::string json = report.str();
    files.write(*options.report, [&](const std::string& path) {
      meccano::write_file_atomically(path, [&json](std::ostream& out) { out << json; });
    });
  }
  files.commit();
  for (const Output& output : options.outputs)
    progress.say("wrote ", step_path(output.path, 0), " ... ", step_path(output.path, steps - 1));
  if (options.report) progress.say("wrote ", *options.report);
  return 0;
}

// The arguments of the subcommands that read one mesh file: FILE.msh [--report FILE.json] [--quiet], and
// --surface FILE[:NAME] ... for those that take surfaces. The report's path is checked writable here.
struct FileCommand {
  std::string file;
  std::optional<std::string> report;
  std::vector<std::pair<std::string, std::string>> surfaces;  // file, name
  bool quiet = false;
};

FileCommand parse_file_command(const std::string& command, const std::vector<std::string>& args, bool takes_surfaces) {
  FileCommand parsed;
  ArgumentParser parser(command + ": ");
  parser.help(usage_text);
  parser.value({"--report"}, [&](const std::string& path) { parsed.report = path; });
  if (takes_surfaces)
    parser.value({"--surface"}, [&](const std::string& text) {
      parsed.surfaces.push_back(meccano::tools::parse_surface_argument(text, parsed.surfaces.size() + 1));
    });
  parser.flag({"--quiet", "-q"}, [&] { parsed.quiet = true; });
  parser.positional([&](const std::string& file) {
    if (!parsed.file.empty())
      throw UsageError(command + " takes one mesh file, got '" + parsed.file + "' and '" + file + "'");
    parsed.file = file;
  });
  parser.parse(args);
  if (parsed.file.empty()) throw UsageError(command + " needs a mesh file: meccano-immerse " + command + " FILE.msh");
  if (parsed.report) meccano::require_writable(*parsed.report);  // before the mesh file is read
  return parsed;
}

// Prints the text (unless --quiet) and writes the JSON report (with --report) of a subcommand's result.
template <class Result>
void publish(const FileCommand& command, const Result& result) {
  if (!command.quiet) std::cout << result.text();
  if (command.report) {
    const std::string json = result.json();
    meccano::write_file_atomically(*command.report, [&json](std::ostream& out) { out << json; });
  }
}

// meccano-immerse check FILE.msh [--report FILE.json] [--quiet]: 0 if every check passes, 1 otherwise.
int run_check(const std::vector<std::string>& args) {
  const FileCommand command = parse_file_command("check", args, false);
  const meccano::MeshFileCheck result = meccano::check_mesh_file(command.file);
  publish(command, result);
  return result.passed() ? 0 : 1;
}

// meccano-immerse measure FILE.msh [--surface FILE[:NAME] ...] [--report FILE.json] [--quiet]: 0 once
// measured.
int run_measure(const std::vector<std::string>& args) {
  const FileCommand command = parse_file_command("measure", args, true);
  std::vector<meccano::TriangleSurface> surfaces;
  for (const auto& [file, name] : command.surfaces) {
    surfaces.push_back(meccano::read_surface(file));
    surfaces.back().name = name;
  }
  publish(command, meccano::measure_mesh_file(command.file, surfaces));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return meccano::tools::run_reporting_errors("meccano-immerse", [&] {
    if (argc > 1 && std::string(argv[1]) == "check") return run_check({argv + 2, argv + argc});
    if (argc > 1 && std::string(argv[1]) == "measure") return run_measure({argv + 2, argv + argc});
    if (argc > 1 && std::string(argv[1]) == "sequence") return run_sequence({argv + 2, argv + argc});
    return run(parse_options(argc, argv));
  });
}
