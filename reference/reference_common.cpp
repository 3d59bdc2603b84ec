#include "reference_common.hpp"

#include <meccano/io/atomic_file.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/surface/validation.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>

namespace meccano::reference {
namespace {

// --box: six separate numbers, or one comma-separated list as meccano-immerse takes it.
Box parse_box(const std::string& first, tools::ArgumentParser& parser) {
  std::vector<std::string> items;
  if (first.find(',') != std::string::npos) {
    std::stringstream stream(first);
    for (std::string item; std::getline(stream, item, ',');) items.push_back(item);
  } else {
    items.push_back(first);
    while (items.size() < 6)
      if (auto next = parser.next_value()) items.push_back(*next);
      else break;
  }
  if (items.size() != 6) throw UsageError("--box takes 6 numbers: XMIN YMIN ZMIN XMAX YMAX ZMAX");
  std::array<double, 6> v{};
  for (int k = 0; k < 6; ++k) v[k] = tools::parse_finite_number("--box", items[k]);
  return tools::box_from_numbers("--box", v);
}

void declare_common_options(tools::ArgumentParser& parser, const char* usage_text, CommonOptions& options) {
  parser.help(usage_text);
  parser.required_value({"--box"}, [&](const std::string& first) { options.box = parse_box(first, parser); });
  parser.required_value({"--surface"}, [&](const std::string& text) {
    options.surfaces.push_back(tools::parse_surface_argument(text, options.surfaces.size() + 1));
  });
  parser.required_value({"--size"}, [&](const std::string& text) {
    options.size = tools::parse_finite_number("--size", text);
    if (!(*options.size > 0)) throw UsageError("--size must be positive");
  });
  parser.required_value({"--output", "-o"}, [&](const std::string& path) { options.output = path; });
  parser.value({"--report"}, [&](const std::string& path) { options.report = path; });
  parser.flag({"--quiet", "-q"}, [&] { options.quiet = true; });
}

// What parse_arguments checks once every argument is read, past the required options.
void check_common_options(const CommonOptions& options) {
  if (options.output.empty()) throw UsageError("--output is required");  // given as "", as it always was
  if (!options.output.ends_with(".msh"))
    throw UsageError("--output " + options.output + ": only .msh output is supported");
  if (options.report && !options.report->ends_with(".json"))
    throw UsageError("--report " + *options.report + ": the report is a .json file");
  tools::check_distinct_names(options.surfaces);
}

}  // namespace

void parse_arguments(int argc, char** argv, const char* usage_text, CommonOptions& common,
                     const std::function<void(tools::ArgumentParser&)>& declare_tool_options) {
  tools::ArgumentParser parser;
  declare_common_options(parser, usage_text, common);
  declare_tool_options(parser);
  parser.parse({argv + 1, argv + argc});
  check_common_options(common);
}

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

RunStart start_run(const CommonOptions& options) {
  RunStart run{Clock::now(), Progress(options.quiet), {}};
  require_writable(options.output);
  if (options.report) require_writable(*options.report);
  for (const auto& [file, name] : options.surfaces) {
    run.surfaces.push_back(read_surface(file));
    run.surfaces.back().name = name;
    run.progress.say("surface ", name, ": ", file, ", ", run.surfaces.back().triangles.size(), " triangles, ",
                     run.surfaces.back().points.size(), " points");
  }
  validate_surfaces(run.surfaces, options.box);
  run.progress.say("surfaces valid: open disks, inside the box, disjoint");
  return run;
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
  return {.tets = tet_count,
          .nodes = node_count,
          .inverted = static_cast<std::size_t>(summary.inverted),
          .min_mean_ratio = summary.equilateral.min,
          .mean_mean_ratio = summary.equilateral.mean,
          .std_mean_ratio = summary.equilateral.std,
          .min_dihedral_deg = summary.min_dihedral_deg,
          .max_dihedral_deg = summary.max_dihedral_deg,
          .max_volume = max_volume};
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
  json.key("size").value(run.size);
  json.key("tets").value(run.mesh.tets);
  json.key("nodes").value(run.mesh.nodes);
  json.key("inverted").value(run.mesh.inverted);
  json.key("max_tet_volume").value(run.mesh.max_volume);
  json.key("interface_triangles").begin_object();
  for (const auto& [name, count] : run.interface_triangles) json.key(name).value(count);
  json.end_object();
  json.key("seconds").begin_object();
  json.key("meshing").value(run.meshing_seconds);
  json.key("total").value(total_seconds);
  json.end_object();
  json.key("quality").begin_object();
  json.key("equilateral").begin_object();
  json.key("min").value(run.mesh.min_mean_ratio);
  json.key("mean").value(run.mesh.mean_mean_ratio);
  json.key("std").value(run.mesh.std_mean_ratio);
  json.end_object();
  json.key("min_dihedral_deg").value(run.mesh.min_dihedral_deg);
  json.key("max_dihedral_deg").value(run.mesh.max_dihedral_deg);
  json.end_object();
  json.end_object();
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

}  // namespace meccano::reference
