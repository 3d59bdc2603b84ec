#include <meccano/pipeline.hpp>

#include <meccano/error.hpp>
#include <meccano/mesh_check.hpp>

#include <chrono>
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

// Cheap invariant check at the end of a stage: a failure here is a bug, not bad input.
void check_stage(const TetMesh& mesh, const char* stage) {
  const auto check = verify_mesh(mesh, {.physical = true});
  if (!check.ok()) throw MeshingError(std::string("mesh invalid after the ") + stage + " stage: " + check.summary());
}

}  // namespace

InsertionResult insert_surfaces(TetMesh mesh, std::span<const TriangleSurface> surfaces, const InsertionOptions& options) {
  InsertionResult result;
  result.mesh = std::move(mesh);
  if (static_cast<int>(surfaces.size()) > max_interfaces)
    throw InputError("at most " + std::to_string(max_interfaces) + " surfaces can be inserted");

  // Step 1: the volumetric approximation of each surface.
  result.surfaces.reserve(surfaces.size());
  for (const TriangleSurface& surface : surfaces) {
    const auto start = std::chrono::steady_clock::now();
    SurfaceInsertion& inserted = result.surfaces.emplace_back();
    inserted.name = surface.name;
    std::vector<TetRegion*> earlier;
    for (std::size_t s = 0; s + 1 < result.surfaces.size(); ++s) earlier.push_back(&result.surfaces[s].volumetric);
    const TriangleBVH tree(surface);
    inserted.volumetric = approximate_volume(result.mesh, tree, {options.resolution}, inserted.volumetric_stats, earlier);
    inserted.volumetric_seconds = seconds_since(start);
    const auto& stats = inserted.volumetric_stats;
    report(options, "volumetric ", surface.name, ": ", stats.refinement_passes, " refinement passes, ",
           stats.bisections, " bisections, ", stats.tets_intersecting, " tets meet S; grown to ", stats.tets,
           " tets (", stats.euler_node_stars, " node stars, ", stats.cavity_tets, " cavity tets, ", stats.axis_tets,
           " axis tets); mesh ", result.mesh.num_tets(), " tets");
  }
  check_stage(result.mesh, "volumetric");
  return result;
}

MeshGroups output_groups(const InsertionResult& result) {
  MeshGroups groups = standard_groups(result.mesh);
  for (const SurfaceInsertion& inserted : result.surfaces) {
    TetGroup group{"volumetric_" + inserted.name, {}};
    for (TetId t = 0; t < result.mesh.num_tets(); ++t)
      if (inserted.volumetric[t]) group.tets.push_back(t);
    groups.volumes.push_back(std::move(group));
  }
  return groups;
}

}  // namespace meccano
