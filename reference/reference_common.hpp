// What the reference meshers of reference/ (reference-gmsh, reference-tetgen) share: the command-line
// options that mean the same in both, the surfaces read and validated exactly as meccano-immerse reads
// them, progress lines, the per-tet quality summary and the JSON report. No mesher library is linked
// here: libgmsh and libtet both define TetGen's symbols and must never meet in one executable.
//
// Options   --box XMIN YMIN ZMIN XMAX YMAX ZMAX (or X0,Y0,Z0,X1,Y1,Z1), --surface FILE[:NAME]
//           (repeatable; NAME defaults to the 1-based position), --size H, --output FILE.msh,
//           --report FILE.json, --quiet (-q). A usage error throws UsageError, which the tools turn
//           into exit status 2.
// Start     start_run: the clock and progress of a run, the outputs required writable, and the surfaces
//           read and validated (read_surface + validate_surfaces: open disks strictly inside the box,
//           disjoint; InputError names the file, the element and the defect), all before meshing.
// Quality   summarize_tets: meccano's per-tet mean ratio (equilateral) and dihedral angles with the rules
//           of meccano::summarize_quality (an inverted tet counts as quality 0; angles of valid tets
//           only), so that every tool is measured alike.
// Report    write_report: the keys of meccano::QualitySummary plus counts, sizes and timings, written
//           atomically; each tool adds its own keys after "tool".
#pragma once

#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/box.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/report/json_writer.hpp>

#include "arguments.hpp"
#include "tool_support.hpp"

#include <chrono>
#include <cstddef>
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace meccano::reference {

using tools::UsageError;

struct CommonOptions {
  Box box;
  std::vector<std::pair<std::string, std::string>> surfaces;  // file, name
  std::optional<double> size;
  std::string output;
  std::optional<std::string> report;
  bool quiet = false;
};

// Reads the command line: --help (-h) prints usage_text and exits with status 0; the common options go
// to `common`, the tool's own to the handlers that declare_tool_options declares; an argument neither
// knows is a UsageError. Then checks that --box, --surface, --size and --output are given, the output
// is a .msh file, the report a .json file, and no two surfaces have the same name.
void parse_arguments(int argc, char** argv, const char* usage_text, CommonOptions& common,
                     const std::function<void(tools::ArgumentParser&)>& declare_tool_options);

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start);

using tools::Progress;

// What every run does before it meshes: starts its clock and progress, throws InputError naming the first
// of --output and --report that cannot be written (require_writable), and reads the surfaces of the
// options, named, in order, validated against the box. Every input error is found before the mesher runs,
// with meccano-immerse's messages.
struct RunStart {
  Clock::time_point start;
  Progress progress;
  std::vector<TriangleSurface> surfaces;
};
RunStart start_run(const CommonOptions& options);

struct MeshSummary {
  std::size_t tets = 0;
  std::size_t nodes = 0;
  std::size_t inverted = 0;  // signed volume not positive (or not a number)
  // Equilateral mean ratio over all tets, an inverted one counting as 0; std is the population's.
  double min_mean_ratio = 0.0, mean_mean_ratio = 0.0, std_mean_ratio = 0.0;
  double min_dihedral_deg = 180.0, max_dihedral_deg = 0.0;  // over the tets that are not inverted
  double max_volume = 0.0;                                  // the largest tet's volume
};

// Quality of tets 0 .. tet_count - 1, tet t having the corners points_of_tet(t) in the file's order,
// added to one meccano::QualityAccumulator in tet order (points_of_tet need not be thread-safe).
MeshSummary summarize_tets(std::size_t tet_count, std::size_t node_count,
                           const std::function<TetPoints(std::size_t)>& points_of_tet);

// "N tets, M nodes; mean ratio min A mean B, dihedral C..D deg", for progress lines.
std::string describe(const MeshSummary& summary);

struct ReferenceRun {
  std::string tool;  // "reference-gmsh", ...
  double size = 0.0;
  std::vector<std::pair<std::string, std::size_t>> interface_triangles;  // surface name, faces on it
  MeshSummary mesh;
  double meshing_seconds = 0.0;
};

// {"tool", <tool_keys>, "size", "tets", "nodes", "inverted", "max_tet_volume",
//  "interface_triangles": {NAME: count}, "seconds": {"meshing", "total"},
//  "quality": {"equilateral": {"min", "mean", "std"}, "min_dihedral_deg", "max_dihedral_deg"}}.
void write_report(const ReferenceRun& run, const std::function<void(JsonWriter&)>& tool_keys, double total_seconds,
                  const std::string& path);

// The tool's outputs: the mesh (mesh_writer to the path given) and, with --report, the report, staged so
// that both appear or neither (a file already there stays as it was); then says where they went.
using PathWriter = std::function<void(const std::string& path)>;
void write_outputs(const CommonOptions& common, const Progress& progress, const PathWriter& mesh_writer,
                   const PathWriter& report_writer);

}  // namespace meccano::reference
