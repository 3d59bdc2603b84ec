// Writes a file so that it either appears complete or not at all: the content goes to a temporary
// file in the same directory, which is renamed over the target only after a successful flush.
// Errors: InputError naming the path and the system's reason (unwritable directory, full disk, ...);
// the temporary file is removed.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace meccano {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// Throws InputError ("cannot write PATH: why") unless a file can be written at `path`: its directory
// exists and is writable, and the path is not a directory or another non-regular file. A tool checks
// every output this way before a long computation, so that a mistyped path fails at once; the write
// itself still reports what only shows then (a full disk).
void require_writable(const std::string& path);

// Several files that appear together or not at all. write(target, writer) has `writer` write the
// target's content to a staged path next to it (any writer that takes a path: write_mesh, or
// write_file_atomically); commit() renames the staged files over their targets in order. Destroyed
// before commit(), the set removes its staged files and leaves every target as it was, a file already
// there included.
// Errors: write() throws InputError for a target that exists and is not a regular file (renaming over a
// device or a FIFO would replace it), and passes on the writer's errors with the target named in place
// of the staged path; commit() throws InputError naming the file whose rename fails (the staged files
// not yet renamed are removed with the set).
class StagedFiles {
 public:
  StagedFiles() = default;
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  ~StagedFiles();

  void write(const std::string& target, const std::function<void(const std::string& path)>& writer);
  void commit();

 private:
  std::vector<std::pair<std::string, std::string>> staged_;  // (staged path, target), not yet renamed
};

}  // namespace meccano
