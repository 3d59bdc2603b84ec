// Generators of immersed test surfaces.
//
// Every generator returns a regular triangulation of an open topological disk with consistent
// orientation (normals by the right-hand rule), `name` set and `source` empty, lying well inside the
// unit cube [0,1]^3 (at least 0.1 from its faces). n is the resolution: cells per side of a grid patch,
// rings of the spherical cap; triangle counts grow like n^2.
#pragma once

#include <meccano/mesh/box.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace meccano::testing {

// z = f(x, y) over x_range x y_range, n x n cells, two triangles per cell, normals towards +z.
TriangleSurface graph_patch(const std::function<double(double, double)>& f, std::array<double, 2> x_range,
                            std::array<double, 2> y_range, int n, std::string name = "graph");

TriangleSurface tilted_plane(int n);               // z = 0.35 + 0.3 x + 0.1 y over [0.1, 0.9]^2
TriangleSurface near_vertical_patch(int n);        // x ~ 0.5 + small bump, within 5 degrees of the plane x = 0.5
TriangleSurface saddle(int n);                     // z = 0.5 + 1.2 (x - 0.5)(y - 0.5) over [0.1, 0.9]^2
TriangleSurface spherical_cap(int n);              // radius 0.4, polar angle 65 degrees, circular rim, n rings
TriangleSurface strongly_curved_sheet(int n);      // 220-degree sector of a cylinder of radius 0.3 (axis y)
std::vector<TriangleSurface> stacked_pair(int n);  // two parallel bumps, 0.3 apart in z
// A wavy n x n patch over [0.2, 0.8]^2 with a sawtooth rim: a triangle (a tooth) on each of its n rim
// edges at y = 0.2, so those edges join two rim vertices, like the rim of a surface trimmed along its
// triangles (tooth k's apex is point (n + 1)^2 + k).
TriangleSurface sawtooth_patch(int n);
// The paper-like patch of shared/notes/peers.md section 6: over (x, y) in [0.2, 0.8]^2,
// z = 0.42 + 0.12 u v + 0.10 sin(pi u) sin(pi v), u = (x - 0.2) / 0.6, v = (y - 0.2) / 0.6.
TriangleSurface paper_like_patch(int n);

// Closed surfaces (issue 19), normals pointing out. The octahedron |x| + |y| + |z| = 1 with each face cut into
// n^2 triangles, its points pushed onto the ellipsoid with these centre and radii.
TriangleSurface ellipsoid(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii, int n,
                          std::string name = "ellipsoid");
TriangleSurface sphere(int n);  // centre (0.5, 0.5, 0.5), radius 0.3
// A star-shaped blob: the sphere of radius 0.25 about (0.5, 0.5, 0.5) with radius 0.25 (1 + 0.25 b(d)), b a
// sum of three smooth bumps over the unit directions d.
TriangleSurface bumpy_blob(int n);
// A torus (genus 1) of radii 0.25 and 0.1 about (0.5, 0.5, 0.5), n x n cells: closed, but not a sphere.
TriangleSurface closed_torus(int n);

struct NamedSurfaces {
  std::string name;
  std::vector<TriangleSurface> surfaces;
};

// All of the above (the stacked pair as one entry with two surfaces), plus a perturbed paper-like
// patch (irregular triangles).
std::vector<NamedSurfaces> named_test_surfaces(int n);

// The rim edges of a surface (its edges used by one triangle), each as (smaller, larger) vertex, sorted.
std::vector<std::pair<int, int>> rim_edges(const TriangleSurface& surface);
// Distance from x to the rim polyline of a surface.
double distance_to_rim(const TriangleSurface& surface, const Eigen::Vector3d& x);

// A case of the stage tests: surfaces (inserted in order) in a box at a resolution.
struct SurfaceCase {
  std::string name;  // a valid test name: letters, digits, '_'
  std::vector<TriangleSurface> surfaces;
  Box box;
  double resolution;
};

// GoogleTest prints a parameter by its name rather than as a dump of its bytes.
inline void PrintTo(const SurfaceCase& c, std::ostream* os) { *os << c.name; }

// Every entry of named_test_surfaces(n) in the unit cube at l_r = 1/16 and 1/32, in a 2x1x1 box at 1/16
// and in a flat 1 x 1.5 x 0.5 box at 1/40; with `perturbed`, also perturbed (seed 7) at 1/24.
std::vector<SurfaceCase> surface_cases(int n, bool with_perturbed);

// Moves every vertex not on the rim by a random tangential offset of length at most amplitude times
// the shortest edge at that vertex (deterministic for a seed on every platform). amplitude <= 0.25
// keeps every triangle valid.
TriangleSurface perturbed(TriangleSurface surface, double amplitude, std::uint64_t seed);

// Maps the unit cube onto `box` (affinely, per axis).
TriangleSurface scaled_into(TriangleSurface surface, const Box& box);

// Real surfaces: the largest side of a surface's bounding box (its "extent"), and that box enlarged on
// every side by `margin` times the extent (the box a fault is meshed in by the tests and benchmarks).
double largest_extent(const TriangleSurface& surface);
Box box_around(const TriangleSurface& surface, double margin = 0.1);

// The surface as a Wavefront OBJ file at `path` (exact: 17 digits); returns the path.
std::string write_obj(const std::string& path, const TriangleSurface& surface);

// The shared fault file of that name (../shared/data/faults beside the checkout, GOCAD TSurf, UTM
// metres), or an empty string when the data is not there: tests that need it skip.
std::string shared_fault(const std::string& file);

// That shared fault read as meccano-immerse reads it and named "fault", or nothing when the data is not
// there: `if (!surface) GTEST_SKIP() << ...;`.
std::optional<TriangleSurface> read_shared_fault(const std::string& file);

}  // namespace meccano::testing
