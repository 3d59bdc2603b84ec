#include <meccano/report/insertion_report.hpp>

#include <meccano/report/json_writer.hpp>

namespace meccano {
namespace {

void write_statistics(JsonWriter& json, const char* name, const QualityStatistics& statistics) {
  json.key(name).begin_object();
  json.key("min").value(statistics.min).key("mean").value(statistics.mean).key("std").value(statistics.std);
  json.end_object();
}

void write_quality(JsonWriter& json, const char* name, const QualitySummary& quality) {
  json.key(name).begin_object();
  write_statistics(json, "meccano", quality.meccano);
  write_statistics(json, "equilateral", quality.equilateral);
  json.key("inverted").value(quality.inverted);
  json.key("min_dihedral_deg").value(quality.min_dihedral_deg).key("max_dihedral_deg").value(quality.max_dihedral_deg);
  json.end_object();
}

void write_surface(JsonWriter& json, const SurfaceInsertion& inserted, Stage last_stage) {
  json.begin_object().key("name").value(inserted.name).key("resolution").value(inserted.resolution);
  json.key("closed").value(inserted.closed);
  const VolumetricStats& v = inserted.volumetric_stats;
  json.key("volumetric").begin_object();
  json.key("tets").value(v.tets).key("tets_meeting_surface").value(v.tets_intersecting);
  json.key("level").value(v.level).key("reach").value(v.reach);
  json.key("axis_tets").value(v.axis_tets).key("euler_node_stars").value(v.euler_node_stars);
  json.key("cavity_tets").value(v.cavity_tets).key("thickening_layers").value(v.thickening_layers);
  json.key("growth_refinements").value(v.growth_refinements);
  json.key("refinement_passes").value(v.refinement_passes).key("bisections").value(v.bisections);
  json.key("growth_passes").value(v.growth_passes).key("band_tets").value(v.band_tets);
  json.key("seconds").value(inserted.volumetric_seconds).end_object();
  if (last_stage >= Stage::approximation) {
    const HealingStats& h = inserted.healing_stats;
    json.key("approximation").begin_object();
    json.key("side").value(h.side).key("healing_passes").value(h.passes).key("faces").value(h.faces);
    json.key("rim_nodes").value(h.rim_nodes).key("corbels").value(h.corbels);
    json.key("reflex_corners_filled").value(h.reflex_corners_filled);
    json.key("reflex_corners_left").value(h.reflex_corners_left);
    json.key("tets_with_two_faces").value(h.tets_with_two_faces);
    json.key("triangles_with_two_rim_edges").value(h.triangles_with_two_rim_edges);
    json.key("cross_surface_edges").value(h.cross_surface_edges).key("dividing_edges").value(h.dividing_edges);
    json.key("chord_edges").value(h.chord_edges);
    json.key("seconds").value(inserted.approximation_seconds).end_object();
  }
  if (last_stage >= Stage::projection) {
    const ProjectionStats p = inserted.projection_stats();
    json.key("projection").begin_object();
    json.key("nodes").value(p.nodes).key("rim_nodes").value(p.rim_nodes);
    json.key("largest_move").value(p.largest_move).key("largest_distance_after").value(p.largest_distance_after);
    json.key("rim_gap").value(p.rim_gap);
    json.key("inverted_tets").value(p.inverted_tets);
    json.key("creases").begin_object();
    json.key("lines").value(p.creases.lines).key("crossings").value(p.creases.crossings);
    json.key("nodes").value(p.creases.nodes).key("refused").value(p.creases.refused);
    json.key("straddling").value(p.creases.straddling);
    json.key("sharpest_deg").value(p.creases.sharpest).end_object();
    json.key("seconds").value(inserted.projection_seconds).end_object();
  }
  json.end_object();
}

// "operations" by kind, and the tets removed and created.
void write_flip_operations(JsonWriter& json, const FlipStats& flips) {
  json.key("operations").begin_object();
  json.key("flips_2_3").value(flips.flips_2_3).key("flips_3_2").value(flips.flips_3_2);
  json.key("flips_4_4").value(flips.flips_4_4).key("edge_removals").value(flips.edge_removals);
  json.key("surface_edge_flips").value(flips.surface_edge_flips);
  json.key("cap_flips").value(flips.cap_flips);
  json.key("crease_splits").value(flips.crease_splits);
  json.key("crease_moves").value(flips.crease_moves);
  json.end_object();
  json.key("tets_removed").value(flips.tets_removed).key("tets_created").value(flips.tets_created);
}

void write_smoothing(JsonWriter& json, const InsertionResult& result) {
  const SmoothingStats& s = result.smoothing;
  json.key("smoothing").begin_object();
  json.key("inner_nodes").value(s.inner_nodes).key("box_nodes").value(s.box_nodes);
  json.key("surface_nodes").value(s.surface_nodes).key("rim_nodes").value(s.rim_nodes);
  json.key("crease_nodes").value(s.crease_nodes);
  json.key("active_tets").value(s.active_tets).key("colours").value(s.colours);
  json.key("inverted_before").value(s.inverted_before).key("inverted_after").value(s.inverted_after);
  json.key("untangling_sweeps").value(s.untangling_sweeps).key("fallback_sweep").value(s.fallback_sweep);
  json.key("sweeps").begin_array();
  for (const SweepRecord& sweep : s.sweeps) {
    json.begin_object();
    json.key("inverted").value(sweep.inverted).key("nodes_optimised").value(sweep.nodes_optimised);
    json.key("min_quality").value(sweep.min_quality).key("mean_quality").value(sweep.mean_quality);
    json.key("power").value(sweep.power).key("objective").value(sweep.objective);
    json.key("target").value(sweep.target == SmoothingTarget::meccano ? "meccano" : "equilateral");
    json.key("seconds").value(sweep.seconds).end_object();
  }
  json.end_array();
  if (result.untangling_flip_rounds > 0) {
    json.key("untangling_flips").begin_object().key("rounds").value(result.untangling_flip_rounds);
    write_flip_operations(json, result.untangling_flips);
    json.end_object();
  }
  json.key("seconds").value(result.smoothing_seconds).end_object();
}

void write_improvement(JsonWriter& json, const ImprovementStats& s, double seconds) {
  json.key("improvement").begin_object();
  json.key("threshold").value(s.floors.mean_ratio).key("first_threshold").value(s.first_threshold);
  json.key("min_dihedral_deg")
      .value(s.floors.min_dihedral_deg)
      .key("max_dihedral_deg")
      .value(s.floors.max_dihedral_deg);
  json.key("passes").value(s.passes);
  json.key("tets_below_threshold_before").value(s.tets_below_before);
  json.key("tets_below_threshold_after").value(s.tets_below_after);
  json.key("node_updates").value(s.node_updates).key("nodes_moved").value(s.nodes_moved);
  json.key("min_equilateral_quality_before").value(s.min_quality_before);
  json.key("min_equilateral_quality_after").value(s.min_quality_after);
  json.key("shape_passes").value(s.shape_passes);
  json.key("shape_node_updates").value(s.shape_node_updates).key("shape_nodes_moved").value(s.shape_nodes_moved);
  json.key("tets_outside_floors_before").value(s.tets_outside_floors_before);
  json.key("tets_outside_floors_after").value(s.tets_outside_floors_after);
  json.key("rounds").value(s.rounds);
  write_flip_operations(json, s.flips);
  json.key("remeshed_tets").value(s.remeshed_tets);
  json.key("seconds").value(seconds).end_object();
}

}  // namespace

void write_insertion_report(JsonWriter& json, const InsertionResult& result, Stage last_stage) {
  const bool smoothed = last_stage == Stage::smoothing && !result.surfaces.empty();
  const bool projected = last_stage >= Stage::projection && !result.surfaces.empty();
  json.begin_object();
  json.key("tets").value(result.mesh.num_tets()).key("nodes").value(result.mesh.num_vertices());
  json.key("estimated_tets").value(result.estimated_tets);
  const QualitySummary& final_quality = smoothed ? result.quality_after_smoothing : result.quality_before_smoothing;
  if (projected) {
    json.key("inverted").value(final_quality.inverted);
    json.key("quality").begin_object();
    write_quality(json, "before_smoothing", result.quality_before_smoothing);
    if (smoothed) write_quality(json, "after_smoothing", result.quality_after_smoothing);
    json.end_object();
    json.key("min_dihedral_deg").value(final_quality.min_dihedral_deg);
    json.key("max_dihedral_deg").value(final_quality.max_dihedral_deg);
  }
  // Stage seconds are those of the attempt that succeeded; seconds.total counts all attempts.
  if (!result.side_retry.empty()) json.key("side_retry").value(result.side_retry);
  if (!result.finer_retries.empty()) {
    json.key("finer_retries").begin_array();
    for (const std::string& failure : result.finer_retries) json.value(failure);
    json.end_array();
  }

  double stage_seconds[4] = {0, 0, 0, result.smoothing_seconds};
  for (const SurfaceInsertion& inserted : result.surfaces) {
    stage_seconds[0] += inserted.volumetric_seconds;
    stage_seconds[1] += inserted.approximation_seconds;
    stage_seconds[2] += inserted.projection_seconds;
  }
  static constexpr const char* stage_keys[4] = {"volumetric", "approximation", "projection", "smoothing"};
  json.key("seconds").begin_object();
  for (int stage = 0; stage <= static_cast<int>(last_stage) && !result.surfaces.empty(); ++stage)
    json.key(stage_keys[stage]).value(stage_seconds[stage]);
  if (smoothed && result.improvement) json.key("improvement").value(result.improvement_seconds);
  json.key("total").value(result.seconds).end_object();

  json.key("surfaces").begin_array();
  for (const SurfaceInsertion& inserted : result.surfaces) write_surface(json, inserted, last_stage);
  json.end_array();
  if (last_stage >= Stage::projection && result.drag.rings > 0) {
    json.key("drag").begin_object().key("rings").value(result.drag.rings).key("nodes").value(result.drag.nodes);
    json.key("inverted_tets").value(result.drag.inverted_tets).end_object();
  }
  if (smoothed) write_smoothing(json, result);
  if (smoothed && result.improvement) write_improvement(json, *result.improvement, result.improvement_seconds);
  json.end_object();
}

std::string insertion_report_json(const InsertionResult& result, Stage last_stage) {
  JsonWriter json;
  write_insertion_report(json, result, last_stage);
  return json.str();
}

void write_sequence_step(JsonWriter& json, const SequenceStep& step) {
  const InsertionResult& result = step.result;
  json.begin_object().key("step").value(step.index);
  json.key("mode").value(step.kind == StepKind::moved ? "moved" : "inserted");
  if (!step.inserted_because.empty()) json.key("inserted_because").value(step.inserted_because);
  json.key("seconds").value(step.seconds);
  json.key("tets").value(result.mesh.num_tets()).key("nodes").value(result.mesh.num_vertices());
  json.key("nodes_unchanged").value(step.nodes_unchanged);
  write_quality(json, "quality", result.quality_after_smoothing);
  json.key("insertion");
  write_insertion_report(json, result, Stage::smoothing);
  json.end_object();
}

}  // namespace meccano
