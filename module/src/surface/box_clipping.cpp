#include <meccano/surface/box_clipping.hpp>

#include <meccano/error.hpp>
#include <meccano/surface/closed_surface.hpp>
#include <meccano/surface/validation.hpp>

#include "mesh/topology_helpers.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <numeric>
#include <sstream>
#include <string>

namespace meccano {

std::uint8_t box_sides(const Eigen::Vector3d& point, const Box& box) {
  std::uint8_t sides = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (point[axis] == box.min[axis]) sides |= static_cast<std::uint8_t>(1u << (2 * axis));
    if (point[axis] == box.max[axis]) sides |= static_cast<std::uint8_t>(1u << (2 * axis + 1));
  }
  return sides;
}

bool reaches_box(const TriangleSurface& surface, const Box& box) {
  return std::ranges::any_of(surface.points, [&](const Eigen::Vector3d& p) {
    return (p.array() <= box.min.array()).any() || (p.array() >= box.max.array()).any();
  });
}

namespace {

std::string label(const TriangleSurface& surface) {
  return surface.source.empty() ? surface.name : surface.source + " (" + surface.name + ")";
}

// The surface over the points its triangles use, in their first-use order.
TriangleSurface compacted(const TriangleSurface& surface, std::span<const std::array<int, 3>> triangles) {
  TriangleSurface part;
  part.name = surface.name;
  part.source = surface.source;
  std::vector<int> index(surface.points.size(), -1);
  for (const auto& t : triangles) {
    std::array<int, 3>& copy = part.triangles.emplace_back();
    for (int k = 0; k < 3; ++k) {
      if (index[t[k]] < 0) {
        index[t[k]] = static_cast<int>(part.points.size());
        part.points.push_back(surface.points[t[k]]);
      }
      copy[k] = index[t[k]];
    }
  }
  return part;
}

// The part of S on the inside of the plane x[axis] = offset (below it for an upper plane), its vertices
// on the cut set exactly onto the plane.
TriangleSurface clipped_by_plane(const TriangleSurface& surface, int axis, double offset, bool upper) {
  std::optional<PlaneCut> cut = cut_by_plane(surface, axis, offset);
  if (!cut)
    throw InputError(label(surface) + ": a triangle lies in the box plane x" + std::to_string(axis) + " = " +
                     std::to_string(offset) + " (the surface runs along the box boundary)");
  const auto& inside = upper ? cut->below : cut->above;
  const auto& outside = upper ? cut->above : cut->below;
  std::vector<std::uint8_t> used_outside(cut->points.size(), 0);
  for (const auto& t : outside)
    for (int v : t) used_outside[v] = 1;
  for (const auto& t : inside)
    for (int v : t)
      if (used_outside[v]) cut->points[v][axis] = offset;
  TriangleSurface whole = surface;
  whole.points = std::move(cut->points);
  return compacted(whole, inside);
}

// Edge-connected components of the triangles: a component id per triangle, and the count.
std::vector<int> triangle_components(std::span<const std::array<int, 3>> triangles, int& count) {
  std::vector<int> parent(triangles.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  const auto edges = detail::edges_with_triangles(triangles);
  for (std::size_t i = 0; i + 1 < edges.size(); ++i)
    if (edges[i].first == edges[i + 1].first) parent[root(edges[i].second)] = root(edges[i + 1].second);
  std::vector<int> component(triangles.size(), -1), id(triangles.size(), -1);
  count = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const int r = root(static_cast<int>(t));
    if (id[r] < 0) id[r] = count++;
    component[t] = id[r];
  }
  return component;
}

}  // namespace

std::vector<TriangleSurface> clip_to_box(const TriangleSurface& surface, const Box& box) {
  if (!reaches_box(surface, box)) return {surface};
  if (is_closed(surface))
    throw InputError(label(surface) + ": a closed surface must lie strictly inside the box, but it reaches the box "
                                      "boundary");
  TriangleSurface inside = surface;
  for (int axis = 0; axis < 3; ++axis)
    for (bool upper : {false, true}) {
      const double offset = upper ? box.max[axis] : box.min[axis];
      const bool reaches = std::ranges::any_of(
          inside.points, [&](const Eigen::Vector3d& p) { return upper ? p[axis] >= offset : p[axis] <= offset; });
      if (reaches && !inside.triangles.empty()) inside = clipped_by_plane(inside, axis, offset, upper);
    }
  if (inside.triangles.empty()) throw InputError(label(surface) + ": no part of the surface lies inside the box");

  int count = 0;
  const std::vector<int> component = triangle_components(inside.triangles, count);
  std::vector<std::vector<std::array<int, 3>>> triangles(count);
  for (std::size_t t = 0; t < inside.triangles.size(); ++t) triangles[component[t]].push_back(inside.triangles[t]);
  std::vector<TriangleSurface> parts;
  for (const auto& part : triangles) parts.push_back(compacted(inside, part));
  std::ranges::stable_sort(parts, std::greater<>(), [](const TriangleSurface& part) { return surface_area(part); });
  for (std::size_t k = 0; k < parts.size(); ++k) {
    if (parts.size() > 1) parts[k].name = surface.name + "_" + std::to_string(k + 1);
    try {
      require_surface_topology(parts[k]);
    } catch (const InputError& error) {
      throw InputError(std::string(error.what()) + " (the part of the surface inside the box)");
    }
  }
  return parts;
}

RimSnap snap_rim_to_box(TriangleSurface& surface, const Box& box, double distance) {
  detail::TopologyScratch scratch;
  detail::triangle_topology(surface.triangles, scratch);
  std::vector<std::vector<int>> rim_neighbours(surface.points.size());
  for (const auto& [a, b] : scratch.boundary) {
    rim_neighbours[a].push_back(b);
    rim_neighbours[b].push_back(a);
  }

  std::vector<Eigen::Vector3d> snapped = surface.points;
  RimSnap snap;
  for (int axis = 0; axis < 3; ++axis)
    for (const bool upper : {false, true}) {
      const double offset = upper ? box.max[axis] : box.min[axis];
      // How far inside the box a point lies from this plane (negative beyond it).
      const auto depth = [&](const Eigen::Vector3d& p) { return upper ? offset - p[axis] : p[axis] - offset; };
      for (std::size_t v = 0; v < surface.points.size(); ++v) {
        const double d = depth(surface.points[v]);
        if (d <= 0.0 || d > distance) continue;
        // A rim edge that runs along the plane within 45° and ends within `distance` of it (or beyond).
        const bool edge_near = std::ranges::any_of(rim_neighbours[v], [&](int w) {
          const Eigen::Vector3d along = surface.points[static_cast<std::size_t>(w)] - surface.points[v];
          const double across = std::abs(along[axis]);
          return depth(surface.points[static_cast<std::size_t>(w)]) <= distance &&
                 across * across <= along.squaredNorm() - across * across;
        });
        if (!edge_near) continue;
        snapped[v][axis] = offset;
        snap.largest_move = std::max(snap.largest_move, d);
      }
    }
  for (std::size_t v = 0; v < snapped.size(); ++v) snap.vertices += snapped[v] != surface.points[v];

  const auto normal = [](const std::vector<Eigen::Vector3d>& points, const std::array<int, 3>& t) {
    return (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).eval();
  };
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& triangle = surface.triangles[t];
    const auto moved = std::ranges::find_if(triangle, [&](int v) { return snapped[v] != surface.points[v]; });
    if (moved == triangle.end() || normal(snapped, triangle).dot(normal(surface.points, triangle)) > 0.0) continue;
    std::ostringstream message;  // 1-based numbers, as in the surface files and the other messages
    message << label(surface) << ": setting its rim onto the box within " << distance << " turns triangle " << t + 1
            << " over or flattens it (vertex " << *moved + 1 << " moves by "
            << (snapped[*moved] - surface.points[*moved]).norm() << "): give a smaller distance";
    throw InputError(message.str());
  }
  surface.points = std::move(snapped);
  return snap;
}

}  // namespace meccano
