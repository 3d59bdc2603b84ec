// Geometric predicates and the BVH, checked against brute force on real surfaces.
#include <meccano/geometry/geometry.hpp>

#include "test_surfaces.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <utility>
#include <vector>

namespace meccano {
namespace {

using Eigen::Vector3d;
using LongVector = Eigen::Matrix<long double, 3, 1>;

// ---------------------------------------------------------------------------------------------------
// Brute-force reference for triangle-tetrahedron intersection, in long double. The closed triangle
// meets the closed tetrahedron iff an edge of one meets the other: a triangle edge clipped by the four
// face half-spaces, or a tetrahedron edge crossing the triangle (tetrahedron vertices in the triangle
// when coplanar). Dense samples of the triangle tested inside the tetrahedron are a second opinion.

LongVector to_long(const Vector3d& v) { return v.cast<long double>(); }

long double orientation(const LongVector& a, const LongVector& b, const LongVector& c, const LongVector& d) {
  return (b - a).cross(c - a).dot(d - a);
}

struct ReferenceTetrahedron {
  std::array<LongVector, 4> v;
  // Inside iff inside(i, x) >= 0 for every face i (face i is opposite vertex i).
  long double inside(int i, const LongVector& x) const {
    const LongVector& a = v[(i + 1) % 4];
    const LongVector& b = v[(i + 2) % 4];
    const LongVector& c = v[(i + 3) % 4];
    return orientation(a, b, c, x) * (orientation(a, b, c, v[i]) > 0 ? 1.0L : -1.0L);
  }
  bool contains(const LongVector& x) const {
    for (int i = 0; i < 4; ++i) {
      if (inside(i, x) < 0) return false;
    }
    return true;
  }
  bool meets_segment(const LongVector& p, const LongVector& q) const {
    long double lo = 0.0L;
    long double hi = 1.0L;
    for (int i = 0; i < 4; ++i) {
      const long double fp = inside(i, p);
      const long double fq = inside(i, q);
      if (fp < 0 && fq < 0) return false;
      if (fp < 0) lo = std::max(lo, fp / (fp - fq));
      if (fq < 0) hi = std::min(hi, fp / (fp - fq));
    }
    return lo <= hi;
  }
};

bool point_in_coplanar_triangle(const std::array<LongVector, 3>& t, const LongVector& normal, const LongVector& x) {
  for (int k = 0; k < 3; ++k) {
    if ((t[(k + 1) % 3] - t[k]).cross(x - t[k]).dot(normal) < 0) return false;
  }
  return true;
}

bool segment_meets_triangle(const std::array<LongVector, 3>& t, const LongVector& p, const LongVector& q) {
  const long double sp = orientation(t[0], t[1], t[2], p);
  const long double sq = orientation(t[0], t[1], t[2], q);
  const LongVector normal = (t[1] - t[0]).cross(t[2] - t[0]);
  if (sp == 0 && sq == 0) {
    return point_in_coplanar_triangle(t, normal, p) || point_in_coplanar_triangle(t, normal, q);
  }
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0)) return false;
  const LongVector crossing = p + (sp / (sp - sq)) * (q - p);
  return point_in_coplanar_triangle(t, normal, crossing);
}

bool reference_intersects(const Triangle3& tri, const Tetrahedron3& tet) {
  ReferenceTetrahedron reference{{to_long(tet[0]), to_long(tet[1]), to_long(tet[2]), to_long(tet[3])}};
  const std::array<LongVector, 3> t{to_long(tri[0]), to_long(tri[1]), to_long(tri[2])};
  for (int k = 0; k < 3; ++k) {
    if (reference.meets_segment(t[k], t[(k + 1) % 3])) return true;
  }
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      if (segment_meets_triangle(t, reference.v[i], reference.v[j])) return true;
    }
  }
  constexpr int samples = 8;
  for (int i = 0; i <= samples; ++i) {
    for (int j = 0; i + j <= samples; ++j) {
      const long double u = static_cast<long double>(i) / samples;
      const long double w = static_cast<long double>(j) / samples;
      if (reference.contains(t[0] + u * (t[1] - t[0]) + w * (t[2] - t[0]))) return true;
    }
  }
  return false;
}

double uniform(std::mt19937_64& generator, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(generator);
}

Vector3d random_point(std::mt19937_64& generator, double lo, double hi) {
  return {uniform(generator, lo, hi), uniform(generator, lo, hi), uniform(generator, lo, hi)};
}

Tetrahedron3 random_tetrahedron(std::mt19937_64& generator) {
  for (;;) {
    const Tetrahedron3 tet{random_point(generator, 0, 1), random_point(generator, 0, 1), random_point(generator, 0, 1),
                           random_point(generator, 0, 1)};
    const double volume = std::abs((tet[1] - tet[0]).cross(tet[2] - tet[0]).dot(tet[3] - tet[0]));
    if (volume > 1e-3) return tet;
  }
}

// Configuration families; each returns a triangle placed relative to the tetrahedron.
enum class Family { random, parallel_to_face, through_vertex, along_edge, coplanar_with_face, count };
const char* family_name(Family family) {
  switch (family) {
    case Family::random: return "random";
    case Family::parallel_to_face: return "parallel to a face";
    case Family::through_vertex: return "corner near a tet vertex";
    case Family::along_edge: return "edge crossing near a tet edge";
    case Family::coplanar_with_face: return "coplanar with a face";
    default: return "";
  }
}

// Offsets from contact used by the near-contact families (in units of the configuration size ~1).
constexpr std::array<double, 9> offsets{-1e-6, -1e-10, -1e-13, -1e-15, 0.0, 1e-15, 1e-13, 1e-10, 1e-6};

Triangle3 make_triangle(Family family, const Tetrahedron3& tet, double offset, std::mt19937_64& generator) {
  const int i = static_cast<int>(generator() % 4);  // a vertex, or the face opposite it
  const Vector3d& a = tet[(i + 1) % 4];
  const Vector3d& b = tet[(i + 2) % 4];
  const Vector3d& c = tet[(i + 3) % 4];
  Vector3d outward = (b - a).cross(c - a).normalized();
  if (outward.dot(tet[i] - a) > 0) outward = -outward;
  const auto on_face_plane = [&](double lo, double hi) {
    const double u = uniform(generator, lo, hi);
    const double v = uniform(generator, lo, hi);
    return Vector3d(a + u * (b - a) + v * (c - a));
  };
  switch (family) {
    case Family::random: {
      const Vector3d centre = (tet[0] + tet[1] + tet[2] + tet[3]) / 4.0 + random_point(generator, -0.4, 0.4);
      const double size = uniform(generator, 0.1, 0.6);
      return {centre + random_point(generator, -size, size), centre + random_point(generator, -size, size),
              centre + random_point(generator, -size, size)};
    }
    case Family::parallel_to_face: {
      const Vector3d shift = offset * outward;
      return {on_face_plane(-0.5, 1.0) + shift, on_face_plane(-0.5, 1.0) + shift, on_face_plane(-0.5, 1.0) + shift};
    }
    case Family::through_vertex: {
      // A corner at the vertex (moved slightly), the others on the far side of a plane through it.
      const Vector3d& vertex = tet[i];
      const Vector3d away = (vertex - (a + b + c) / 3.0).normalized();
      const Vector3d corner = vertex + offset * random_point(generator, -1, 1).normalized();
      return {corner, vertex + 0.5 * away + random_point(generator, -0.3, 0.3),
              vertex + 0.5 * away + random_point(generator, -0.3, 0.3)};
    }
    case Family::along_edge: {
      // A triangle edge through a point near the tet edge (a, b), crossing it at a random angle.
      const Vector3d point = a + uniform(generator, -0.1, 1.1) * (b - a) + offset * outward;
      const Vector3d direction = random_point(generator, -1, 1).normalized();
      return {point - 0.4 * direction, point + 0.4 * direction, point + random_point(generator, -0.6, 0.6)};
    }
    case Family::coplanar_with_face:
      return {on_face_plane(-0.5, 1.5), on_face_plane(-0.5, 1.5), on_face_plane(-0.5, 1.5)};
    default: return {};
  }
}

// Distance between a triangle and a tetrahedron that do not intersect: the nearest tet point is on a face.
double distance_to_tetrahedron(const Triangle3& tri, const Tetrahedron3& tet) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i)
    best = std::min(best, triangle_distance(tri, {tet[(i + 1) % 4], tet[(i + 2) % 4], tet[(i + 3) % 4]}));
  return best;
}

TEST(Geometry, TriangleTetrahedronNeverMissesAnIntersection) {
  // 120 000 configurations against the long double reference: no false negative in any vertex order;
  // false positives are counted with the distance at which they happen.
  std::mt19937_64 generator(20240611);
  constexpr int per_family = 24000;
  int total = 0;
  int total_disjoint = 0;
  int total_false_positives = 0;
  double farthest_false_positive = 0.0;
  int random_false_positives = 0;
  for (int f = 0; f < static_cast<int>(Family::count); ++f) {
    const auto family = static_cast<Family>(f);
    const bool uses_offset = family != Family::random && family != Family::coplanar_with_face;
    std::array<int, offsets.size()> disjoint{};
    std::array<int, offsets.size()> false_positives{};
    int intersecting = 0;
    for (int k = 0; k < per_family; ++k) {
      const Tetrahedron3 tet = random_tetrahedron(generator);
      const std::size_t o = uses_offset ? generator() % offsets.size() : 4;
      const Triangle3 tri = make_triangle(family, tet, offsets[o], generator);
      const bool expected = reference_intersects(tri, tet);
      const bool actual = triangle_intersects_tetrahedron(tri, tet);
      // Vertex order and orientation of either shape do not matter for a true intersection.
      const bool reordered =
          triangle_intersects_tetrahedron({tri[1], tri[2], tri[0]}, {tet[2], tet[0], tet[3], tet[1]});
      if (expected && !(actual && reordered)) {
        ADD_FAILURE() << "missed intersection, family " << family_name(family) << ", configuration " << k;
      }
      intersecting += expected;
      disjoint[o] += !expected;
      if (!expected && actual) {
        ++false_positives[o];
        random_false_positives += family == Family::random;
        farthest_false_positive = std::max(farthest_false_positive, distance_to_tetrahedron(tri, tet));
      }
    }
    std::printf("[ info ] %-30s %d intersecting of %d\n", family_name(family), intersecting, per_family);
    for (std::size_t i = 0; i < offsets.size(); ++i) {
      if (disjoint[i] == 0) continue;
      std::printf("[ info ]     offset %8.0e: false positives %5d of %5d disjoint\n", uses_offset ? offsets[i] : 0.0,
                  false_positives[i], disjoint[i]);
      total_disjoint += disjoint[i];
      total_false_positives += false_positives[i];
    }
    total += per_family;
  }
  std::printf("[ info ] all: %d configurations, false-positive rate %.2e of disjoint ones, largest distance %.1e\n",
              total, double(total_false_positives) / std::max(total_disjoint, 1), farthest_false_positive);
  EXPECT_GE(total, 100000);
  // The answer "intersects" for disjoint shapes only happens within the tolerance (1e-12 of the size).
  EXPECT_LT(farthest_false_positive, 2e-12);
  // Random configurations are never that close.
  EXPECT_EQ(random_false_positives, 0);
}

TEST(Geometry, TriangleTetrahedronExactContacts) {
  const Tetrahedron3 tet{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(0, 0, 1)};
  // Corner of the triangle at a tet vertex, rest outside.
  EXPECT_TRUE(triangle_intersects_tetrahedron({Vector3d(1, 0, 0), Vector3d(2, 1, 0), Vector3d(2, 0, 1)}, tet));
  // The plane x = 1 touches the tet at its vertex (1, 0, 0), inside the triangle.
  EXPECT_TRUE(triangle_intersects_tetrahedron({Vector3d(1, -1, -1), Vector3d(1, 2, -1), Vector3d(1, -1, 2)}, tet));
  EXPECT_FALSE(triangle_intersects_tetrahedron(
      {Vector3d(1 + 1e-6, -1, -1), Vector3d(1 + 1e-6, 2, -1), Vector3d(1 + 1e-6, -1, 2)}, tet));
  // Edge lying on the face z = 0, rest below.
  EXPECT_TRUE(
      triangle_intersects_tetrahedron({Vector3d(0.25, 0.25, 0), Vector3d(0.5, 0.25, 0), Vector3d(0.25, 0.5, -1)}, tet));
  // Edge crossing the tet edge (1,0,0)-(0,1,0) at (0.5, 0.5, 0), triangle otherwise outside.
  EXPECT_TRUE(triangle_intersects_tetrahedron(
      {Vector3d(0.75, 0.75, 0.5), Vector3d(0.25, 0.25, -0.5), Vector3d(1.5, 1.5, 0)}, tet));
  // Moved by 1e-6 along the separating direction (1, 1, -1) (the cross product of the two edges).
  const Vector3d shift = 1e-6 * Vector3d(1, 1, -1);
  EXPECT_FALSE(triangle_intersects_tetrahedron(
      {Vector3d(0.75, 0.75, 0.5) + shift, Vector3d(0.25, 0.25, -0.5) + shift, Vector3d(1.5, 1.5, 0) + shift}, tet));
  // Coplanar with the face z = 0 and overlapping it; a triangle inside the tet; one containing it.
  EXPECT_TRUE(
      triangle_intersects_tetrahedron({Vector3d(0.5, 0.5, 0), Vector3d(-1, 0.2, 0), Vector3d(0.2, -1, 0)}, tet));
  EXPECT_TRUE(triangle_intersects_tetrahedron(
      {Vector3d(0.1, 0.1, 0.1), Vector3d(0.2, 0.1, 0.1), Vector3d(0.1, 0.2, 0.1)}, tet));
  EXPECT_TRUE(
      triangle_intersects_tetrahedron({Vector3d(-5, -5, 0.2), Vector3d(10, -5, 0.2), Vector3d(-5, 10, 0.2)}, tet));
  EXPECT_FALSE(triangle_intersects_tetrahedron({Vector3d(2, 2, 2), Vector3d(3, 2, 2), Vector3d(2, 3, 2)}, tet));
}

TEST(Geometry, LongestEdgeAndBoundingBox) {
  const Tetrahedron3 tet{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(1, 1, 0), Vector3d(1, 1, 1)};
  EXPECT_DOUBLE_EQ(tetrahedron_longest_edge(tet), std::sqrt(3.0));
  const Eigen::AlignedBox3d box = bounding_box(tet);
  EXPECT_EQ(box.min(), Vector3d(0, 0, 0));
  EXPECT_EQ(box.max(), Vector3d(1, 1, 1));
}

// ---------------------------------------------------------------------------------------------------
// Triangle-triangle predicates.

const Triangle3 unit_triangle{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0)};

TEST(Geometry, TrianglesIntersectGeneralPosition) {
  // Crossing: the second triangle passes through the interior of the first.
  const Triangle3 crossing{Vector3d(0.25, 0.25, -1), Vector3d(0.25, 0.25, 1), Vector3d(2, 2, 0)};
  EXPECT_TRUE(triangles_intersect(unit_triangle, crossing));
  EXPECT_LT(triangle_separation(unit_triangle, crossing), 0.0);
  // Touching at one point (a corner on the interior of the other).
  const Triangle3 touching{Vector3d(0.25, 0.25, 0), Vector3d(1, 0, 1), Vector3d(0, 1, 1)};
  EXPECT_TRUE(triangles_intersect(unit_triangle, touching));
  EXPECT_NEAR(triangle_separation(unit_triangle, touching), 0.0, 1e-15);
  EXPECT_FALSE(triangles_intersect(unit_triangle, {Vector3d(0.25, 0.25, 1e-9), Vector3d(1, 0, 1), Vector3d(0, 1, 1)}));
  // Coplanar: overlapping, and disjoint across the hypotenuse x + y = 1.
  EXPECT_TRUE(triangles_intersect(unit_triangle, {Vector3d(0.2, 0.2, 0), Vector3d(1, 1, 0), Vector3d(-0.5, 1, 0)}));
  EXPECT_FALSE(triangles_intersect(unit_triangle, {Vector3d(1, 1, 0), Vector3d(2, 1, 0), Vector3d(1, 2, 0)}));
  // Coplanar, touching along the hypotenuse.
  EXPECT_TRUE(triangles_intersect(unit_triangle, {Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(1, 1, 0)}));
  // Parallel planes.
  EXPECT_FALSE(triangles_intersect(unit_triangle, {Vector3d(0, 0, 1e-6), Vector3d(1, 0, 1e-6), Vector3d(0, 1, 1e-6)}));
}

TEST(Geometry, TrianglesSharingAnEdge) {
  const Triangle3 flat_neighbour{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0.5, -1, 0)};
  EXPECT_FALSE(triangles_intersect(unit_triangle, flat_neighbour, 2));
  EXPECT_FALSE(triangles_intersect(unit_triangle, {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0.5, 0.3, 1)}, 2));
  // A sharp but open crease is not an intersection.
  EXPECT_FALSE(triangles_intersect(unit_triangle, {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0.5, 1, 1e-3)}, 2));
  // Folded back onto itself.
  EXPECT_TRUE(triangles_intersect(unit_triangle, {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0.5, 0.5, 0)}, 2));
  EXPECT_TRUE(triangles_intersect(unit_triangle, {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(3, 2, 1e-14)}, 2));
}

TEST(Geometry, TrianglesSharingAVertex) {
  const Triangle3 a{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(1, 1, 0)};
  // Flat fan, sectors [0, 45] and [135, 180] degrees.
  EXPECT_FALSE(triangles_intersect(a, {Vector3d(0, 0, 0), Vector3d(-1, 1, 0), Vector3d(-1, 0, 0)}, 1));
  // Overlapping sectors [0, 45] and [26, 63] degrees.
  EXPECT_TRUE(triangles_intersect(a, {Vector3d(0, 0, 0), Vector3d(1, 0.5, 0), Vector3d(0.5, 1, 0)}, 1));
  // Only the shared vertex in common, the other triangle above.
  EXPECT_FALSE(triangles_intersect(a, {Vector3d(0, 0, 0), Vector3d(1, 0, 1), Vector3d(0, 1, 1)}, 1));
  // The other triangle's opposite edge pierces this one at (0.8, 0.3, 0).
  EXPECT_TRUE(triangles_intersect(a, {Vector3d(0, 0, 0), Vector3d(0.8, 0.3, -1), Vector3d(0.8, 0.3, 1)}, 1));
  // Sharing the vertex and an edge direction: the edges overlap beyond the vertex.
  EXPECT_TRUE(triangles_intersect(a, {Vector3d(0, 0, 0), Vector3d(0.5, 0, 0), Vector3d(0.5, -1, 1)}, 1));
}

TEST(Geometry, TriangleDistanceMatchesSampling) {
  std::mt19937_64 generator(7);
  constexpr int samples = 60;
  for (int k = 0; k < 200; ++k) {
    const Triangle3 a{random_point(generator, 0, 1), random_point(generator, 0, 1), random_point(generator, 0, 1)};
    const Vector3d shift = random_point(generator, -1, 1);
    const Triangle3 b{random_point(generator, 0, 1) + shift, random_point(generator, 0, 1) + shift,
                      random_point(generator, 0, 1) + shift};
    double sampled = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= samples; ++i) {
      for (int j = 0; i + j <= samples; ++j) {
        const Vector3d x = a[0] + (double(i) / samples) * (a[1] - a[0]) + (double(j) / samples) * (a[2] - a[0]);
        sampled = std::min(sampled, std::sqrt(closest_point_on_triangle(x, b).squared_distance));
      }
    }
    const double distance = triangle_distance(a, b);
    const double separation = triangle_separation(a, b);
    EXPECT_LE(distance, sampled + 1e-12);
    EXPECT_GE(distance, sampled - 0.05);  // sample spacing at most sqrt(3) / 60
    EXPECT_LE(separation, distance + 1e-12);
    EXPECT_EQ(separation > 0.0, distance > 0.0);
    EXPECT_EQ(triangles_intersect(a, b), distance <= 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------------
// BVH.

std::vector<TriangleSurface> query_surfaces() {
  std::vector<TriangleSurface> surfaces;
  for (auto& entry : testing::named_test_surfaces(8)) {
    for (auto& surface : entry.surfaces) surfaces.push_back(std::move(surface));
  }
  return surfaces;
}

Triangle3 corners(const TriangleSurface& surface, int t) {
  const auto& v = surface.triangles[t];
  return {surface.points[v[0]], surface.points[v[1]], surface.points[v[2]]};
}

TEST(Geometry, BvhClosestPointEqualsBruteForce) {
  std::mt19937_64 generator(11);
  for (const TriangleSurface& surface : query_surfaces()) {
    const TriangleBVH bvh(surface);
    for (int k = 0; k < 400; ++k) {
      // Half the queries anywhere around the cube, half close to the surface.
      Vector3d x = random_point(generator, -0.2, 1.2);
      if (k % 2) {
        const Triangle3 t = corners(surface, static_cast<int>(generator() % surface.triangles.size()));
        x = (t[0] + t[1] + t[2]) / 3.0 + random_point(generator, -0.02, 0.02);
      }
      double brute = std::numeric_limits<double>::infinity();
      for (int t = 0; t < static_cast<int>(surface.triangles.size()); ++t) {
        brute = std::min(brute, closest_point_on_triangle(x, corners(surface, t)).squared_distance);
      }
      const ClosestPoint closest = bvh.closest_point(x);
      ASSERT_GE(closest.triangle, 0);
      EXPECT_NEAR(closest.squared_distance, brute, 1e-14 * (1 + brute)) << surface.name;
      EXPECT_NEAR((closest.point - x).squaredNorm(), closest.squared_distance, 1e-14);
      EXPECT_LT((closest_point_on_triangle(x, bvh.triangle(closest.triangle)).point - closest.point).norm(), 1e-15);
    }
  }
}

TEST(Geometry, BvhOverlapQueriesEqualBruteForce) {
  std::mt19937_64 generator(13);
  for (const TriangleSurface& surface : query_surfaces()) {
    const TriangleBVH bvh(surface);
    for (int k = 0; k < 300; ++k) {
      const Vector3d corner = random_point(generator, -0.1, 1.0);
      const Eigen::AlignedBox3d box(corner, corner + random_point(generator, 0.0, k % 3 ? 0.1 : 0.6));
      std::vector<int> found;
      bvh.for_each_triangle_overlapping(box, [&](int t) { found.push_back(t); });
      std::sort(found.begin(), found.end());
      std::vector<int> expected;
      for (int t = 0; t < static_cast<int>(surface.triangles.size()); ++t) {
        const Triangle3 c = corners(surface, t);
        if (bounding_box(c).intersects(box)) expected.push_back(t);
      }
      EXPECT_EQ(found, expected) << surface.name;
      EXPECT_EQ(bvh.any_triangle_overlapping(box, [](int) { return true; }), !expected.empty());
      if (!expected.empty()) {
        const int wanted = expected.back();
        EXPECT_TRUE(bvh.any_triangle_overlapping(box, [&](int t) { return t == wanted; }));
      }
    }
  }
}

TEST(Geometry, BvhTetrahedraAroundAndAwayFromTheSurface) {
  std::mt19937_64 generator(17);
  for (const TriangleSurface& surface : query_surfaces()) {
    const TriangleBVH bvh(surface);
    for (int k = 0; k < 200; ++k) {
      // A random tetrahedron of size h containing a random point of the surface ...
      const Triangle3 t = corners(surface, static_cast<int>(generator() % surface.triangles.size()));
      double u = uniform(generator, 0, 1);
      double v = uniform(generator, 0, 1);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      const Vector3d p = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
      const double h = uniform(generator, 1e-4, 0.1);
      Tetrahedron3 tet;
      std::array<double, 4> weights{};
      double total = 0;
      for (double& w : weights) total += (w = uniform(generator, 0.05, 1.0));
      Vector3d mean = Vector3d::Zero();
      for (int i = 0; i < 4; ++i) {
        tet[i] = h * random_point(generator, -1, 1);
        mean += weights[i] / total * tet[i];
      }
      for (Vector3d& vertex : tet) vertex += p - mean;  // p has barycentric coordinates weights / total
      EXPECT_TRUE(bvh.intersects_tetrahedron(tet)) << surface.name;
      // ... and the same tetrahedron moved to where the surface is farther than its size.
      const Vector3d far = random_point(generator, 0, 1);
      if (std::sqrt(bvh.closest_point(far).squared_distance) > 4 * h) {
        Tetrahedron3 moved = tet;
        for (Vector3d& vertex : moved) vertex += far - p;
        EXPECT_FALSE(bvh.intersects_tetrahedron(moved)) << surface.name;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// side().

// The pseudo-normal of a point of the surface given by its feature, computed independently of the BVH.
struct SurfacePoint {
  Vector3d point;
  Vector3d normal;
};

Vector3d face_normal(const TriangleSurface& s, int t) {
  const Triangle3 c = corners(s, t);
  return (c[1] - c[0]).cross(c[2] - c[0]).normalized();
}

std::vector<SurfacePoint> points_with_normals(const TriangleSurface& s, std::mt19937_64& generator) {
  std::vector<SurfacePoint> result;
  const int n = static_cast<int>(s.triangles.size());
  // Face points.
  for (int t = 0; t < n; t += 3) {
    const Triangle3 c = corners(s, t);
    const double u = uniform(generator, 0.1, 0.45);
    const double v = uniform(generator, 0.1, 0.45);
    result.push_back({c[0] + u * (c[1] - c[0]) + v * (c[2] - c[0]), face_normal(s, t)});
  }
  // Interior edges (two triangles) and interior vertices (angle-weighted normal, closed fan).
  std::map<std::pair<int, int>, std::vector<int>> edge_triangles;
  std::vector<Vector3d> vertex_normal(s.points.size(), Vector3d::Zero());
  for (int t = 0; t < n; ++t) {
    const Triangle3 c = corners(s, t);
    for (int k = 0; k < 3; ++k) {
      const int a = s.triangles[t][k];
      const int b = s.triangles[t][(k + 1) % 3];
      edge_triangles[{std::min(a, b), std::max(a, b)}].push_back(t);
      const Vector3d e1 = c[(k + 1) % 3] - c[k];
      const Vector3d e2 = c[(k + 2) % 3] - c[k];
      vertex_normal[a] += std::atan2(e1.cross(e2).norm(), e1.dot(e2)) * face_normal(s, t);
    }
  }
  std::vector<bool> on_rim(s.points.size(), false);
  for (const auto& [edge, triangles] : edge_triangles) {
    if (triangles.size() == 1) on_rim[edge.first] = on_rim[edge.second] = true;
  }
  for (const auto& [edge, triangles] : edge_triangles) {
    if (triangles.size() != 2) continue;
    const double w = uniform(generator, 0.2, 0.8);
    result.push_back({(1 - w) * s.points[edge.first] + w * s.points[edge.second],
                      (face_normal(s, triangles[0]) + face_normal(s, triangles[1])).normalized()});
  }
  for (std::size_t v = 0; v < s.points.size(); ++v) {
    if (!on_rim[v]) result.push_back({s.points[v], vertex_normal[v].normalized()});
  }
  return result;
}

TEST(Geometry, SideAlongPseudoNormalsAtAllDistances) {
  std::mt19937_64 generator(19);
  for (const TriangleSurface& surface :
       {testing::spherical_cap(8), testing::saddle(8), testing::perturbed(testing::saddle(8), 0.25, 3),
        testing::strongly_curved_sheet(6)}) {
    const TriangleBVH bvh(surface);
    int vertex_features = 0;
    int edge_features = 0;
    for (const SurfacePoint& sp : points_with_normals(surface, generator)) {
      for (double t : {1e-3, 1e-5, 1e-7, 1e-9, 1e-11}) {
        for (int sign : {1, -1}) {
          const Vector3d x = sp.point + sign * t * sp.normal;
          EXPECT_EQ(bvh.side(x), sign) << surface.name << " distance " << t << " at " << sp.point.transpose();
          const ClosestPoint closest = bvh.closest_point(x);
          vertex_features += closest.feature == Feature::vertex;
          edge_features += closest.feature == Feature::edge;
        }
      }
      EXPECT_EQ(bvh.side(sp.point), 1) << "tie value on the surface";
    }
    // The sign was checked where the closest feature is a vertex or an edge, not only faces (saddle
    // vertices have no region of closest points on one side, hence fewer vertex features there).
    EXPECT_GE(vertex_features, 10) << surface.name;
    EXPECT_GE(edge_features, 50) << surface.name;
  }
}

TEST(Geometry, SideOfSphericalCapIsInsideOrOutsideTheSphere) {
  // The cap's vertices are on the sphere of radius 0.4 about (0.5, 0.5, 0.3), normals outwards; points
  // 0.05 off the sphere within polar angle 55 degrees are on a known side of the triangulation.
  const TriangleBVH bvh(testing::spherical_cap(12));
  std::mt19937_64 generator(23);
  for (int k = 0; k < 2000; ++k) {
    const double phi = std::acos(uniform(generator, std::cos(55.0 * std::numbers::pi / 180.0), 1.0));
    const double theta = uniform(generator, 0, 2 * std::numbers::pi);
    const Vector3d direction(std::sin(phi) * std::cos(theta), std::sin(phi) * std::sin(theta), std::cos(phi));
    const double radius = uniform(generator, 0.0, 0.35) + (k % 2 ? 0.45 : 0.0);
    EXPECT_EQ(bvh.side(Vector3d(0.5, 0.5, 0.3) + radius * direction), k % 2 ? 1 : -1);
  }
}

// Height of a triangulated graph z = f(x, y) above (x, y), by barycentric interpolation in the triangle
// whose projection contains (x, y).
double discrete_height(const TriangleSurface& graph, double x, double y) {
  for (int t = 0; t < static_cast<int>(graph.triangles.size()); ++t) {
    const Triangle3 c = corners(graph, t);
    const Eigen::Vector2d a = c[0].head<2>();
    Eigen::Matrix2d edges;
    edges << (c[1] - c[0]).head<2>(), (c[2] - c[0]).head<2>();
    const Eigen::Vector2d w = edges.inverse() * (Eigen::Vector2d(x, y) - a);
    if (w.minCoeff() >= -1e-12 && w.sum() <= 1 + 1e-12) {
      return c[0].z() + w[0] * (c[1].z() - c[0].z()) + w[1] * (c[2].z() - c[0].z());
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

TEST(Geometry, SideNearSharpRidgesAndApexes) {
  // Graphs oriented towards +z with sharp features, where one adjacent face's normal gives the wrong
  // sign: a ridge with a 60-degree interior angle, a pyramid and a steep cone. Points at distance t in
  // every direction from the ridge and the apex are above the surface iff they are on its + side.
  using std::abs;
  const std::vector<std::pair<TriangleSurface, Vector3d>> cases{
      {testing::graph_patch([](double x, double) { return 0.8 - std::sqrt(3.0) * abs(x - 0.5); }, {0.4, 0.6},
                            {0.3, 0.7}, 8, "ridge"),
       Vector3d(0.5, 0.5, 0.8)},
      {testing::graph_patch([](double x, double y) { return 0.8 - 1.5 * std::max(abs(x - 0.5), abs(y - 0.5)); },
                            {0.3, 0.7}, {0.3, 0.7}, 8, "pyramid"),
       Vector3d(0.5, 0.5, 0.8)},
      {testing::graph_patch([](double x, double y) { return 0.8 - 3.0 * std::hypot(x - 0.5, y - 0.5); }, {0.4, 0.6},
                            {0.4, 0.6}, 8, "cone"),
       Vector3d(0.5, 0.5, 0.8)}};
  std::mt19937_64 generator(31);
  for (const auto& [surface, apex] : cases) {
    const TriangleBVH bvh(surface);
    int vertex_features = 0;
    int edge_features = 0;
    for (double t : {1e-3, 1e-5, 1e-7, 1e-9}) {
      for (int k = 0; k < 400; ++k) {
        // Along the ridge (y varies) or at the apex.
        const Vector3d base = apex + Vector3d(0, k % 2 ? uniform(generator, -0.1, 0.1) : 0.0, 0);
        const Vector3d x = base + t * random_point(generator, -1, 1).normalized();
        const double above = x.z() - discrete_height(surface, x.x(), x.y());
        if (abs(above) < 1e-3 * t) continue;  // nearly tangent: the side is not well defined
        EXPECT_EQ(bvh.side(x), above > 0 ? 1 : -1) << surface.name << " at distance " << t;
        const ClosestPoint closest = bvh.closest_point(x);
        vertex_features += closest.feature == Feature::vertex;
        edge_features += closest.feature == Feature::edge;
      }
    }
    // Closest features: the ridge's edges (its vertices have no region of their own on a straight
    // ridge), the apexes of the pyramid and the cone, and their edges.
    if (surface.name != "ridge") {
      EXPECT_GE(vertex_features, 100) << surface.name;
    }
    EXPECT_GE(edge_features, 100) << surface.name;
  }
}

TEST(Geometry, SideAboveAndBelowGraphPatches) {
  // Graph patches are oriented towards +z: p + t e_z is above for t > 0, whatever the closest feature.
  std::mt19937_64 generator(29);
  for (const TriangleSurface& surface :
       {testing::paper_like_patch(10), testing::saddle(7), testing::perturbed(testing::tilted_plane(9), 0.25, 5)}) {
    const TriangleBVH bvh(surface);
    for (int t = 0; t < static_cast<int>(surface.triangles.size()); ++t) {
      const Triangle3 c = corners(surface, t);
      double u = uniform(generator, 0, 1);
      double v = uniform(generator, 0, 1);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      const Vector3d p = c[0] + u * (c[1] - c[0]) + v * (c[2] - c[0]);
      for (double offset : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10}) {
        EXPECT_EQ(bvh.side(p + Vector3d(0, 0, offset)), 1) << surface.name;
        EXPECT_EQ(bvh.side(p - Vector3d(0, 0, offset)), -1) << surface.name;
      }
    }
  }
}

// The nearest point of a hull: a point, the middle of a segment, the foot on a face, the origin inside;
// on random sets away from the origin, the optimality condition p·x ≥ |x|² for every point.
TEST(Geometry, HullPointNearestOrigin) {
  using V = Eigen::Vector3d;
  auto nearest = [](std::vector<V> points) { return hull_point_nearest_origin(points); };
  EXPECT_TRUE(nearest({V(2, 1, 0)}).isApprox(V(2, 1, 0)));
  EXPECT_LT((nearest({V(1, 0, 0), V(0, 1, 0)}) - V(0.5, 0.5, 0)).norm(), 1e-12);
  EXPECT_LT((nearest({V(1, 1, 2), V(1, -1, 2), V(1, 0, -3), V(4, 0, 0)}) - V(1, 0, 0)).norm(), 1e-12);
  EXPECT_LT(nearest({V(1, 0, 0), V(-1, 0, 0), V(0, 1, 0)}).norm(), 1e-9);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<V> points(2 + trial % 7);
    for (V& p : points) p = V(coordinate(rng), coordinate(rng), coordinate(rng)) + V(1.2, 0.3, 0.0);
    const V x = hull_point_nearest_origin(points);
    ASSERT_GT(x.norm(), 0.0);
    for (const V& p : points) EXPECT_GE(p.dot(x), (1 - 1e-9) * x.squaredNorm()) << "trial " << trial;
  }
}

// The rigid motion carrying paired points: exact for a rotation and translation (at the points and
// away from them), a proper rotation even when the pairs are mirror images, none when the points fix
// no rotation.
TEST(Geometry, RigidDisplacement) {
  using V = Eigen::Vector3d;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  auto random_point = [&] { return V(coordinate(rng), coordinate(rng), coordinate(rng)); };
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(3.0 * coordinate(rng), random_point().normalized()).matrix();
    const V translation = 10.0 * random_point();
    std::vector<V> from(3 + trial % 5), to;
    for (V& p : from) {
      p = random_point();
      to.push_back(rotation * p + translation);
    }
    for (const V& x : {from[0], V(5.0 * random_point())}) {
      const std::optional<V> d = rigid_displacement(from, to, x);
      ASSERT_TRUE(d) << "trial " << trial;
      EXPECT_LT((x + *d - (rotation * x + translation)).norm(), 1e-12 * (1.0 + x.norm())) << "trial " << trial;
    }
  }

  // Mirrored pairs: the best proper rotation keeps the tet's orientation and its edge lengths.
  const std::vector<V> tet{V(0, 0, 0), V(1, 0, 0), V(0, 2, 0), V(0, 0, 3)};
  std::vector<V> mirrored, carried;
  for (const V& p : tet) mirrored.push_back(V(-p.x(), p.y(), p.z()));
  for (const V& p : tet) carried.push_back(p + *rigid_displacement(tet, mirrored, p));
  auto volume = [](const std::vector<V>& t) { return (t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0]); };
  EXPECT_NEAR(volume(carried), volume(tet), 1e-12);
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) EXPECT_NEAR((carried[i] - carried[j]).norm(), (tet[i] - tet[j]).norm(), 1e-12);

  // Two points, or points on a line, leave the rotation about the line free; a line bent by 1 % fixes it.
  const std::vector<V> two{V(0, 0, 0), V(1, 0, 0)}, line{V(0, 0, 0), V(1, 1, 1), V(2, 2, 2), V(3, 3, 3)};
  EXPECT_FALSE(rigid_displacement(two, two, V(0, 1, 0)));
  EXPECT_FALSE(rigid_displacement(line, line, V(0, 1, 0)));
  std::vector<V> bent = line;
  bent[1] += V(0.01, -0.01, 0);
  const std::optional<V> still = rigid_displacement(bent, bent, V(0, 1, 0));
  ASSERT_TRUE(still);
  EXPECT_LT(still->norm(), 1e-12);
}

}  // namespace
}  // namespace meccano
