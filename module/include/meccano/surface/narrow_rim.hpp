// Where a surface is narrower than a given width, measured from its rim.
//
// Why    The surface approximation (stages/surface_approximation.hpp) gives no side to the nodes of V_M
//        beyond the rim of S, so that S_M does not grow a ragged lip there. Where S is a strip or a tip
//        narrower than V_M's tets, though, nearly every node around it lies beyond the rim, S_M misses that
//        part of S, and the projection would drag S_M's rim over it (a fault model's thin tongue at a coarse
//        l_r). There the rule is lifted.
// What   S's width at a rim vertex v is the distance to the nearest rim point q *across* S from it: one whose
//        shorter way from v along the rim is more than twice the straight distance |v − q|. The rim then
//        leaves v and comes back near it: S between them is a strip, or a tip sharper than 60° (where the
//        ratio is 1 / sin(half the angle)). Rim points near v on the same stretch of rim are not across
//        (there the ratio is close to 1), so a straight or gently curved rim, or one with corners of 60° or
//        more, has no rim point across it; nor has the vertex at a tip. Points on two different rim loops
//        are always across.
// Input  a surface that passed require_surface_topology (surface/validation.hpp): its rim vertices have two
//        rim edges each; a closed surface has no rim. `up_to` > 0.
// Cost   O(R log R) plus, per rim vertex, the rim edges within `up_to` of it in x (a sweep over the edges
//        sorted by x).
#pragma once

#include <meccano/surface/triangle_surface.hpp>

#include <vector>

namespace meccano {

// Per vertex of `surface`: S's width at a rim vertex when it is below `up_to`; infinity for the other rim
// vertices and for the vertices off the rim.
std::vector<double> rim_widths(const TriangleSurface& surface, double up_to);

}  // namespace meccano
