#include <meccano/mesh/node_correspondence.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <unordered_map>

namespace meccano {
namespace {

// A position as its coordinates' bits, with -0.0 made 0.0 so that equal numbers hash equal.
using PositionBits = std::array<std::uint64_t, 3>;

PositionBits position_bits(const Eigen::Vector3d& p) {
  return {std::bit_cast<std::uint64_t>(p.x() + 0.0), std::bit_cast<std::uint64_t>(p.y() + 0.0),
          std::bit_cast<std::uint64_t>(p.z() + 0.0)};
}

struct PositionHash {
  std::size_t operator()(const PositionBits& b) const {
    std::uint64_t h = 0;
    for (const std::uint64_t word : b) {
      h = (h ^ word) * 0xbf58476d1ce4e5b9ull;
      h ^= h >> 31;
    }
    return static_cast<std::size_t>(h);
  }
};

}  // namespace

std::vector<VertexId> match_previous_nodes(const TetMesh& previous, const TetMesh& current) {
  std::unordered_map<PositionBits, VertexId, PositionHash> node_at;
  node_at.reserve(previous.points.size());
  for (VertexId v = 0; v < previous.num_vertices(); ++v) node_at.try_emplace(position_bits(previous.points[v]), v);
  std::vector<VertexId> previous_node(current.points.size(), no_previous_node);
  for (VertexId v = 0; v < current.num_vertices(); ++v)
    if (const auto found = node_at.find(position_bits(current.points[v])); found != node_at.end())
      previous_node[v] = found->second;
  return previous_node;
}

std::int64_t count_unchanged_nodes(std::span<const VertexId> previous_node) {
  return std::ranges::count_if(previous_node, [](VertexId v) { return v != no_previous_node; });
}

}  // namespace meccano
