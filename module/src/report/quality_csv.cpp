#include <meccano/report/quality_csv.hpp>

#include <meccano/io/atomic_file.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <ostream>
#include <stdexcept>

namespace meccano {
namespace {

void write_shortest(std::ostream& out, double value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  out.write(buffer, end - buffer);
}

}  // namespace

void write_quality_histograms_csv(const std::filesystem::path& file,
                                  std::span<const std::pair<std::string, const QualitySummary*>> labelled) {
  const auto reject = [&](const std::string& why) {
    throw std::invalid_argument("cannot write " + file.string() + ": " + why);
  };
  if (labelled.empty() || !labelled.front().second) reject("no histograms given");
  const std::size_t bins = labelled.front().second->meccano_histogram.counts.size();
  if (bins == 0) reject("empty histograms");
  for (const auto& [label, summary] : labelled) {
    const bool plain = !label.empty() && std::all_of(label.begin(), label.end(), [](char ch) {
      return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
    });
    if (!plain) reject("label '" + label + "' is not letters, digits, '_' and '-'");
    if (!summary || summary->meccano_histogram.counts.size() != bins ||
        summary->equilateral_histogram.counts.size() != bins)
      reject("histogram '" + label + "' does not have " + std::to_string(bins) + " bins");
  }
  write_file_atomically(file.string(), [&](std::ostream& out) {
    out << "bin_low,bin_high";
    for (const auto& [label, summary] : labelled) out << ',' << label << "_meccano," << label << "_equilateral";
    out << '\n';
    const auto bin_count = static_cast<double>(bins);
    for (std::size_t b = 0; b < bins; ++b) {
      write_shortest(out, static_cast<double>(b) / bin_count);
      out << ',';
      write_shortest(out, static_cast<double>(b + 1) / bin_count);
      for (const auto& [label, summary] : labelled)
        out << ',' << summary->meccano_histogram.counts[b] << ',' << summary->equilateral_histogram.counts[b];
      out << '\n';
    }
  });
}

}  // namespace meccano
