// Geometric predicates on triangles and tetrahedra, and a bounding volume hierarchy over a surface.
//
// Inputs   points in double precision; triangles and tetrahedra as arrays of their corners (any vertex
//          order, any orientation, degenerate shapes allowed).
// Outputs  yes/no predicates, distances, closest points, and the side of an oriented surface.
// Guarantees and tolerances (L = size of the configuration: the largest coordinate difference between
//          its points, measured from one of them):
//   triangle_intersects_tetrahedron  never misses an intersection; may answer "intersects" when the two
//                      are disjoint but closer than about 1e-12 L along a separating axis.
//   triangles_intersect  closed triangles; "touching" counts as intersecting, and so does a gap below
//                      1e-12 L along every separating axis. Triangles sharing corners (same surface) are
//                      tested for contact elsewhere than the shared corners; see the function.
//   triangle_separation, triangle_distance  accurate to rounding (about 1e-15 L).
//   TriangleBVH::side  +1 for points closer to S than 1e-12 times the diagonal of its bounding box.
#pragma once

#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <optional>
#include <span>
#include <vector>

namespace meccano {

using Triangle3 = std::array<Eigen::Vector3d, 3>;
using Tetrahedron3 = std::array<Eigen::Vector3d, 4>;

Eigen::AlignedBox3d bounding_box(std::span<const Eigen::Vector3d> points);

// The 2D cross product a.x b.y - a.y b.x: twice the signed area of the triangle (0, a, b), positive when
// it turns counterclockwise.
inline double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double tetrahedron_longest_edge(const Tetrahedron3& tet);

// The point x of the convex hull of `points` (at least one) nearest the origin, by GJK's distance
// algorithm: every point p then has p·x ≥ (1 − 1e-12)|x|², so a step along x raises every p·d at once. For
// gradients, x is the steepest ascent direction of their minimum, and zero at a max-min optimum.
Eigen::Vector3d hull_point_nearest_origin(std::span<const Eigen::Vector3d> points);

// The displacement at x of the rigid motion that best carries `from` onto `to` (paired points; least
// squares: the rotation from the SVD of their centred cross-covariance, Kabsch's, with a reflection
// turned back into a rotation), or none when the points do not fix a rotation (fewer than three, or so
// nearly on a line that their spread's middle eigenvalue is below 1e-6 of the largest).
std::optional<Eigen::Vector3d> rigid_displacement(std::span<const Eigen::Vector3d> from,
                                                  std::span<const Eigen::Vector3d> to, const Eigen::Vector3d& x);

// Whether the triangle meets the closed tetrahedron: a separating axis test (axis-aligned directions,
// triangle normal, the 4 face normals, the 18 cross products of a triangle edge and a tetrahedron edge).
// An axis separates only if the gap exceeds 1e-12 L, far above the rounding error of the projections,
// so a true intersection is never missed. Near-parallel edge pairs give tiny, imprecise axes; that
// does not matter, since any direction that separates proves disjointness.
bool triangle_intersects_tetrahedron(const Triangle3& tri, const Tetrahedron3& tet);

// Whether two closed triangles intersect or touch (coplanar overlap included); tolerance 1e-12 L as
// above. `shared_corners` (0, 1 or 2) says that the first shared_corners corners of a and b are the same
// vertices of one surface, listed in the same order:
//   1 (shared vertex): true if they meet elsewhere than at that vertex, i.e. an edge opposite the shared
//     vertex meets the other triangle (within 1e-12 L), which is exact in the absence of tolerance;
//   2 (shared edge): true if the triangles fold onto each other (coplanar, on the same side of the edge),
//     i.e. the angle between their half-planes is below 1e-12 radians; non-coplanar triangles sharing
//     an edge only meet along it.
bool triangles_intersect(const Triangle3& a, const Triangle3& b, int shared_corners = 0);

// Largest gap between the projections of a and b onto the separating-axis candidates (unit directions).
// Positive: disjoint, and the value is a lower bound of their distance. Otherwise they intersect and
// -value is the penetration depth: the length of the shortest translation that separates them.
double triangle_separation(const Triangle3& a, const Triangle3& b);

// Squared distance from x to the segment p0-p1; `parameter`, if given, receives the closest point's t in
// p0 + t (p1 - p0), t in [0, 1] (0 for a degenerate segment).
double squared_distance_to_segment(const Eigen::Vector3d& x, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                   double* parameter = nullptr);

// Euclidean distance between two closed triangles (0 when they intersect).
double triangle_distance(const Triangle3& a, const Triangle3& b);

// Euclidean distance between two triangulated surfaces (0 when they meet): the smallest triangle_distance
// over the pairs of `a`'s triangles and `b`'s, found through b's hierarchy (TriangleBVH, below).
class TriangleBVH;
double surface_distance(const TriangleSurface& a, const TriangleBVH& b);

// The feature of a triangle that holds a closest point. Edge k joins corners k and (k + 1) % 3.
enum class Feature { face, edge, vertex };

struct ClosestPoint {
  Eigen::Vector3d point;
  double squared_distance = 0.0;
  Feature feature = Feature::face;
  int feature_index = 0;  // corner (vertex) or edge number within the triangle; 0 for the face
  int triangle = -1;      // triangle of the surface (set by TriangleBVH; -1 for a lone triangle)
};

ClosestPoint closest_point_on_triangle(const Eigen::Vector3d& x, const Triangle3& tri);

// Bounding volume hierarchy over the triangles of a surface. It copies the coordinates of every
// triangle, so the surface may change or go away after construction. Build: median split of the
// centroids along the longest axis, leaves of at most 4 triangles, O(n log n). Queries are const and
// keep their state on the stack, so threads may share one hierarchy.
class TriangleBVH {
 public:
  // Throws std::invalid_argument for a surface without triangles.
  explicit TriangleBVH(const TriangleSurface& surface);

  int triangle_count() const { return static_cast<int>(corners_.size()); }
  const Triangle3& triangle(int t) const { return corners_[t]; }
  const Eigen::AlignedBox3d& bounds() const { return nodes_.front().box; }

  // Calls visit(t) for every triangle t whose bounding box meets the closed box `box`.
  template <class Visit>
  void for_each_triangle_overlapping(const Eigen::AlignedBox3d& box, Visit&& visit) const {
    any_triangle_overlapping(box, [&visit](int t) {
      visit(t);
      return false;
    });
  }

  // Whether predicate(t) holds for some triangle t whose bounding box meets `box`; stops at the first.
  template <class Predicate>
  bool any_triangle_overlapping(const Eigen::AlignedBox3d& box, Predicate&& predicate) const;

  // Exact nearest point of the surface (branch and bound on box distances).
  ClosestPoint closest_point(const Eigen::Vector3d& x) const;

  // Side of the oriented surface (normals by the right-hand rule on the triangles' corner order): the
  // sign of (x - p) . n, p the closest point and n the angle-weighted pseudo-normal of its feature
  // (Baerentzen & Aanaes 2005): the face normal; for an edge the sum of the unit normals of its
  // triangles (on the rim, the one triangle's normal); for a vertex the angle-weighted sum of the unit
  // normals of its triangles. +1 when x is closer to S than 1e-12 times the diagonal of its bounding box
  // or when (x - p) . n is exactly 0. Beyond the rim of an open surface the side is only what this
  // formula gives: points in the tangent direction get an arbitrary sign.
  int side(const Eigen::Vector3d& x) const;

  // Whether some triangle meets the closed tetrahedron: triangle_intersects_tetrahedron on the
  // triangles whose bounding box meets the tetrahedron's.
  bool intersects_tetrahedron(const Tetrahedron3& tet) const;

 private:
  // Internal node: children at index + 1 and `right`; leaf: count > 0 triangles from `first` in order_.
  struct Node {
    Eigen::AlignedBox3d box;
    int first_or_right = 0;
    int count = 0;
  };

  int build(int begin, int end, const std::vector<Eigen::Vector3d>& centroids,
            const std::vector<Eigen::AlignedBox3d>& boxes);

  std::vector<Node> nodes_;
  std::vector<int> order_;                       // triangle numbers in leaf order
  std::vector<Eigen::AlignedBox3d> leaf_boxes_;  // box of order_[i]
  std::vector<Triangle3> corners_;
  std::vector<std::array<int, 3>> vertices_;     // the surface's triangles (for vertex pseudo-normals)
  std::vector<Eigen::Vector3d> face_normals_;    // unit
  std::vector<Eigen::Vector3d> edge_normals_;    // 3 per triangle
  std::vector<Eigen::Vector3d> vertex_normals_;  // per surface point
  double tie_squared_distance_ = 0.0;
};

template <class Predicate>
bool TriangleBVH::any_triangle_overlapping(const Eigen::AlignedBox3d& box, Predicate&& predicate) const {
  // A median split keeps the depth below log2(n) + 1, so 64 entries cannot overflow.
  std::array<int, 64> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const int index = stack[--top];
    const Node& node = nodes_[index];
    if (!node.box.intersects(box)) continue;
    if (node.count > 0) {
      for (int i = node.first_or_right; i < node.first_or_right + node.count; ++i) {
        if (leaf_boxes_[i].intersects(box) && predicate(order_[i])) return true;
      }
    } else {
      stack[top++] = node.first_or_right;
      stack[top++] = index + 1;
    }
  }
  return false;
}

}  // namespace meccano
