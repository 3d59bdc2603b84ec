// The JSON report of an insertion (the CLI's --report). Key names are an interface: scripts read them.
#pragma once

#include <meccano/stages/pipeline.hpp>

#include <string>

namespace meccano {

// The report of an insertion as a JSON document: tets, nodes, inverted (after smoothing), quality
// before and after smoothing (meccano and equilateral min/mean/std, inverted, dihedral range),
// min_dihedral_deg and max_dihedral_deg of the result, seconds per stage and in total, and per surface
// the statistics of every stage and its resolution, side_retry and finer_retries if the insertion had to
// be run again (the stage seconds are then those of the last run). Keys of stages not run are left out.
std::string insertion_report_json(const InsertionResult& result, Stage last_stage);

}  // namespace meccano
