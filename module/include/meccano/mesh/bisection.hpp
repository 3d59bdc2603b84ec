// Kossaczky bisection (the recursive refinement of ALBERTA), conforming at every step.
//
// Input    a conforming TetMesh whose tets are in Kossaczky order (v0-v1 = refinement edge) with types,
//          e.g. the cube meccano of mesh/cube_meccano.hpp.
// Rule     bisecting tet (v0, v1, v2, v3) of type t at the midpoint m of v0-v1 gives
//            child 0 = (v0, v2, v3, m) and
//            child 1 = (v1, v3, v2, m) for t = 0, (v1, v2, v3, m) for t = 1, 2,
//          both of type (t + 1) mod 3. A tet is only bisected together with every tet around its
//          refinement edge (its refinement patch); a tet of the patch whose refinement edge differs is
//          first bisected itself, recursively. The mesh is therefore conforming after every patch.
// Storage  child 0 takes its parent's index; child 1 is appended. A stage that keeps per-tet data
//          passes a ChildCallback to extend it (called with the parent index and child 1's index).
// Output   face tags are inherited by the sub-faces of each tagged face; the new interior face is
//          untagged. New vertices get the exact computational midpoint and the physical midpoint.
// Errors   MeshingError when a midpoint cannot be represented exactly (more than 3·grid_bits levels).
#pragma once

#include <meccano/mesh/tet_mesh.hpp>

#include <functional>
#include <span>

namespace meccano {

using ChildCallback = std::function<void(TetId parent, TetId child1)>;

// Bisects every marked tet once (marked tets bisected as part of another's patch count as done), plus
// whatever the closure needs. Returns the number of bisections performed.
std::int64_t refine_marked(TetMesh& mesh, std::span<const TetId> marked, const ChildCallback& on_child = {});

// Bisects every tet `levels` times: 2^levels times as many tets. On the cube meccano every patch is
// compatible, so no recursion happens.
void refine_uniformly(TetMesh& mesh, int levels);

// Splits the edge (a, b), which `start` must contain, by bisecting tets that contain it until it is a
// refinement edge and gets bisected. Returns the midpoint vertex.
VertexId split_edge(TetMesh& mesh, TetId start, VertexId a, VertexId b, const ChildCallback& on_child = {});

}  // namespace meccano
