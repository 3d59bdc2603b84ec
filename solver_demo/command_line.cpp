#include "command_line.hpp"

#include <algorithm>
#include <iostream>

namespace solver_demo {

namespace {

Options parse_options(int argc, char** argv, const std::vector<std::string>& known,
                      const std::vector<std::string>& required) {
  Options options;
  meccano::tools::ArgumentParser parser;
  for (const std::string& name : known) {
    auto store_once = [&options, name](const std::string& value) {
      if (!options.emplace(name, value).second) throw UsageError(name + " is given twice");
    };
    if (std::find(required.begin(), required.end(), name) != required.end()) parser.required_value({name}, store_once);
    else parser.value({name}, store_once);
  }
  parser.parse({argv + 1, argv + argc});
  return options;
}

}  // namespace

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
