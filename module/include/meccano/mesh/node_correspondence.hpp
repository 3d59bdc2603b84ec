// Which nodes of a mesh were already nodes of another: what a solver needs to carry its nodal values
// from one step of a moving surface to the next (issue 20; the `sequence` command writes it as the node
// data `previous_node`).
//
// Input    the previous step's mesh and the current one; any two TetMesh.
// Output   per node of `current`, the node of `previous` at the same physical position, bit for bit (all
//          three coordinates equal as stored; 0.0 and -0.0 count as equal), or no_previous_node. A node
//          that moved by one rounding error is a new node: only an identical position lets a solver
//          copy its value unchanged.
// Cost     one hash of every node of `previous` and one lookup per node of `current`.
#pragma once

#include <meccano/mesh/tet_mesh.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace meccano {

inline constexpr VertexId no_previous_node = -1;

std::vector<VertexId> match_previous_nodes(const TetMesh& previous, const TetMesh& current);

// The nodes that have a previous node.
std::int64_t count_unchanged_nodes(std::span<const VertexId> previous_node);

}  // namespace meccano
