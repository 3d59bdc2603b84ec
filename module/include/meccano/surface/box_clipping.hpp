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
// Input  a surface that passed require_surface_topology (surface/validation.hpp).
// Output of clip_to_box: S itself when it does not reach the box; otherwise the edge-connected parts of S
//        inside the box, by decreasing area, named NAME for one part and NAME_1, NAME_2, ... for several,
//        each with its own points (unused ones dropped), S's orientation and source.
// Errors InputError naming the surface: nothing of S inside the box; a closed surface reaching the box (it
//        must lie strictly inside); a triangle in a box plane (S running along the boundary); a part that
//        is not a disk (require_surface_topology's message, e.g. an annulus where a tube crosses the box).
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

}  // namespace meccano
