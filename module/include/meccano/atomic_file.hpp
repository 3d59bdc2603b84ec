// Writes a file so that it either appears complete or not at all: the content goes to a temporary
// file in the same directory, which is renamed over the target only after a successful flush.
// Errors: InputError naming the path and the system's reason (unwritable directory, full disk, ...);
// the temporary file is removed.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace meccano {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace meccano
