#include "command_line.hpp"

#include <algorithm>
#include <charconv>
#include <iostream>

namespace solver_demo {

Options parse_options(int argc, char** argv, const std::vector<std::string>& known,
                      const std::vector<std::string>& required) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string name = argv[i];
    if (std::find(known.begin(), known.end(), name) == known.end()) throw UsageError("unknown option '" + name + "'");
    if (i + 1 >= argc) throw UsageError(name + " needs a value");
    if (!options.emplace(name, argv[++i]).second) throw UsageError(name + " is given twice");
  }
  for (const std::string& name : required)
    if (!options.count(name)) throw UsageError(name + " is required");
  return options;
}

int parse_positive_int(const std::string& option, const std::string& text) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || stop != end || value < 1) throw UsageError(option + ": '" + text + "' is not a positive integer");
  return value;
}

unsigned int parse_degree(const std::string& text) {
  if (text != "1" && text != "2") throw UsageError("--degree " + text + ": the degrees are 1 and 2");
  return text == "1" ? 1u : 2u;
}

int run_program(int argc, char** argv, const std::string& name, const std::string& usage,
                const std::function<void(MPI_Comm, const Options&)>& body, const std::vector<std::string>& known,
                const std::vector<std::string>& required) {
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm communicator = MPI_COMM_WORLD;
  const bool root = dealii::Utilities::MPI::this_mpi_process(communicator) == 0;
  int status = 0;
  try {
    if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
      if (root) std::cout << usage;
      return 0;
    }
    body(communicator, parse_options(argc, argv, known, required));
  } catch (const UsageError& error) {
    if (root) std::cerr << name << ": " << error.what() << "\n(see " << name << " --help)\n";
    status = 2;
  } catch (const std::exception& error) {
    std::cerr << name << ": error: " << error.what() << '\n';
    status = 1;
  }
  if (status == 1 && dealii::Utilities::MPI::n_mpi_processes(communicator) > 1) MPI_Abort(communicator, status);
  return status;
}

}  // namespace solver_demo
