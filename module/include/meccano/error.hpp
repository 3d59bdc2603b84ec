// Errors thrown by the module.
//
// InputError   the user's data is wrong (a file, a surface, an option value); the message names the
//              file, the line or element, and the defect. The CLI maps it to exit status 1.
// MeshingError the input was accepted but a pipeline stage could not produce a valid result
//              (refinement depth exhausted, healing did not converge, SUS could not untangle).
#pragma once

#include <stdexcept>
#include <string>

namespace meccano {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class MeshingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace meccano
