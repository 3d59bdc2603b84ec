// What the two demo programs share on the command line: `--name value` options, and main() under MPI
// with the project's exit statuses (0 success, 1 failure: bad input, meshing failed, cannot write;
// 2 usage error).
#pragma once

#include "arguments.hpp"

#include <deal.II/base/mpi.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace solver_demo {

using meccano::tools::UsageError;

// `--name value` pairs. Every name must be one of `known`, given once; `required` ones must be given.
using Options = std::map<std::string, std::string>;

unsigned int parse_degree(const std::string& text);  // 1 or 2

// Initialises MPI, prints `usage` for --help, runs `body` and maps its exceptions to exit statuses,
// printing "NAME: error: ..." or the usage error. Under several ranks, a failure on any rank aborts
// them all, since the others may be waiting in a collective call (usage errors happen on every rank).
int run_program(int argc, char** argv, const std::string& name, const std::string& usage,
                const std::function<void(MPI_Comm, const Options&)>& body, const std::vector<std::string>& known,
                const std::vector<std::string>& required);

}  // namespace solver_demo
