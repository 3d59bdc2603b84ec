// libFuzzer target: read_stl on arbitrary bytes (see fuzz_input.hpp for what counts as a finding).
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return meccano::fuzz::read_surface_bytes(data, size, ".stl", meccano::read_stl);
}
