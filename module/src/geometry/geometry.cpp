#include <meccano/geometry/geometry.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace meccano {

namespace {

// The point of the simplex's hull nearest the origin; keeps in `simplex` only the corners that carry it.
// Every face (subset of corners) is tried: its affine hull's nearest point counts when it lies inside the
// face (all barycentric weights positive), and the nearest of those is the answer.
Eigen::Vector3d nearest_point_of_simplex(std::vector<Eigen::Vector3d>& simplex) {
  const auto corners = static_cast<int>(simplex.size());
  Eigen::Vector3d best = simplex.front();
  int best_face = 1;
  for (int face = 1; face < (1 << corners); ++face) {
    std::array<int, 4> in{};
    int count = 0;
    for (int i = 0; i < corners; ++i)
      if (face & (1 << i)) in[count++] = i;
    const Eigen::Vector3d& origin = simplex[in[0]];
    const int k = count - 1;
    if (k > 0) {
      using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
      Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3> edges(3, k);
      for (int j = 0; j < k; ++j) edges.col(j) = simplex[in[j + 1]] - origin;
      const Small gram = edges.transpose() * edges;
      const Eigen::LDLT<Small> solver(gram);
      if (solver.info() != Eigen::Success || !(solver.vectorD().cwiseAbs().minCoeff() > 1e-14 * gram.trace())) continue;
      const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> weights = solver.solve(-edges.transpose() * origin);
      if ((weights.array() <= 0.0).any() || weights.sum() >= 1.0) continue;
      const Eigen::Vector3d point = origin + edges * weights;
      if (point.squaredNorm() < best.squaredNorm()) best = point, best_face = face;
    } else if (origin.squaredNorm() < best.squaredNorm()) {
      best = origin, best_face = face;
    }
  }
  std::vector<Eigen::Vector3d> carriers;
  for (int i = 0; i < corners; ++i)
    if (best_face & (1 << i)) carriers.push_back(simplex[i]);
  simplex = std::move(carriers);
  return best;
}

using Eigen::Vector3d;

// Gaps and distances below this fraction of the configuration size count as contact. Rounding errors
// of the projections are about 1e-15 of it, so the predicates never miss a true contact.
constexpr double relative_tolerance = 1e-12;
constexpr int leaf_size = 4;

struct Interval {
  double lo;
  double hi;
};

template <std::size_t N>
Interval project(const std::array<Vector3d, N>& points, const Vector3d& axis) {
  Interval result{points[0].dot(axis), points[0].dot(axis)};
  for (std::size_t i = 1; i < N; ++i) {
    const double value = points[i].dot(axis);
    result.lo = std::min(result.lo, value);
    result.hi = std::max(result.hi, value);
  }
  return result;
}

double gap_between(Interval a, Interval b) { return std::max(b.lo - a.hi, a.lo - b.hi); }

// Whether the intervals (projections onto `axis`, not normalised) are apart by more than the length
// `tolerance`. Any axis that separates proves disjointness, so a tiny or imprecise axis is harmless.
bool separated_beyond(Interval a, Interval b, const Vector3d& axis, double tolerance) {
  const double gap = gap_between(a, b);
  if (!(gap > 0.0)) return false;
  const double length2 = axis.squaredNorm();
  return length2 > std::numeric_limits<double>::min() && gap > tolerance * std::sqrt(length2);
}

double max_abs_coordinate(std::span<const Vector3d> points) {
  double result = 0.0;
  for (const Vector3d& p : points) result = std::max(result, p.cwiseAbs().maxCoeff());
  return result;
}

// Moves the points to a local origin (points[0]) and scales them to a unit size; returns that size
// (0 if all points coincide). In this frame the relative tolerance is an absolute one.
double to_unit_frame(std::span<Vector3d> points) {
  const Vector3d origin = points[0];
  for (Vector3d& p : points) p -= origin;
  const double size = max_abs_coordinate(points);
  if (size > 0.0) {
    for (Vector3d& p : points) p /= size;
  }
  return size;
}

// Largest gap between the projections of p and q onto the unit directions of the axes. Zero or
// denormal axes are skipped: they carry no direction.
template <std::size_t N, std::size_t M, std::size_t K>
double max_unit_gap(const std::array<Vector3d, N>& p, const std::array<Vector3d, M>& q,
                    const std::array<Vector3d, K>& axes) {
  double result = -std::numeric_limits<double>::infinity();
  for (const Vector3d& axis : axes) {
    const double length2 = axis.squaredNorm();
    if (!(length2 > std::numeric_limits<double>::min())) continue;
    result = std::max(result, gap_between(project(p, axis), project(q, axis)) / std::sqrt(length2));
  }
  return result;
}

// Separation of two triangles in the unit frame. The axes are complete: the face normals and edge
// cross products are the face normals of the Minkowski difference when the triangles are not coplanar,
// the in-plane edge normals cover the coplanar case.
double unit_triangle_separation(const Triangle3& a, const Triangle3& b) {
  const std::array<Vector3d, 3> ea{a[1] - a[0], a[2] - a[1], a[0] - a[2]};
  const std::array<Vector3d, 3> eb{b[1] - b[0], b[2] - b[1], b[0] - b[2]};
  const Vector3d na = ea[0].cross(ea[1]);
  const Vector3d nb = eb[0].cross(eb[1]);
  std::array<Vector3d, 17> axes;
  axes[0] = na;
  axes[1] = nb;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) axes[2 + 3 * i + j] = ea[i].cross(eb[j]);
    axes[11 + i] = na.cross(ea[i]);
    axes[14 + i] = nb.cross(eb[i]);
  }
  return max_unit_gap(a, b, axes);
}

// Separation of a segment and a triangle in the unit frame (complete axes as above).
double unit_segment_triangle_separation(const std::array<Vector3d, 2>& s, const Triangle3& t) {
  const Vector3d d = s[1] - s[0];
  const std::array<Vector3d, 3> e{t[1] - t[0], t[2] - t[1], t[0] - t[2]};
  const Vector3d n = e[0].cross(e[1]);
  std::array<Vector3d, 8> axes;
  axes[0] = n;
  axes[1] = n.cross(d);
  for (int j = 0; j < 3; ++j) {
    axes[2 + j] = d.cross(e[j]);
    axes[5 + j] = n.cross(e[j]);
  }
  return max_unit_gap(s, t, axes);
}

// Triangles sharing corner 0 meet elsewhere iff an edge opposite the shared corner meets the other
// triangle: the intersection is convex and contains the shared corner, and each of its extreme points
// other than that corner lies on an opposite edge.
bool meet_beyond_shared_vertex(const Triangle3& a, const Triangle3& b) {
  std::array<Vector3d, 6> points{a[0], a[1], a[2], b[0], b[1], b[2]};
  to_unit_frame(points);
  const Triangle3 ua{points[0], points[1], points[2]};
  const Triangle3 ub{points[3], points[4], points[5]};
  return unit_segment_triangle_separation({ua[1], ua[2]}, ub) <= relative_tolerance ||
         unit_segment_triangle_separation({ub[1], ub[2]}, ua) <= relative_tolerance;
}

// Triangles sharing the edge (corner 0, corner 1) meet beyond it iff they are coplanar and their third
// corners lie on the same side of the edge: the angle between the two half-planes is zero.
bool fold_onto_shared_edge(const Triangle3& a, const Triangle3& b) {
  const Vector3d edge = (a[1] - a[0]).normalized();
  Vector3d ua = a[2] - a[0];
  Vector3d ub = b[2] - a[0];
  ua -= ua.dot(edge) * edge;
  ub -= ub.dot(edge) * edge;
  const double cosine_part = ua.dot(ub);
  return cosine_part > 0.0 && ua.cross(ub).norm() <= relative_tolerance * cosine_part;
}

double squared_segment_distance(const Vector3d& p0, const Vector3d& p1, const Vector3d& q0, const Vector3d& q1) {
  // The minimum is at an endpoint of one segment, or at the interior critical point of both.
  double best = std::min({squared_distance_to_segment(p0, q0, q1), squared_distance_to_segment(p1, q0, q1),
                          squared_distance_to_segment(q0, p0, p1), squared_distance_to_segment(q1, p0, p1)});
  const Vector3d d1 = p1 - p0;
  const Vector3d d2 = q1 - q0;
  const Vector3d r = p0 - q0;
  const double a = d1.squaredNorm();
  const double b = d1.dot(d2);
  const double e = d2.squaredNorm();
  const double denominator = a * e - b * b;
  if (denominator > 1e-14 * a * e) {
    const double s = (b * d2.dot(r) - e * d1.dot(r)) / denominator;
    const double t = (a * d2.dot(r) - b * d1.dot(r)) / denominator;
    if (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) {
      best = std::min(best, (r + s * d1 - t * d2).squaredNorm());
    }
  }
  return best;
}

// The triangle test of a tetrahedron, with everything that depends only on the tetrahedron prepared
// once (the BVH tests one tetrahedron against many triangles).
class TetrahedronTest {
 public:
  explicit TetrahedronTest(const Tetrahedron3& tet) : origin_(tet[0]) {
    for (int i = 0; i < 4; ++i) vertices_[i] = tet[i] - origin_;
    const std::array<std::array<int, 2>, 6> edge_ends{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
    for (int i = 0; i < 6; ++i) edges_[i] = vertices_[edge_ends[i][1]] - vertices_[edge_ends[i][0]];
    normals_ = {edges_[0].cross(edges_[1]), edges_[0].cross(edges_[2]), edges_[1].cross(edges_[2]),
                edges_[3].cross(edges_[4])};
    for (int i = 0; i < 4; ++i) normal_extents_[i] = project(vertices_, normals_[i]);
    for (int k = 0; k < 3; ++k) box_extents_[k] = project(vertices_, Vector3d::Unit(k));
    size_ = max_abs_coordinate(vertices_);
  }

  bool meets(const Triangle3& triangle) const {
    const Triangle3 t{triangle[0] - origin_, triangle[1] - origin_, triangle[2] - origin_};
    const double tolerance = relative_tolerance * std::max(size_, max_abs_coordinate(t));
    for (int k = 0; k < 3; ++k) {
      const Interval extent{std::min({t[0][k], t[1][k], t[2][k]}), std::max({t[0][k], t[1][k], t[2][k]})};
      if (gap_between(extent, box_extents_[k]) > tolerance) return false;
    }
    const std::array<Vector3d, 3> e{t[1] - t[0], t[2] - t[1], t[0] - t[2]};
    const Vector3d normal = e[0].cross(e[1]);
    if (separated_beyond(project(t, normal), project(vertices_, normal), normal, tolerance)) return false;
    for (int i = 0; i < 4; ++i) {
      if (separated_beyond(project(t, normals_[i]), normal_extents_[i], normals_[i], tolerance)) return false;
    }
    for (const Vector3d& triangle_edge : e) {
      for (const Vector3d& tet_edge : edges_) {
        const Vector3d axis = triangle_edge.cross(tet_edge);
        if (separated_beyond(project(t, axis), project(vertices_, axis), axis, tolerance)) return false;
      }
    }
    return true;
  }

 private:
  Vector3d origin_;
  std::array<Vector3d, 4> vertices_;  // relative to origin_
  std::array<Vector3d, 6> edges_;
  std::array<Vector3d, 4> normals_;
  std::array<Interval, 4> normal_extents_;
  std::array<Interval, 3> box_extents_;
  double size_ = 0.0;
};

double corner_angle(const Vector3d& u, const Vector3d& v) { return std::atan2(u.cross(v).norm(), u.dot(v)); }

}  // namespace

double squared_distance_to_segment(const Vector3d& x, const Vector3d& p0, const Vector3d& p1, double* parameter) {
  const Vector3d d = p1 - p0;
  const double length2 = d.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((x - p0).dot(d) / length2, 0.0, 1.0) : 0.0;
  if (parameter) *parameter = t;
  return (p0 + t * d - x).squaredNorm();
}


Eigen::AlignedBox3d bounding_box(std::span<const Eigen::Vector3d> points) {
  Eigen::AlignedBox3d box;
  for (const Vector3d& p : points) box.extend(p);
  return box;
}

double tetrahedron_longest_edge(const Tetrahedron3& tet) {
  double longest2 = 0.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) longest2 = std::max(longest2, (tet[i] - tet[j]).squaredNorm());
  }
  return std::sqrt(longest2);
}

std::optional<Eigen::Vector3d> rigid_displacement(std::span<const Eigen::Vector3d> from,
                                                  std::span<const Eigen::Vector3d> to, const Eigen::Vector3d& x) {
  if (from.size() < 3) return std::nullopt;
  Eigen::Vector3d from_centre = Eigen::Vector3d::Zero(), to_centre = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    from_centre += from[i];
    to_centre += to[i];
  }
  from_centre /= static_cast<double>(from.size());
  to_centre /= static_cast<double>(to.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero(), spread = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    covariance += (from[i] - from_centre) * (to[i] - to_centre).transpose();
    spread += (from[i] - from_centre) * (from[i] - from_centre).transpose();
  }
  const Eigen::Vector3d extent = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread).eigenvalues();  // ascending
  if (!(extent[1] > 1e-6 * extent[2])) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  sign(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d rotation = svd.matrixV() * sign * svd.matrixU().transpose();
  return rotation * (x - from_centre) + to_centre - x;
}

Eigen::Vector3d hull_point_nearest_origin(std::span<const Eigen::Vector3d> points) {
  // GJK's distance algorithm: the nearest point of a simplex of at most four of the points, which then
  // takes in the point furthest back along it, until none is.
  std::vector<Eigen::Vector3d> simplex{points.front()};
  Eigen::Vector3d x = points.front();
  for (std::size_t step = 0; step <= points.size() + 8; ++step) {
    const Eigen::Vector3d* support = &points.front();
    for (const Eigen::Vector3d& p : points)
      if (p.dot(x) < support->dot(x)) support = &p;
    if (x.squaredNorm() - support->dot(x) <= 1e-12 * x.squaredNorm() ||
        std::find(simplex.begin(), simplex.end(), *support) != simplex.end())
      break;
    simplex.push_back(*support);
    x = nearest_point_of_simplex(simplex);
    if (simplex.size() == 4 || x.squaredNorm() <= 1e-28 * support->squaredNorm())
      return Eigen::Vector3d::Zero();  // the origin is inside a tetrahedron of them (or on its face)
  }
  return x;
}

bool triangle_intersects_tetrahedron(const Triangle3& tri, const Tetrahedron3& tet) {
  return TetrahedronTest(tet).meets(tri);
}

bool triangles_intersect(const Triangle3& a, const Triangle3& b, int shared_corners) {
  switch (shared_corners) {
    case 0: {
      std::array<Vector3d, 6> points{a[0], a[1], a[2], b[0], b[1], b[2]};
      to_unit_frame(points);
      return unit_triangle_separation({points[0], points[1], points[2]}, {points[3], points[4], points[5]}) <=
             relative_tolerance;
    }
    case 1: return meet_beyond_shared_vertex(a, b);
    case 2: return fold_onto_shared_edge(a, b);
    default: throw std::invalid_argument("triangles_intersect: shared_corners must be 0, 1 or 2");
  }
}

double triangle_separation(const Triangle3& a, const Triangle3& b) {
  std::array<Vector3d, 6> points{a[0], a[1], a[2], b[0], b[1], b[2]};
  const double size = to_unit_frame(points);
  if (size == 0.0) return 0.0;
  return size * unit_triangle_separation({points[0], points[1], points[2]}, {points[3], points[4], points[5]});
}

double triangle_distance(const Triangle3& a, const Triangle3& b) {
  if (triangle_separation(a, b) <= 0.0) return 0.0;
  // Disjoint triangles: the closest pair is a corner and a triangle, or two edges.
  double best2 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    best2 = std::min({best2, closest_point_on_triangle(a[i], b).squared_distance,
                      closest_point_on_triangle(b[i], a).squared_distance});
    for (int j = 0; j < 3; ++j) {
      best2 = std::min(best2, squared_segment_distance(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]));
    }
  }
  return std::sqrt(best2);
}

ClosestPoint closest_point_on_triangle(const Eigen::Vector3d& x, const Triangle3& tri) {
  ClosestPoint result;
  const Vector3d normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
  const double normal2 = normal.squaredNorm();
  bool inside = normal2 > 0.0;
  for (int k = 0; k < 3 && inside; ++k) {
    inside = (tri[(k + 1) % 3] - tri[k]).cross(x - tri[k]).dot(normal) >= 0.0;
  }
  if (inside) {
    result.point = x - ((x - tri[0]).dot(normal) / normal2) * normal;
    result.squared_distance = (x - result.point).squaredNorm();
    return result;
  }
  // The projection is outside the triangle (or the triangle is degenerate): the nearest point is on
  // its boundary.
  result.squared_distance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    double t = 0.0;
    const double distance2 = squared_distance_to_segment(x, tri[k], tri[(k + 1) % 3], &t);
    if (distance2 < result.squared_distance) {
      result.squared_distance = distance2;
      result.point = tri[k] + t * (tri[(k + 1) % 3] - tri[k]);
      result.feature = t == 0.0 || t == 1.0 ? Feature::vertex : Feature::edge;
      result.feature_index = t == 1.0 ? (k + 1) % 3 : k;
    }
  }
  return result;
}

TriangleBVH::TriangleBVH(const TriangleSurface& surface) : vertices_(surface.triangles) {
  const int n = static_cast<int>(surface.triangles.size());
  if (n == 0) throw std::invalid_argument("TriangleBVH: the surface has no triangles");
  corners_.reserve(n);
  std::vector<Eigen::Vector3d> centroids;
  std::vector<Eigen::AlignedBox3d> boxes;
  centroids.reserve(n);
  boxes.reserve(n);
  for (const auto& triangle : surface.triangles) {
    const Triangle3& c = corners_.emplace_back(
        Triangle3{surface.points[triangle[0]], surface.points[triangle[1]], surface.points[triangle[2]]});
    centroids.push_back((c[0] + c[1] + c[2]) / 3.0);
    boxes.push_back(bounding_box(c));
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(std::size_t{2} * (n / leaf_size + 1));
  build(0, n, centroids, boxes);
  leaf_boxes_.reserve(n);
  for (int t : order_) leaf_boxes_.push_back(boxes[t]);

  // Pseudo-normals for side().
  face_normals_.reserve(n);
  vertex_normals_.assign(surface.points.size(), Vector3d::Zero());
  std::vector<std::tuple<int, int, int>> half_edges;  // (smaller vertex, larger vertex, 3 t + k)
  half_edges.reserve(std::size_t{3} * n);
  for (int t = 0; t < n; ++t) {
    const Triangle3& c = corners_[t];
    const Vector3d normal = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
    face_normals_.push_back(normal);
    for (int k = 0; k < 3; ++k) {
      const int next = (k + 1) % 3;
      const int previous = (k + 2) % 3;
      vertex_normals_[vertices_[t][k]] += corner_angle(c[next] - c[k], c[previous] - c[k]) * normal;
      half_edges.emplace_back(std::min(vertices_[t][k], vertices_[t][next]),
                              std::max(vertices_[t][k], vertices_[t][next]), 3 * t + k);
    }
  }
  std::sort(half_edges.begin(), half_edges.end());
  edge_normals_.assign(std::size_t{3} * n, Vector3d::Zero());
  for (std::size_t begin = 0; begin < half_edges.size();) {
    std::size_t end = begin;
    Vector3d sum = Vector3d::Zero();
    for (; end < half_edges.size() && std::get<0>(half_edges[end]) == std::get<0>(half_edges[begin]) &&
           std::get<1>(half_edges[end]) == std::get<1>(half_edges[begin]);
         ++end) {
      sum += face_normals_[std::get<2>(half_edges[end]) / 3];
    }
    for (std::size_t i = begin; i < end; ++i) edge_normals_[std::get<2>(half_edges[i])] = sum;
    begin = end;
  }
  const double tie_distance = relative_tolerance * bounds().diagonal().norm();
  tie_squared_distance_ = tie_distance * tie_distance;
}

int TriangleBVH::build(int begin, int end, const std::vector<Eigen::Vector3d>& centroids,
                       const std::vector<Eigen::AlignedBox3d>& boxes) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::AlignedBox3d box;
  Eigen::AlignedBox3d centroid_box;
  for (int i = begin; i < end; ++i) {
    box.extend(boxes[order_[i]]);
    centroid_box.extend(centroids[order_[i]]);
  }
  nodes_[index].box = box;
  if (end - begin <= leaf_size) {
    nodes_[index].first_or_right = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  Eigen::Index axis = 0;
  centroid_box.sizes().maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int s, int t) { return centroids[s][axis] < centroids[t][axis]; });
  build(begin, middle, centroids, boxes);
  nodes_[index].first_or_right = build(middle, end, centroids, boxes);
  return index;
}

double surface_distance(const TriangleSurface& a, const TriangleBVH& b) {
  // An upper bound from the vertices first, so that each triangle looks only at b's triangles within it.
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& p : a.points) best = std::min(best, b.closest_point(p).squared_distance);
  best = std::sqrt(best);
  for (const auto& [i, j, k] : a.triangles) {
    const Triangle3 triangle{a.points[i], a.points[j], a.points[k]};
    Eigen::AlignedBox3d box(triangle[0]);
    box.extend(triangle[1]).extend(triangle[2]);
    box.min().array() -= best;
    box.max().array() += best;
    b.for_each_triangle_overlapping(box,
                                    [&](int t) { best = std::min(best, triangle_distance(triangle, b.triangle(t))); });
  }
  return best;
}

ClosestPoint TriangleBVH::closest_point(const Eigen::Vector3d& x) const {
  ClosestPoint best;
  best.squared_distance = std::numeric_limits<double>::infinity();
  struct Entry {
    int node;
    double squared_distance;
  };
  std::array<Entry, 64> stack;
  int top = 0;
  stack[top++] = {0, nodes_[0].box.squaredExteriorDistance(x)};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (entry.squared_distance >= best.squared_distance) continue;
    const Node& node = nodes_[entry.node];
    if (node.count > 0) {
      for (int i = node.first_or_right; i < node.first_or_right + node.count; ++i) {
        const ClosestPoint candidate = closest_point_on_triangle(x, corners_[order_[i]]);
        if (candidate.squared_distance < best.squared_distance) {
          best = candidate;
          best.triangle = order_[i];
        }
      }
      continue;
    }
    Entry near{entry.node + 1, nodes_[entry.node + 1].box.squaredExteriorDistance(x)};
    Entry far{node.first_or_right, nodes_[node.first_or_right].box.squaredExteriorDistance(x)};
    if (far.squared_distance < near.squared_distance) std::swap(near, far);
    if (far.squared_distance < best.squared_distance) stack[top++] = far;
    if (near.squared_distance < best.squared_distance) stack[top++] = near;
  }
  return best;
}

int TriangleBVH::side(const Eigen::Vector3d& x) const {
  const ClosestPoint closest = closest_point(x);
  if (closest.squared_distance <= tie_squared_distance_) return 1;
  const int t = closest.triangle;
  const Vector3d& normal = closest.feature == Feature::face   ? face_normals_[t]
                           : closest.feature == Feature::edge ? edge_normals_[3 * t + closest.feature_index]
                                                              : vertex_normals_[vertices_[t][closest.feature_index]];
  return (x - closest.point).dot(normal) < 0.0 ? -1 : 1;
}

bool TriangleBVH::intersects_tetrahedron(const Tetrahedron3& tet) const {
  const TetrahedronTest test(tet);
  return any_triangle_overlapping(bounding_box(tet), [&](int t) { return test.meets(corners_[t]); });
}

}  // namespace meccano
