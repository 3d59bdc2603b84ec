// Step 3 of the method (paper §4.3): Floater parameterizations of a triangulated disk onto the unit
// square P = [0,1]^2, the choice of matching corners for the pair (S, S_M), and point location in the
// parametric triangulation, i.e. evaluation of φ: P -> S and of its derivative.
//
// Input    a DiskView: points and triangles (0-based) of an open topological disk whose triangles are
//          consistently oriented. Points no triangle uses are allowed (S_M is a subset of the faces of a
//          mesh and keeps the mesh's vertex numbering): they get NaN parameters.
// Rim      rim_loop: the boundary as one loop of vertex ids, in the direction of the triangles'
//          boundary edges, so the disk lies to its left seen from the side its normals point to.
// Square   parameterize_to_square: the 4 corners go to (0,0), (1,0), (1,1), (0,1); the rim is walked
//          from corner 0 through corners 1, 2, 3 (in whichever direction meets them in that order) and
//          the vertices between two corners are spaced along that side of the square by chord length.
//          Interior vertex i: u_i = Σ_j λ_ij u_j with Floater's convex weights λ (mean value, Floater 2003,
//          or shape preserving, Floater 1997), one sparse LU factorisation for both coordinates.
// Invariants of a returned SquareParameterization (Floater 2003, "One-to-one piecewise linear mappings
//          over triangulations": convex weights on a convex boundary give a one-to-one map exactly when no
//          interior edge joins two vertices of one side of the square):
//          - rim vertices have one coordinate exactly 0 or 1, corners are exactly the square's corners;
//          - every parametric triangle has a signed area (corner order) of the sign `orientation`, +1 when
//            the corners follow rim_loop's direction, -1 when they run against it; the areas sum to 1
//            up to rounding, so the parametric triangles tile P.
// Corners  corners_by_arc_length chooses the corners of one disk (S); matching_corners chooses those of
//          S_M near the corners of S, in the same cyclic order around the same normal. Both then move a
//          corner into the short rim arc of any interior edge whose ends would lie on one side.
// Location ParametricSurface: the triangle of the parametric triangulation holding a point of P, by a
//          straight walk from a hint triangle or by a uniform grid over P; φ and dφ/duv there. All
//          queries are const and keep their state on the stack: threads may share one object.
// Errors   MeshingError, with the vertex, edge or triangle at fault, when the rim is not one loop, the
//          corners cannot be chosen, or the map is not one-to-one; std::invalid_argument for misuse
//          (corner ids not on the rim or not in cyclic order, a non-finite query point).
#pragma once

#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>

#include <array>
#include <optional>
#include <span>
#include <vector>

namespace meccano {

// A triangulated disk, borrowed: the spans must outlive every call that receives the view.
struct DiskView {
  std::span<const Eigen::Vector3d> points;
  std::span<const std::array<int, 3>> triangles;

  DiskView(std::span<const Eigen::Vector3d> disk_points, std::span<const std::array<int, 3>> disk_triangles)
      : points(disk_points), triangles(disk_triangles) {}
  // Implicit on purpose: a TriangleSurface is a disk wherever a view is expected.
  DiskView(const TriangleSurface& surface) : points(surface.points), triangles(surface.triangles) {}  // NOLINT
};

// The rim, starting at its smallest vertex id, in the direction of the triangles' boundary edges.
// Throws MeshingError if an edge is used twice in one direction (inconsistent orientation or more than two
// triangles on an edge), if there is no rim, if the rim edges do not form one simple loop, or if the Euler
// characteristic is not 1 (a handle, or another component).
std::vector<int> rim_loop(DiskView disk);

// ½ Σ x_i × x_{i+1} over a closed loop: the vector area of any surface the loop bounds (Stokes), which
// for a disk is the area-weighted sum of its triangle normals. Its direction is "the mean normal" around
// which the orientation of rim loops is compared.
Eigen::Vector3d vector_area(std::span<const Eigen::Vector3d> points, std::span<const int> loop);

enum class FloaterWeights { mean_value, shape_preserving };

struct SquareParameterization {
  std::vector<Eigen::Vector2d> uv;  // per point of the view; NaN for points no triangle uses
  std::vector<int> rim;             // rim loop in the order the square's boundary is walked; rim[0] = corners[0]
  std::array<int, 4> corners{};     // vertex ids mapped to (0,0), (1,0), (1,1), (0,1)
  int orientation = 1;              // sign of every parametric triangle's area, see the header comment
  FloaterWeights weights = FloaterWeights::mean_value;
};

// A rim vertex placed at a given point of the square's perimeter, besides the corners: `at` is the
// perimeter coordinate, k + t on side k (0 <= t < 1, see perimeter_coordinate). A surface clipped by the box
// pins S_M's rim nodes where its rim passes from one box face to another, or into the box, at the
// coordinates of the matching rim vertices of S, so that the arcs on each box face map onto each other.
struct RimAnchor {
  int vertex = -1;
  double at = 0.0;
};

// Where on the square's perimeter a point of it lies: u on side 0 (v = 0), 1 + v on side 1 (u = 1),
// 2 + (1 - u) on side 2 (v = 1), 3 + (1 - v) on side 3 (u = 0); corners give 0, 1, 2, 3.
double perimeter_coordinate(const Eigen::Vector2d& uv);

// Throws std::invalid_argument if the corners are not 4 distinct rim vertices met in this cyclic order
// along the rim (either direction), or the anchors are not rim vertices whose coordinates increase with
// the corners' along that walk; MeshingError if an interior edge joins two vertices of one side (the
// message names the triangle when all three of its vertices are on that side), if the sparse solver
// fails, or if a parametric triangle comes out flipped or flat (a rounding failure that the theorem above
// excludes in exact arithmetic). Between consecutive corners and anchors the rim is spaced by chord length.
SquareParameterization parameterize_to_square(DiskView disk, const std::array<int, 4>& corners,
                                              FloaterWeights weights = FloaterWeights::mean_value,
                                              std::span<const RimAnchor> anchors = {});

// Corners of one disk, in rim_loop's direction, for a rim with or without natural corners:
//  1. corner 0 is `start` (a rim vertex id) or, for start = -1, the rim vertex with the largest turning
//     angle (the first in rim_loop order among equals);
//  2. corner k (k = 1, 2, 3) targets the arc-length fraction k/4 of the perimeter measured from corner 0:
//     it is the sharpest rim vertex turning by more than 45 degrees within 1/8 of the perimeter of the
//     target (a natural corner: rectangles keep theirs), else the rim vertex closest to the target;
//  3. the corners are made distinct and increasing along the rim, then repaired: while an interior edge
//     has both ends on one side, the nearer (by arc length) of that side's two corners moves to the
//     nearest vertex strictly inside the edge's short rim arc (an ear's apex thus becomes a corner).
// Throws MeshingError if the rim has fewer than 4 vertices or the repair does not settle.
std::array<int, 4> corners_by_arc_length(DiskView disk, int start = -1);

// Corners of S_M matching those of S. `targets` are S's corners (3D points, in S's corner order) and
// `normal` the common mean normal, vector_area of S's rim loop. S_M's rim is walked in the direction that
// turns around `normal` the same way as S's rim: rim_loop's if vector_area(S_M rim) · normal > 0, the
// reverse otherwise (an S_M whose triangles are oriented against S's). Along that walk, corner 0 is the
// rim vertex closest to targets[0]; corners 1, 2, 3 follow it in order and minimise the sum of their
// distances to targets[1..3] (exact, by dynamic programming over the walk); then the repair of
// corners_by_arc_length step 3. Pass the result to parameterize_to_square as is: its orientation is -1 when
// the walk ran against rim_loop. Throws MeshingError as corners_by_arc_length.
std::array<int, 4> matching_corners(DiskView disk, const std::array<Eigen::Vector3d, 4>& targets,
                                    const Eigen::Vector3d& normal);

// φ: P -> disk, piecewise linear over the parametric triangulation. Copies what it needs.
class ParametricSurface {
 public:
  struct Location {
    int triangle = -1;            // index into the view's triangles
    Eigen::Vector3d barycentric;  // weights of the triangle's corners: >= 0, sum 1
  };

  // Throws std::invalid_argument if `parameterization` does not fit this disk (another point count, or a
  // vertex of a triangle without parameters).
  ParametricSurface(DiskView disk, SquareParameterization parameterization);

  // The triangle holding uv, clamped to P. With a hint (a triangle index), a straight walk from it is
  // tried first (up to 32 steps: beyond that the grid is cheaper); otherwise, or if the walk gives up, the
  // grid cell of uv is searched. A point within 1e-12 (in barycentric terms) of a triangle counts as
  // inside; the barycentrics returned are clamped to >= 0 and renormalised, so evaluate always lands on
  // the triangle. On an edge shared by two triangles either may be returned. Throws std::invalid_argument
  // for a non-finite uv.
  Location locate(const Eigen::Vector2d& uv, int hint = -1) const;

  // The straight walk alone: from the centroid of triangle `start` along the line towards uv (clamped to
  // P), crossing at each step the edge beyond which uv lies that the line crosses. Empty if it did not
  // arrive within max_steps (>= 0) steps (or left P by rounding).
  std::optional<Location> walk(const Eigen::Vector2d& uv, int start, int max_steps) const;

  Eigen::Vector3d evaluate(const Location& location) const;    // φ(uv)
  Eigen::Matrix<double, 3, 2> derivative(int triangle) const;  // dφ/duv, constant per triangle
  // How closely the triangle with corners x lies along S's triangle `triangle`: |cos| of the angle between
  // their normals, 1 where they are parallel, 0 for a degenerate triangle (no normal: never aligned). An
  // S_M triangle's alignment with S is taken at its centroid in P.
  double alignment(const std::array<Eigen::Vector3d, 3>& x, int triangle) const;
  const SquareParameterization& parameterization() const { return parameterization_; }
  int triangle_count() const { return static_cast<int>(triangles_.size()); }

 private:
  Eigen::Vector3d barycentric(int triangle, const Eigen::Vector2d& uv) const;
  Location grid_search(const Eigen::Vector2d& uv) const;

  SquareParameterization parameterization_;
  // Compact copies: only the vertices the triangles use (S_M uses few of the mesh's points).
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Vector2d> uv_;
  std::vector<std::array<int, 3>> triangles_;   // compact vertex ids, same triangle order as the view
  std::vector<std::array<int, 3>> neighbours_;  // across the edge opposite corner k; -1 on the rim
  int grid_size_ = 1;                           // cells per side of P
  std::vector<int> cell_start_;                 // CSR: triangles whose box meets cell c are
  std::vector<int> cell_triangles_;             // cell_triangles_[cell_start_[c] .. cell_start_[c+1])
};

}  // namespace meccano
