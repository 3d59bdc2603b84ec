// Closed surfaces (issue 19): a triangulated sphere (genus 0) that encloses an inclusion.
//
// Why    The method maps a disk S_M onto a disk S through Floater parameterizations of both onto the unit
//        square (stages/parameterization.hpp). A closed S and its closed S_M are each cut into two disks
//        along matching curves in one coordinate plane, and each half of S_M is mapped onto the
//        corresponding half of S (stages/projection.hpp). This header holds what concerns S alone.
// What   is_closed: no edge of S is used by one triangle only (validation then requires genus 0).
//        enclosed_volume: the volume S encloses, signed: positive when its normals point outwards.
//        oriented_outward: S with every triangle reversed when its normals point inwards, so that S_M,
//        built on S's positive side, lies outside S and the interface faces point out of the inclusion.
//        cut_by_plane: the two parts of S on either side of the plane x[axis] = offset, over one point array
//        (S's points, then one point on each edge that crosses the plane), so the parts share the cut's
//        vertices exactly. A triangle across the plane becomes a triangle on one side and one or two on
//        the other. Where the plane passes within cut_snap of an edge's span along the axis from a vertex
//        of that edge, the vertex counts as on the plane instead (a crossing there would leave a sliver):
//        the cut then runs through it, a little off the plane, and no point of S moves. Each crossing is
//        recorded as a fraction of its edge of S: crossing_points places the crossings on S's edges again
//        after S's points moved (same triangulation), so that a moving closed surface is cut alike at every
//        step (the parts then keep their triangles; the crossings no longer lie on one plane).
//        triangulate_star_shaped: a closed surface for tests and demos (spheres, ellipsoids, blobs): the
//        octahedron |x| + |y| + |z| = 1 with each face cut into n^2 triangles, every point p placed at
//        place(p / |p|), normals pointing out when `place` keeps the directions' order (a star-shaped image).
// Input  a surface that passed require_surface_topology (surface/validation.hpp).
// Output of cut_by_plane: the parts' triangles keep S's orientation. Empty when some triangle lies in the
//        plane. Whether each part is a disk is the caller's question (the plane may cut S in several loops).
#pragma once

#include <meccano/surface/triangle_surface.hpp>

#include <array>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace meccano {

bool is_closed(const TriangleSurface& surface);

double enclosed_volume(const TriangleSurface& surface);

TriangleSurface oriented_outward(TriangleSurface surface);

inline constexpr double cut_snap = 1e-3;

// The point low + fraction (high - low) on the edge (low, high) of S.
struct EdgeCrossing {
  int low = 0, high = 0;
  double fraction = 0.0;
};

struct PlaneCut {
  std::vector<Eigen::Vector3d> points;  // S's points, then the crossings
  std::vector<EdgeCrossing> crossings;  // where each crossing lies on S (same order)
  std::vector<std::array<int, 3>> below, above;
};

std::optional<PlaneCut> cut_by_plane(const TriangleSurface& surface, int axis, double offset);

// `points` (S's, wherever they are now), then the `crossings` on S's edges between them.
std::vector<Eigen::Vector3d> crossing_points(std::vector<Eigen::Vector3d> points,
                                             std::span<const EdgeCrossing> crossings);

TriangleSurface triangulate_star_shaped(const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& place, int n,
                                        std::string name);

}  // namespace meccano
