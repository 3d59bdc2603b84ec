// The JSON report of an insertion (the CLI's --report). Key names are an interface: scripts read them.
#pragma once

#include <meccano/report/json_writer.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/stages/sequence.hpp>

#include <string>

namespace meccano {

// The report of an insertion as a JSON document: tets, nodes, inverted (after smoothing), quality
// before and after smoothing (meccano and equilateral min/mean/std, inverted, dihedral range),
// min_dihedral_deg and max_dihedral_deg of the result, seconds per stage and in total, and per surface
// the statistics of every stage and its resolution, side_retry and finer_retries if the insertion had to
// be run again (the stage seconds are then those of the last run). Keys of stages not run are left out.
std::string insertion_report_json(const InsertionResult& result, Stage last_stage);

// The same object, written as the next value of `json` (a member value after key(), or an array element).
void write_insertion_report(JsonWriter& json, const InsertionResult& result, Stage last_stage);

// One step of a moving interface (stages/sequence.hpp) as the next value of `json`: step (from 0), mode
// (moved or inserted), inserted_because (why a later step was inserted anew), seconds (the whole step),
// tets, nodes, nodes_unchanged (nodes at the position of a node of the previous step, bit for bit), quality
// (the result's, keys as after_smoothing above) and the step's whole report under `insertion`.
void write_sequence_step(JsonWriter& json, const SequenceStep& step);

}  // namespace meccano
