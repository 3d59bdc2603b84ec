// Quality histograms as CSV (the CLI's --histograms), for plotting (scripts/plot_quality.py).
#pragma once

#include <meccano/mesh/quality.hpp>

#include <filesystem>
#include <span>
#include <string>
#include <utility>

namespace meccano {

// CSV with columns bin_low,bin_high,<label>_meccano,<label>_equilateral for each labelled summary, written
// atomically. Labels are letters, digits, '_' and '-'; all summaries have the same bin count
// (std::invalid_argument otherwise). Throws InputError naming the file if it cannot be written.
void write_quality_histograms_csv(const std::filesystem::path& file,
                                  std::span<const std::pair<std::string, const QualitySummary*>> labelled);

}  // namespace meccano
