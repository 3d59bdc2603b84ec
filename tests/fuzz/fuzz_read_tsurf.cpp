// libFuzzer target: read_surface_parts and read_tsurf on arbitrary bytes (see fuzz_input.hpp for what
// counts as a finding). The parts come first: a file of several parts is read whole there, and the
// message read_tsurf then composes names them.
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return meccano::fuzz::read_surface_bytes(data, size, ".ts", [](const std::string& path) {
    for (const meccano::TriangleSurface& part : meccano::read_surface_parts(path)) meccano::fuzz::check_indices(part);
    return meccano::read_tsurf(path);
  });
}
