// What the project's command-line tools share (meccano-immerse, and reference-gmsh and reference-tetgen
// in meshes/): the box, the FILE[:NAME] surface argument and timestamped progress lines. Header-only;
// not part of the installed library.
#pragma once

#include <meccano/mesh/cube_meccano.hpp>

#include "arguments.hpp"

#include <array>
#include <cctype>
#include <chrono>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace meccano::tools {

// The box of six numbers, the minimum corner first. A box the meccano cannot fill (box_defect) is a
// malformed option: UsageError naming the option and the defect.
inline Box box_from_numbers(const std::string& option, const std::array<double, 6>& v) {
  Box box{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  if (const std::string defect = box_defect(box); !defect.empty()) throw UsageError(option + ": " + defect);
  return box;
}

// FILE[:NAME] as (file, name), NAME defaulting to the surface's 1-based position. A colon followed by a
// path separator belongs to the file name. A bad name throws UsageError with why.
inline std::pair<std::string, std::string> parse_surface_argument(const std::string& text, std::size_t position) {
  const auto colon = text.rfind(':');
  if (colon != std::string::npos && colon > 0 && text.find('/', colon) == std::string::npos) {
    const std::string name = text.substr(colon + 1);
    if (name.empty()) throw UsageError("--surface " + text + ": empty name after ':'");
    for (char c : name)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-')
        throw UsageError("--surface " + text + ": a name may hold letters, digits, '_' and '-' only");
    return {text.substr(0, colon), name};
  }
  return {text, std::to_string(position)};
}

// UsageError "two surfaces are named NAME" unless the (file, name) pairs of --surface have distinct names.
inline void check_distinct_names(const std::vector<std::pair<std::string, std::string>>& surfaces) {
  for (std::size_t i = 0; i < surfaces.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (surfaces[i].second == surfaces[j].second) throw UsageError("two surfaces are named " + surfaces[i].second);
}

// Progress lines on stderr, each stamped with the seconds since the tool started; nothing when quiet.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet) {}
  template <class... Parts>
  void say(const Parts&... parts) const {
    if (quiet_) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::ostringstream line;
    line.precision(3);
    line << "[" << std::fixed << seconds << " s] " << std::defaultfloat;
    (line << ... << parts);
    std::cerr << line.str() << std::endl;
  }

 private:
  bool quiet_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace meccano::tools
