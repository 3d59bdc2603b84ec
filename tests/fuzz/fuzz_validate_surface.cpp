// libFuzzer target: validate_surfaces on up to three small surfaces decoded from arbitrary bytes.
//
// Each surface is: a byte v (vertex count, 1..64; its top bit selects raw doubles instead of grid
// coordinates), a byte t (triangle count, 1..64), the coordinates, then 3 t index bytes. Grid
// coordinates are k / 200 - 0.1 for a byte k, which puts points on a lattice in and around the unit box,
// the cases the exact predicates must get right: coplanar and collinear triangles, shared vertices,
// points on the box boundary. Raw doubles bring NaN, infinities and huge values. An index byte i gives
// i - 4, so a few negative and out-of-range indices occur. validate_surfaces must either accept the set
// or throw InputError; anything else (another exception, a sanitizer report, a hang) is a finding.
// Then the same surfaces go the tool's way (module/cli/main.cpp): each disk's rim set onto the box within
// 0.02 (snap_rim_to_box), clipped to the box (clip_to_box), the parts validated; InputError again is the
// only acceptable failure. Surfaces with non-finite coordinates, which the readers refuse, skip that way.
#include <meccano/error.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/validation.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace {

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool has(std::size_t count) const { return bytes_.size() - pos_ >= count; }
  std::uint8_t byte() { return bytes_[pos_++]; }
  double raw_double() {
    double value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof value);
    pos_ += sizeof value;
    return value;
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

constexpr int kMaxSurfaces = 3;
constexpr int kMaxCount = 64;

// False when the bytes run out before the surface is complete.
bool decode_surface(ByteReader& in, meccano::TriangleSurface& surface) {
  if (!in.has(2)) return false;
  const std::uint8_t vertex_byte = in.byte();
  const bool raw = (vertex_byte & 0x80) != 0;
  const int vertices = 1 + (vertex_byte & 0x7f) % kMaxCount;
  const int triangles = 1 + in.byte() % kMaxCount;
  if (!in.has(static_cast<std::size_t>(vertices) * 3 * (raw ? sizeof(double) : 1) +
              3 * static_cast<std::size_t>(triangles)))
    return false;
  for (int v = 0; v < vertices; ++v) {
    Eigen::Vector3d& p = surface.points.emplace_back();
    for (int axis = 0; axis < 3; ++axis) p[axis] = raw ? in.raw_double() : in.byte() / 200.0 - 0.1;
  }
  for (int t = 0; t < triangles; ++t) {
    std::array<int, 3>& triangle = surface.triangles.emplace_back();
    for (int& vertex : triangle) vertex = in.byte() - 4;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader in({data, size});
  std::vector<meccano::TriangleSurface> surfaces;
  while (static_cast<int>(surfaces.size()) < kMaxSurfaces) {
    meccano::TriangleSurface surface;
    surface.name = "fuzz" + std::to_string(surfaces.size() + 1);
    if (!decode_surface(in, surface)) break;
    surfaces.push_back(std::move(surface));
  }
  if (surfaces.empty()) return 0;
  const meccano::Box box{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
  try {
    meccano::validate_surfaces(surfaces, box);
  } catch (const meccano::InputError&) {
  }
  try {
    std::vector<meccano::TriangleSurface> inside;
    for (meccano::TriangleSurface& surface : surfaces) {
      for (const Eigen::Vector3d& p : surface.points)
        if (!p.allFinite()) return 0;
      meccano::require_surface_topology(surface);
      meccano::snap_rim_to_box(surface, box, 0.02);
      for (meccano::TriangleSurface& part : meccano::clip_to_box(surface, box)) inside.push_back(std::move(part));
    }
    meccano::validate_surfaces(inside, box);
  } catch (const meccano::InputError&) {
  }
  return 0;
}
