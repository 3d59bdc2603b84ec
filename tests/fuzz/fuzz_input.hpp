// What every reader fuzz target does with one libFuzzer input.
//
// Input    the bytes of a candidate surface file and the extension of its format.
// Action   the bytes are written to a per-process temporary file (the readers take a path, not a
//          buffer) and read back with the given reader.
// Outcome  an accepted surface must have in-range indices (checked here: the readers promise them);
//          an InputError is the expected answer to bad bytes. Anything else escapes and stops the
//          fuzzer: another exception type (std::bad_alloc from an absurd count, std::length_error, ...),
//          a sanitizer report, a hang (-timeout) or an allocation over -rss_limit_mb / -malloc_limit_mb.
#pragma once

#include <meccano/error.hpp>
#include <meccano/io/surface_readers.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <unistd.h>

namespace meccano::fuzz {

// A file unique to this process, removed at exit; one for the process's life, so that an input
// costs one write, not a file creation.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& extension)
      : path_((std::filesystem::temp_directory_path() / ("meccano-fuzz-" + std::to_string(::getpid()) + extension))
                  .string()) {}
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ~ScratchFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }

  const std::string& write(const std::uint8_t* data, std::size_t size) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) std::abort();  // a full disk is not a finding: stop loudly rather than fuzz nothing
    return path_;
  }

 private:
  std::string path_;
};

// The readers promise in-range indices in every surface they return.
inline void check_indices(const TriangleSurface& surface) {
  for (const auto& triangle : surface.triangles)
    for (const int vertex : triangle)
      if (vertex < 0 || static_cast<std::size_t>(vertex) >= surface.points.size()) std::abort();
}

template <class Reader>
int read_surface_bytes(const std::uint8_t* data, std::size_t size, const std::string& extension, Reader read) {
  static const ScratchFile file(extension);
  const std::string& path = file.write(data, size);
  try {
    check_indices(read(path));
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace meccano::fuzz
