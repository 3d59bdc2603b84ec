// The geometric checks of surface/validation.hpp.
//
// Tolerances (all relative, so the checks do not depend on the units):
//   self-intersection  triangles_intersect (geometry/geometry.hpp): contact within 1e-12 of the pair's size;
//                      neighbouring triangles only when they meet away from their shared corners.
//   inside the box     a vertex closer to a box face than 1e-9 times the box diagonal lies on the
//                      boundary; farther out than that it is outside. A rim vertex of an open surface
//                      may lie exactly on a box plane (a surface clipped by the box).
//   two surfaces       they touch when closer than 1e-9 times the diagonal of the bounding box of
//                      both; they intersect when they cross by more than that (penetration depth of a
//                      pair of triangles, see triangle_separation), so a shallow crossing counts as
//                      touching.
#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/surface/box_clipping.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/validation.hpp>

#include "mesh/topology_helpers.hpp"

#include <algorithm>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace meccano {

namespace {

constexpr double boundary_margin = 1e-9;
constexpr double touch_tolerance = 1e-9;

std::string label(const TriangleSurface& surface) {
  if (!surface.source.empty()) return surface.source;
  return surface.name.empty() ? std::string("surface") : surface.name;
}

std::ostringstream message_stream() {
  std::ostringstream out;
  out.precision(15);
  return out;
}

std::string describe(const Box& box) {
  std::ostringstream out = message_stream();
  for (int k = 0; k < 3; ++k) out << (k ? " x [" : "[") << box.min[k] << ", " << box.max[k] << "]";
  return out.str();
}

Triangle3 corners(const TriangleSurface& surface, const std::array<int, 3>& v) {
  return {surface.points[v[0]], surface.points[v[1]], surface.points[v[2]]};
}

// Reorders the corners of a and b so that their common vertices come first, in the same order in
// both (the convention of triangles_intersect); returns how many they share.
int put_shared_corners_first(std::array<int, 3>& a, std::array<int, 3>& b) {
  std::array<int, 3> new_a{};
  std::array<int, 3> new_b{};
  int shared = 0;
  for (int i = 0; i < 3; ++i) {
    const auto match = std::find(b.begin(), b.end(), a[i]);
    if (match != b.end()) {
      new_a[shared] = a[i];
      new_b[shared] = a[i];
      ++shared;
    }
  }
  int rest_a = shared;
  int rest_b = shared;
  for (int i = 0; i < 3; ++i) {
    if (std::find(new_a.begin(), new_a.begin() + shared, a[i]) == new_a.begin() + shared) new_a[rest_a++] = a[i];
    if (std::find(new_b.begin(), new_b.begin() + shared, b[i]) == new_b.begin() + shared) new_b[rest_b++] = b[i];
  }
  a = new_a;
  b = new_b;
  return shared;
}

Eigen::AlignedBox3d inflated(Eigen::AlignedBox3d box, double margin) {
  box.min().array() -= margin;
  box.max().array() += margin;
  return box;
}

}  // namespace

void require_no_self_intersection(const TriangleSurface& surface) {
  if (surface.triangles.empty()) return;
  const TriangleBVH bvh(surface);
  std::vector<int> candidates;
  for (int i = 0; i < bvh.triangle_count(); ++i) {
    // Triangles with disjoint bounding boxes are disjoint, so the box query loses no contact.
    candidates.clear();
    bvh.for_each_triangle_overlapping(bounding_box(bvh.triangle(i)), [&](int j) {
      if (j > i) candidates.push_back(j);
    });
    std::sort(candidates.begin(), candidates.end());  // report the first pair in reading order
    for (int j : candidates) {
      std::array<int, 3> a = surface.triangles[i];
      std::array<int, 3> b = surface.triangles[j];
      const int shared = put_shared_corners_first(a, b);
      if (shared == 3 || triangles_intersect(corners(surface, a), corners(surface, b), shared)) {
        std::ostringstream out = message_stream();
        out << label(surface) << ": triangles " << i + 1 << " and " << j + 1 << " intersect";
        throw InputError(out.str());
      }
    }
  }
}

void require_strictly_inside_box(const TriangleSurface& surface, const Box& box) {
  const double margin = boundary_margin * box.diagonal();
  for (std::size_t v = 0; v < surface.points.size(); ++v) {
    const Eigen::Array3d p = surface.points[v].array();
    const bool outside = !p.allFinite() || (p < box.min.array() - margin).any() || (p > box.max.array() + margin).any();
    const bool on_boundary = (p <= box.min.array() + margin).any() || (p >= box.max.array() - margin).any();
    if (!outside && !on_boundary) continue;
    std::ostringstream out = message_stream();
    out << label(surface) << ": vertex " << v + 1 << " (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
    if (outside) {
      out << " is outside the box " << describe(box);
    } else {
      out << " lies on the box boundary (box " << describe(box) << ", margin " << margin << ")";
    }
    throw InputError(out.str());
  }
}

void require_inside_box(const TriangleSurface& surface, const Box& box) {
  if (is_closed(surface)) {
    require_strictly_inside_box(surface, box);
    return;
  }
  // Clipped by the box (surface/box_clipping.hpp): rim vertices may lie exactly on its planes.
  detail::TopologyScratch scratch;
  detail::triangle_topology(surface.triangles, scratch);
  // The box planes each vertex's rim edges run on: a rim vertex on a plane must have one of its rim edges
  // on it, or S would touch the box at a point (where S_M cannot follow it).
  std::vector<std::uint8_t> rim_planes(surface.points.size(), 0);
  for (const detail::Edge& e : scratch.boundary) {
    const auto planes =
        static_cast<std::uint8_t>(box_sides(surface.points[e.first], box) & box_sides(surface.points[e.second], box));
    rim_planes[e.first] |= planes;
    rim_planes[e.second] |= planes;
  }
  const double margin = boundary_margin * box.diagonal();
  for (std::size_t v = 0; v < surface.points.size(); ++v) {
    const Eigen::Array3d p = surface.points[v].array();
    const bool outside = !p.allFinite() || (p < box.min.array()).any() || (p > box.max.array()).any();
    const std::uint8_t planes = box_sides(surface.points[v], box);
    const bool near_planes = (p <= box.min.array() + margin).any() || (p >= box.max.array() - margin).any();
    if (!outside && (planes != 0 ? rim_planes[v] == planes : !near_planes)) continue;
    std::ostringstream out = message_stream();
    out << label(surface) << ": vertex " << v + 1 << " (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
    if (outside) out << " is outside the box " << describe(box) << " (clip the surface to the box first)";
    else if (planes != 0)
      out << " lies on the box boundary " << describe(box)
          << ", but the surface's rim does not run along the boundary there (it touches the box at a point)";
    else out << " lies within " << margin << " of the box boundary " << describe(box) << " without being on it";
    throw InputError(out.str());
  }
}

void require_surfaces_disjoint(const TriangleSurface& a, const TriangleSurface& b) {
  if (a.triangles.empty() || b.triangles.empty()) return;
  const Eigen::AlignedBox3d box_a = bounding_box(a.points);
  const Eigen::AlignedBox3d box_b = bounding_box(b.points);
  const double tolerance = touch_tolerance * box_a.merged(box_b).diagonal().norm();
  if (!inflated(box_a, tolerance).intersects(box_b)) return;

  const TriangleBVH bvh(b);
  std::optional<std::pair<int, int>> touching;
  std::vector<int> candidates;
  const auto fail = [&](const char* verb, int i, int j) {
    std::ostringstream out = message_stream();
    out << label(a) << " and " << label(b) << " " << verb << " (triangle " << i + 1 << " of " << label(a)
        << ", triangle " << j + 1 << " of " << label(b) << "; tolerance " << tolerance << ")";
    throw InputError(out.str());
  };
  for (int i = 0; i < static_cast<int>(a.triangles.size()); ++i) {
    const Triangle3 triangle = corners(a, a.triangles[i]);
    candidates.clear();
    bvh.for_each_triangle_overlapping(inflated(bounding_box(triangle), tolerance),
                                      [&](int j) { candidates.push_back(j); });
    std::sort(candidates.begin(), candidates.end());
    for (int j : candidates) {
      const double separation = triangle_separation(triangle, bvh.triangle(j));
      if (separation <= -tolerance) fail("intersect", i, j);
      // The separation is a lower bound of the distance; compute the distance only when it matters.
      if (!touching && separation < tolerance && triangle_distance(triangle, bvh.triangle(j)) < tolerance) {
        touching = std::pair{i, j};
      }
    }
  }
  if (touching) fail("touch", touching->first, touching->second);
}

void validate_surfaces(std::span<const TriangleSurface> surfaces, const Box& box) {
  for (const TriangleSurface& surface : surfaces) {
    require_surface_topology(surface);
    require_inside_box(surface, box);
    require_no_self_intersection(surface);
  }
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    for (std::size_t j = i + 1; j < surfaces.size(); ++j) require_surfaces_disjoint(surfaces[i], surfaces[j]);
  }
}

}  // namespace meccano
