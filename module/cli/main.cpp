// meccano-immerse: the command-line front end of the module.
// Exit status: 0 success, 1 failure (bad input data, meshing failed, cannot write), 2 usage error.

#include <meccano/cube_meccano.hpp>
#include <meccano/error.hpp>
#include <meccano/mesh_check.hpp>
#include <meccano/mesh_io.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace {

constexpr const char* usage_text = R"(Usage: meccano-immerse --box X0,Y0,Z0,X1,Y1,Z1 [options] --output FILE.msh

Builds the meccano tetrahedral mesh of a box: equal cells as close to cubes as possible, 6 Kuhn tets
per cell, refined uniformly by Kossaczky bisection.

Options:
  --box X0,Y0,Z0,X1,Y1,Z1  the box (required)
  --cells NX,NY,NZ         cell counts (default: equal cells as close to cubes as possible)
  --level K                uniform bisection levels: 6·2^K tets per cell (default 0)
  --output FILE.msh        Gmsh MSH 4.1 ASCII with the 3D group `domain` and the 2D groups
                           xmin, xmax, ymin, ymax, zmin, zmax (may repeat)
  --quiet                  no progress output
  --help                   this text

Examples:
  meccano-immerse --box 0,0,0,1,1,1 --level 9 --output cube.msh
  meccano-immerse --box 0,0,0,2,1,1 --level 6 --output bar.msh      (two unit cells)
)";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Options {
  meccano::Box box;
  bool box_given = false;
  std::optional<std::array<int, 3>> cells;
  int level = 0;
  std::vector<std::string> outputs;
  bool quiet = false;
};

std::vector<double> parse_numbers(const std::string& option, const std::string& text, std::size_t count) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(value))
      throw UsageError(option + ": '" + item + "' is not a finite number");
    values.push_back(value);
  }
  if (values.size() != count)
    throw UsageError(option + " takes " + std::to_string(count) + " comma-separated numbers, got '" + text + "'");
  return values;
}

int parse_int(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size()) throw UsageError(option + ": '" + text + "' is not an integer");
  return value;
}

Options parse_options(int argc, char** argv) {
  Options options;
  std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw UsageError(arg + " needs a value");
      return args[++i];
    };
    if (arg == "--help" || arg == "-h") {
      std::cout << usage_text;
      std::exit(0);
    } else if (arg == "--box") {
      const auto v = parse_numbers(arg, value(), 6);
      options.box = {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
      options.box_given = true;
    } else if (arg == "--cells") {
      const auto v = parse_numbers(arg, value(), 3);
      std::array<int, 3> cells{};
      for (int k = 0; k < 3; ++k) {
        cells[k] = static_cast<int>(v[k]);
        if (cells[k] != v[k] || cells[k] < 1) throw UsageError("--cells takes three positive integers");
      }
      options.cells = cells;
    } else if (arg == "--level") {
      options.level = parse_int(arg, value());
      if (options.level < 0 || options.level > 40) throw UsageError("--level must be between 0 and 40");
    } else if (arg == "--output" || arg == "-o") {
      options.outputs.push_back(value());
    } else if (arg == "--quiet" || arg == "-q") {
      options.quiet = true;
    } else {
      throw UsageError("unknown option '" + arg + "'");
    }
  }
  if (!options.box_given) throw UsageError("--box is required");
  if (options.outputs.empty()) throw UsageError("--output is required");
  for (const auto& output : options.outputs)
    if (output.size() < 4 || output.substr(output.size() - 4) != ".msh")
      throw UsageError("--output " + output + ": only .msh output is supported");
  return options;
}

class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet) {}
  template <class... Parts>
  void say(const Parts&... parts) const {
    if (quiet_) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::ostringstream line;
    line.precision(3);
    line << "[" << std::fixed << seconds << " s] ";
    (line << ... << parts);
    std::cerr << line.str() << std::endl;
  }

 private:
  bool quiet_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

int run(const Options& options) {
  const Progress progress(options.quiet);
  const auto cells = options.cells ? *options.cells : meccano::cells_for_box(options.box);
  const std::int64_t expected_tets = (std::int64_t{6} * cells[0] * cells[1] * cells[2]) << options.level;
  progress.say("meccano: ", cells[0], "x", cells[1], "x", cells[2], " cells, level ", options.level, ", ",
               expected_tets, " tets");
  const meccano::TetMesh mesh = meccano::make_cube_meccano(options.box, cells, options.level);
  progress.say("meccano: ", mesh.num_tets(), " tets, ", mesh.num_vertices(), " nodes");

  const auto check = meccano::verify_mesh(mesh);
  if (!check.ok()) throw meccano::MeshingError("the mesh fails its invariant checks: " + check.summary());

  const auto groups = meccano::standard_groups(mesh);
  for (const auto& output : options.outputs) {
    meccano::write_msh41(mesh, groups, output);
    progress.say("wrote ", output);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse_options(argc, argv));
  } catch (const UsageError& error) {
    std::cerr << "meccano-immerse: " << error.what() << "\n(see meccano-immerse --help)\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << "meccano-immerse: error: " << error.what() << '\n';
    return 1;
  }
}
