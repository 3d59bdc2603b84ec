// Surfaces that reach the box boundary (issue 19): the part of S inside the box.
//
// Why    Faults and fractures reach the ground and cut through the model; the method inserts the part of S
//        inside the box, with its rim on the box faces where S crosses them (stages/projection.hpp, "Box").
// What   box_sides: the box planes a point lies on, exactly (bit 2 axis for box.min[axis], 2 axis + 1 for
//        box.max[axis]). reaches_box: some point of S lies on or beyond the box boundary.
//        clip_to_box: S cut by the six box planes in turn (cut_by_plane, surface/closed_surface.hpp), the
//        inside kept. Every vertex on a cut (a crossing, or a vertex of S that cut_by_plane counts as on the
//        plane because a crossing beside it would leave a sliver) is set exactly onto the plane, so the
//        clipped rim lies on the box faces and box_sides finds it there; a vertex of S moves by at most
//        cut_snap of the span of an edge it ends.
//        snap_rim_to_box: S's rim set onto the box where it runs within `distance` of a box plane without
//        reaching it. A real fault's top edge follows the ground only within its data's accuracy: with the
//        box top at the ground, it dips into the box and back by tens or hundreds of metres, and where the
//        tets are larger than the dip V_M cannot follow it, so S_M's rim runs on along the box and its
//        arcs do not match S's (stages/projection.hpp). A rim vertex inside the box is set onto a box
//        plane when it lies within `distance` of it on a rim edge that runs along the plane (within 45°)
//        and whose other end lies within `distance` too (or on or beyond the plane): whole rim edges come
//        onto the plane, never a lone vertex, which would touch the box at a point, and a rim that leaves
//        the plane steeply (a fault's side edge below the ground) stays. Each vertex moves along the
//        plane's normal, by at most `distance`.
// Input  a surface that passed require_surface_topology (surface/validation.hpp).
// Output of clip_to_box: S itself when it does not reach the box; otherwise the edge-connected parts of S
//        inside the box, by decreasing area, named NAME for one part and NAME_1, NAME_2, ... for several,
//        each with its own points (unused ones dropped), S's orientation and source.
//        of snap_rim_to_box: the surface changed in place, with the count of vertices moved and the
//        largest move.
// Errors clip_to_box: InputError naming the surface: nothing of S inside the box; a closed surface reaching
//        the box (it must lie strictly inside); a triangle in a box plane (S running along the boundary); a
//        part that is not a disk (require_surface_topology's message, e.g. an annulus where a tube crosses
//        the box). snap_rim_to_box: InputError naming the surface, a triangle and its moved vertex when
//        the moves turn the triangle over or flatten it (`distance` too large for the triangles at the
//        rim); the surface is then left as it was.
#pragma once

#include <meccano/mesh/box.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace meccano {

std::uint8_t box_sides(const Eigen::Vector3d& point, const Box& box);

bool reaches_box(const TriangleSurface& surface, const Box& box);

std::vector<TriangleSurface> clip_to_box(const TriangleSurface& surface, const Box& box);

struct RimSnap {
  int vertices = 0;           // rim vertices set onto a box plane
  double largest_move = 0.0;  // in the surface's units
};
RimSnap snap_rim_to_box(TriangleSurface& surface, const Box& box, double distance);

}  // namespace meccano
