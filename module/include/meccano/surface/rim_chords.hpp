// Rim chords of S: interior edges whose two ends both lie on S's rim.
//
// Why    Floater's map of a disk onto the square is one-to-one only if no interior edge joins two rim
//        vertices on one side of the square (stages/parameterization.hpp). The corners of S are moved into
//        the chords' arcs to keep them off one side, but several chords close together (a surface cut out
//        of a larger one, a fault model trimmed along its triangles) can leave no choice of four corners, and
//        S's parameterization fails at every l_r.
// What   split_rim_chords splits every rim chord at its midpoint: the new vertex is interior, and each of the
//        chord's two triangles becomes two. The points of S do not move (the new vertex lies on the chord),
//        so S keeps its geometry, its rim, its creases and their angles; only its triangulation is finer.
//        The result depends on the triangulation alone: the same triangles give the same split whatever the
//        points, so a moving surface (stages/sequence.hpp) is split alike at every step.
// Input  a surface that passed require_surface_topology (surface/validation.hpp).
// Output the surface with new points appended after the old ones (old ids unchanged) and each split
//        triangle replaced in place by its first half, its second half appended; consistently oriented.
#pragma once

#include <meccano/surface/triangle_surface.hpp>

namespace meccano {

// The number of rim chords of `surface`.
int count_rim_chords(const TriangleSurface& surface);

// `surface` with every rim chord split at its midpoint (a copy of it when there is none).
TriangleSurface split_rim_chords(const TriangleSurface& surface);

}  // namespace meccano
