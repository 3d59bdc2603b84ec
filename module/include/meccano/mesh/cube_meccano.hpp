// The cube meccano: a box cut into nx × ny × nz equal cells, each cell into the 6 Kuhn tets around its
// main diagonal, refined uniformly.
//
// Input   a box (min < max on every axis), optionally the cell counts, and a uniform level K.
// Output  a conforming TetMesh with 6 · 2^K tets per cell. Each Kuhn tet with path vertices
//         p0 = corner, p1 = p0 + e_a, p2 = p1 + e_b, p3 = opposite corner is stored as (p0, p3, p2, p1),
//         type 0: the refinement edge is the cell diagonal, and this order is the one under which
//         Kossaczky bisection produces exactly 3 similarity classes (notes §1.3). The Kuhn split is
//         translation invariant, so neighbouring cells conform. Boundary faces carry their box-side tag.
// Errors  InputError for an empty, inverted or infinite box, cell counts outside 1..max_cells_per_axis, or
//         a negative level.
#pragma once

#include <meccano/mesh/tet_mesh.hpp>

#include <string>

namespace meccano {

// The most cells along one axis: grid coordinate differences then stay below 2^41, which orientation
// tests need to be exact in 127 bits (mesh/tet_mesh.cpp).
inline constexpr int max_cells_per_axis = 1024;

// Why the meccano cannot fill `box`, naming the axis ("on axis y the minimum 1 must be below the maximum
// 0", or "... by a finite extent" when max − min overflows), or an empty string if it can. The library
// throws InputError("invalid box: " + defect); the command-line tools make it a usage error.
std::string box_defect(const Box& box);

// Cell counts for equal cells as close to cubes as possible: the cell edge is the box's shortest
// extent and each count is the nearest integer to extent / cell edge (a 2×1×1 box gives 2, 1, 1).
std::array<int, 3> cells_for_box(const Box& box);

TetMesh make_cube_meccano(const Box& box, const std::array<int, 3>& cells, int level = 0);
TetMesh make_cube_meccano(const Box& box, int level = 0);

// The longest physical edge of any tet of bisection level `level` (TetMesh::level) in the undeformed
// meccano. Every cell is cut alike and the tets of level 3k + j are those of level j scaled by 2^-k, so
// one cell refined j times tells.
double longest_edge_at_level(const MeccanoGrid& meccano, int level);

// The finest level V_M may be refined to: computational coordinates have grid_bits bits per cell edge
// (three levels per bit), and V_M's growth may bisect 12 levels beyond its own.
inline constexpr int finest_level = 3 * grid_bits - 12;

// The coarsest level whose tets all have their longest edge below `resolution` (> 0), so that refining
// every tet meeting a surface to it satisfies eq. 1 (l_T < l_r) with one level throughout. InputError
// if that is finer than finest_level.
int level_for_resolution(const MeccanoGrid& meccano, double resolution);

}  // namespace meccano
