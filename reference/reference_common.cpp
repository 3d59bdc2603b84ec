#include "reference_common.hpp"

#include <meccano/io/atomic_file.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/surface/validation.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>

namespace meccano::reference {
namespace {

// Six separate numbers, or one comma-separated list as meccano-immerse takes it.
Box parse_box(const std::vector<std::string>& args, std::size_t& i) {
  const std::string& option = args[i];
  std::vector<std::string> items;
  if (const std::string& first = option_value(args, i); first.find(',') != std::string::npos) {
    std::stringstream stream(first);
    for (std::string item; std::getline(stream, item, ',');) items.push_back(item);
  } else {
    items.push_back(first);
    while (items.size() < 6 && i + 1 < args.size() && !args[i + 1].starts_with("--")) items.push_back(args[++i]);
  }
  if (items.size() != 6) throw UsageError(option + " takes 6 numbers: XMIN YMIN ZMIN XMAX YMAX ZMAX");
  std::array<double, 6> v{};
  for (int k = 0; k < 6; ++k) v[k] = parse_number(option, items[k]);
  return tools::box_from_numbers<UsageError>(option, v);
}

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// If args[i] is one of the common options, reads it and its values into `options`, leaves i at its
// last value and returns true; returns false for any other argument.
bool parse_common_option(const std::vector<std::string>& args, std::size_t& i, CommonOptions& options) {
  const std::string& arg = args[i];
  if (arg == "--box") {
    options.box = parse_box(args, i);
    options.box_given = true;
  } else if (arg == "--surface") {
    options.surfaces.push_back(tools::parse_surface_argument<UsageError>(option_value(args, i), options.surfaces.size() + 1));
  } else if (arg == "--size") {
    options.size = parse_number(arg, option_value(args, i));
    if (!(*options.size > 0)) throw UsageError("--size must be positive");
  } else if (arg == "--output" || arg == "-o") {
    options.output = option_value(args, i);
  } else if (arg == "--report") {
    options.report = option_value(args, i);
  } else if (arg == "--quiet" || arg == "-q") {
    options.quiet = true;
  } else {
    return false;
  }
  return true;
}

// What parse_arguments checks once every argument is read.
void check_common_options(const CommonOptions& options) {
  if (!options.box_given) throw UsageError("--box is required");
  if (options.surfaces.empty()) throw UsageError("--surface is required");
  if (!options.size) throw UsageError("--size is required");
  if (options.output.empty()) throw UsageError("--output is required");
  if (!ends_with(options.output, ".msh"))
    throw UsageError("--output " + options.output + ": only .msh output is supported");
  if (options.report && !ends_with(*options.report, ".json"))
    throw UsageError("--report " + *options.report + ": the report is a .json file");
  for (std::size_t i = 0; i < options.surfaces.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (options.surfaces[i].second == options.surfaces[j].second)
        throw UsageError("two surfaces are named " + options.surfaces[i].second);
}

}  // namespace

const std::string& option_value(const std::vector<std::string>& args, std::size_t& i) {
  if (i + 1 >= args.size()) throw UsageError(args[i] + " needs a value");
  return args[++i];
}

double parse_number(const std::string& option, const std::string& text) {
  return tools::parse_finite_number<UsageError>(option, text);
}

void parse_arguments(int argc, char** argv, const char* usage_text, CommonOptions& common,
                     const ToolOptionParser& parse_tool_option) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::cout << usage_text;
      std::exit(0);
    }
    if (!parse_common_option(args, i, common) && !parse_tool_option(args, i))
      throw UsageError("unknown option '" + args[i] + "'");
  }
  check_common_options(common);
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void check_outputs_writable(const CommonOptions& options) {
  require_writable(options.output);
  if (options.report) require_writable(*options.report);
}

std::vector<TriangleSurface> read_valid_surfaces(const CommonOptions& options, const Progress& progress) {
  std::vector<TriangleSurface> surfaces;
  for (const auto& [file, name] : options.surfaces) {
    surfaces.push_back(read_surface(file));
    surfaces.back().name = name;
    progress.say("surface ", name, ": ", file, ", ", surfaces.back().triangles.size(), " triangles, ",
                 surfaces.back().points.size(), " points");
  }
  validate_surfaces(surfaces, options.box);
  progress.say("surfaces valid: open disks, inside the box, disjoint");
  return surfaces;
}

MeshSummary summarize_tets(std::size_t tet_count, std::size_t node_count,
                           const std::function<TetPoints(std::size_t)>& points_of_tet) {
  QualityAccumulator quality;
  double max_volume = 0.0;
  for (std::size_t t = 0; t < tet_count; ++t) {
    const TetPoints p = points_of_tet(t);
    quality.add(p);
    if (const double volume = signed_volume(p[0], p[1], p[2], p[3]); std::isfinite(volume))
      max_volume = std::max(max_volume, volume);
  }
  const QualitySummary summary = quality.summary();
  return {.tets = tet_count, .nodes = node_count, .inverted = static_cast<std::size_t>(summary.inverted),
          .min_mean_ratio = summary.equilateral.min, .mean_mean_ratio = summary.equilateral.mean,
          .std_mean_ratio = summary.equilateral.std, .min_dihedral_deg = summary.min_dihedral_deg,
          .max_dihedral_deg = summary.max_dihedral_deg, .max_volume = max_volume};
}

std::string describe(const MeshSummary& summary) {
  std::ostringstream text;
  text << summary.tets << " tets, " << summary.nodes << " nodes; mean ratio min " << summary.min_mean_ratio << " mean "
       << summary.mean_mean_ratio << ", dihedral " << summary.min_dihedral_deg << ".." << summary.max_dihedral_deg
       << " deg";
  return text.str();
}

void write_report(const ReferenceRun& run, const std::function<void(JsonWriter&)>& tool_keys, double total_seconds,
                  const std::string& path) {
  JsonWriter json;
  json.begin_object().key("tool").value(run.tool);
  tool_keys(json);
  json.key("size").value(run.size)
      .key("tets").value(run.mesh.tets)
      .key("nodes").value(run.mesh.nodes)
      .key("inverted").value(run.mesh.inverted)
      .key("max_tet_volume").value(run.mesh.max_volume)
      .key("interface_triangles").begin_object();
  for (const auto& [name, count] : run.interface_triangles) json.key(name).value(count);
  json.end_object()
      .key("seconds").begin_object()
      .key("meshing").value(run.meshing_seconds)
      .key("total").value(total_seconds)
      .end_object()
      .key("quality").begin_object()
      .key("equilateral").begin_object()
      .key("min").value(run.mesh.min_mean_ratio)
      .key("mean").value(run.mesh.mean_mean_ratio)
      .key("std").value(run.mesh.std_mean_ratio)
      .end_object()
      .key("min_dihedral_deg").value(run.mesh.min_dihedral_deg)
      .key("max_dihedral_deg").value(run.mesh.max_dihedral_deg)
      .end_object()
      .end_object();
  write_file_atomically(path, [&](std::ostream& out) { out << json.str(); });
}

void write_outputs(const CommonOptions& common, const Progress& progress, const PathWriter& mesh_writer,
                   const PathWriter& report_writer) {
  StagedFiles files;
  files.write(common.output, mesh_writer);
  if (common.report) files.write(*common.report, report_writer);
  files.commit();
  progress.say("wrote ", common.output);
  if (common.report) progress.say("wrote ", *common.report);
}

int run_tool(const std::string& tool, const std::function<int()>& parse_and_run) {
  try {
    return parse_and_run();
  } catch (const UsageError& error) {
    std::cerr << tool << ": " << error.what() << "\n(see " << tool << " --help)\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << tool << ": error: " << error.what() << '\n';
    return 1;
  }
}

}  // namespace meccano::reference
