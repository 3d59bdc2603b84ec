// Validation of immersed surfaces before any meshing.
//
// The method handles consistently oriented triangulated surfaces that are open disks or closed spheres
// (genus 0, surface/closed_surface.hpp), lie inside the box (strictly, but for the rim of a surface clipped
// by the box, surface/box_clipping.hpp) and do not intersect each other. Every function here throws
// InputError for the first defect it finds; the message names the surface's source file (or its name), the element
// (1-based triangle or vertex number, in the order read) and the defect.
//
// Topology (surface/validation.cpp): empty surface, non-finite coordinates, index out of range,
// zero-area triangle, non-manifold edge or vertex, inconsistent orientation, more than one connected
// component, neither a topological disk (holes, an annulus, a handle) nor a sphere (a closed surface of
// genus 1 or more: a torus).
// Geometry (surface/geometry_checks.cpp): self-intersection, a point outside or on the box boundary (but
// for a rim vertex of an open surface, exactly on a box plane), two surfaces that intersect or touch.
#pragma once

#include <meccano/mesh/box.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <span>

namespace meccano {

void require_surface_topology(const TriangleSurface& surface);
void require_no_self_intersection(const TriangleSurface& surface);
void require_strictly_inside_box(const TriangleSurface& surface, const Box& box);
// Closed surfaces strictly inside; open ones inside, their rim vertices allowed exactly on the box planes
// (a surface clipped by the box, surface/box_clipping.hpp), any other vertex off them by the margin.
void require_inside_box(const TriangleSurface& surface, const Box& box);
void require_surfaces_disjoint(const TriangleSurface& a, const TriangleSurface& b);

// All of the above, topology first (the geometric checks assume a valid triangulation).
void validate_surfaces(std::span<const TriangleSurface> surfaces, const Box& box);

}  // namespace meccano
