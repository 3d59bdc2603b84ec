// Small helpers shared by the stages that reason about the topology of regions and surfaces of the
// mesh (volumetric_approximation.cpp, surface_approximation.cpp). Internal: not installed.
#pragma once

#include <meccano/tet_mesh.hpp>

#include <numeric>
#include <utility>
#include <vector>

namespace meccano::detail {

using Edge = std::pair<VertexId, VertexId>;
inline Edge make_edge(VertexId a, VertexId b) { return a < b ? Edge{a, b} : Edge{b, a}; }

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) { reset(n); }
  void reset(std::size_t n) {
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(std::size_t a, std::size_t b) { parent_[find(a)] = find(b); }
  int components() {
    int count = 0;
    for (std::size_t i = 0; i < parent_.size(); ++i) count += find(i) == i;
    return count;
  }

 private:
  std::vector<std::size_t> parent_;
};

}  // namespace meccano::detail
