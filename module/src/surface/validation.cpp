// Topological validation of an immersed surface: it must be a consistently oriented, manifold
// topological disk, or a closed one of genus 0 (a sphere). The checks run from the most basic to the most global, so that each one may
// assume what the previous ones established, and the first defect found is reported.
#include <meccano/error.hpp>
#include <meccano/surface/validation.hpp>

#include "mesh/topology_helpers.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cstddef>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace meccano {
namespace {

constexpr double kZeroAreaRelativeTolerance = 1e-14;  // times the squared bounding-box diagonal

using Triangle = std::array<int, 3>;

[[noreturn]] void fail(const TriangleSurface& surface, const std::string& defect) {
  const std::string& label = surface.source.empty() ? surface.name : surface.source;
  throw InputError((label.empty() ? std::string("surface") : label) + ": " + defect);
}

// Messages number triangles and vertices from 1, in the order read.
std::string triangle_name(std::size_t t) { return "triangle " + std::to_string(t + 1); }
std::string vertex_name(int v) { return "vertex " + std::to_string(v + 1); }

std::string format_number(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value;
  return out.str();
}


// One side of an edge: the triangle and whether it traverses the edge from its lower to its higher vertex.
struct EdgeSide {
  int low, high;
  int triangle;
  bool ascending;
};

// The triangles' edge sides, grouped by edge (sorted by vertex pair, then triangle).
std::vector<EdgeSide> sorted_edge_sides(const std::vector<Triangle>& triangles) {
  std::vector<EdgeSide> sides;
  sides.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int from = triangles[t][static_cast<std::size_t>(k)];
      const int to = triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      sides.push_back({std::min(from, to), std::max(from, to), static_cast<int>(t), from < to});
    }
  std::ranges::sort(sides, [](const EdgeSide& a, const EdgeSide& b) {
    return std::tie(a.low, a.high, a.triangle) < std::tie(b.low, b.high, b.triangle);
  });
  return sides;
}

// Calls visit(first, count) for each edge's run of sides.
template <class Visit>
void for_each_edge(const std::vector<EdgeSide>& sides, Visit visit) {
  for (std::size_t begin = 0; begin < sides.size();) {
    std::size_t end = begin + 1;
    while (end < sides.size() && sides[end].low == sides[begin].low && sides[end].high == sides[begin].high) ++end;
    visit(begin, end - begin);
    begin = end;
  }
}

void check_elements(const TriangleSurface& surface) {
  const auto& points = surface.points;
  const auto& triangles = surface.triangles;
  if (triangles.empty()) fail(surface, "the surface has no triangles");
  for (std::size_t v = 0; v < points.size(); ++v)
    if (!points[v].allFinite())
      fail(surface, vertex_name(static_cast<int>(v)) + " has a non-finite coordinate (" + format_number(points[v].x()) +
                        ", " + format_number(points[v].y()) + ", " + format_number(points[v].z()) + ")");
  const auto vertex_count = static_cast<long long>(points.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const int v : triangles[t])
      if (v < 0 || v >= vertex_count)
        fail(surface, triangle_name(t) + " refers to vertex " + std::to_string(static_cast<long long>(v) + 1) +
                          ", out of range (the surface has vertices 1.." + std::to_string(vertex_count) + ")");
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto [a, b, c] = triangles[t];
    if (a == b || b == c || a == c)
      fail(surface, triangle_name(t) + " repeats " + vertex_name(a == b || a == c ? a : b) + " (its vertices are " +
                        std::to_string(a + 1) + ", " + std::to_string(b + 1) + ", " + std::to_string(c + 1) + ")");
  }

  Eigen::Vector3d lo = points[static_cast<std::size_t>(triangles[0][0])];
  Eigen::Vector3d hi = lo;
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double min_area = kZeroAreaRelativeTolerance * (hi - lo).squaredNorm();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3d& a = points[static_cast<std::size_t>(triangles[t][0])];
    const Eigen::Vector3d& b = points[static_cast<std::size_t>(triangles[t][1])];
    const Eigen::Vector3d& c = points[static_cast<std::size_t>(triangles[t][2])];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (area <= min_area)
      fail(surface, triangle_name(t) + " has zero area (area " + format_number(area) +
                        " <= " + format_number(min_area) + " = 1e-14 x squared bounding-box diagonal)");
  }
}

void check_no_duplicate_triangles(const TriangleSurface& surface) {
  struct Keyed {
    Triangle sorted;
    int triangle;
  };
  std::vector<Keyed> keyed;
  keyed.reserve(surface.triangles.size());
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    Triangle sorted = surface.triangles[t];
    std::ranges::sort(sorted);
    keyed.push_back({sorted, static_cast<int>(t)});
  }
  std::ranges::sort(keyed, [](const Keyed& a, const Keyed& b) {
    return std::tie(a.sorted, a.triangle) < std::tie(b.sorted, b.triangle);
  });
  // Of all the duplicated pairs, report the one whose later triangle comes first in the file.
  const Keyed* first = nullptr;
  const Keyed* second = nullptr;
  for (std::size_t i = 1; i < keyed.size(); ++i)
    if (keyed[i].sorted == keyed[i - 1].sorted && (!second || keyed[i].triangle < second->triangle)) {
      first = &keyed[i - 1];
      second = &keyed[i];
    }
  if (second)
    fail(surface, triangle_name(static_cast<std::size_t>(first->triangle)) + " and " +
                      triangle_name(static_cast<std::size_t>(second->triangle)) +
                      " are duplicates (both use vertices " + std::to_string(first->sorted[0] + 1) + ", " +
                      std::to_string(first->sorted[1] + 1) + ", " + std::to_string(first->sorted[2] + 1) + ")");
}

void check_manifold_edges(const TriangleSurface& surface, const std::vector<EdgeSide>& sides) {
  for_each_edge(sides, [&](std::size_t first, std::size_t count) {
    if (count <= 2) return;
    std::string names;
    for (std::size_t i = first; i < first + count; ++i)
      names += (i == first ? "" : ", ") + std::to_string(sides[i].triangle + 1);
    fail(surface, "non-manifold edge between " + vertex_name(sides[first].low) + " and " +
                      vertex_name(sides[first].high) + ": shared by " + std::to_string(count) + " triangles (" + names +
                      ")");
  });
}

void check_consistent_orientation(const TriangleSurface& surface, const std::vector<EdgeSide>& sides) {
  for_each_edge(sides, [&](std::size_t first, std::size_t count) {
    if (count != 2 || sides[first].ascending != sides[first + 1].ascending) return;
    const int from = sides[first].ascending ? sides[first].low : sides[first].high;
    const int to = sides[first].ascending ? sides[first].high : sides[first].low;
    fail(surface, "inconsistent orientation: " + triangle_name(static_cast<std::size_t>(sides[first].triangle)) +
                      " and " + triangle_name(static_cast<std::size_t>(sides[first + 1].triangle)) +
                      " both traverse their shared edge from " + vertex_name(from) + " to " + vertex_name(to));
  });
}

// Triangles sharing a vertex are connected: a bow-tie is one component with a non-manifold vertex.
void check_single_component(const TriangleSurface& surface) {
  detail::UnionFind sets(surface.points.size());
  for (const Triangle& triangle : surface.triangles) {
    sets.join(triangle[0], triangle[1]);
    sets.join(triangle[0], triangle[2]);
  }
  std::vector<bool> seen(surface.points.size(), false);
  int components = 0;
  std::size_t second_component_triangle = 0;
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const std::size_t root = sets.find(surface.triangles[t][0]);
    if (seen[root]) continue;
    seen[root] = true;
    if (++components == 2) second_component_triangle = t;
  }
  if (components > 1)
    fail(surface, "the surface has " + std::to_string(components) + " connected components (" +
                      triangle_name(second_component_triangle) +
                      " is in the second one); a single connected surface is required");
}

// The triangles around each vertex must form a single fan: corners of two triangles that share an
// edge through the vertex are joined, and a vertex whose corners end in several groups is pinched.
void check_manifold_vertices(const TriangleSurface& surface, const std::vector<EdgeSide>& sides) {
  const auto& triangles = surface.triangles;
  auto corner = [&](int t, int vertex) {
    const Triangle& triangle = triangles[static_cast<std::size_t>(t)];
    return 3 * t + static_cast<int>(std::ranges::find(triangle, vertex) - triangle.begin());
  };
  detail::UnionFind fans(3 * triangles.size());
  for_each_edge(sides, [&](std::size_t first, std::size_t count) {
    if (count != 2) return;
    for (const int vertex : {sides[first].low, sides[first].high})
      fans.join(corner(sides[first].triangle, vertex), corner(sides[first + 1].triangle, vertex));
  });
  std::vector<int> fan_of_vertex(surface.points.size(), -1);
  std::vector<int> triangle_of_vertex(surface.points.size(), -1);
  int pinched = -1;
  int other_triangle = -1;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const int vertex = triangles[t][k];
      const auto fan = static_cast<int>(fans.find(3 * t + k));
      int& known = fan_of_vertex[static_cast<std::size_t>(vertex)];
      if (known < 0) {
        known = fan;
        triangle_of_vertex[static_cast<std::size_t>(vertex)] = static_cast<int>(t);
      } else if (known != fan && (pinched < 0 || vertex < pinched)) {
        pinched = vertex;
        other_triangle = static_cast<int>(t);
      }
    }
  if (pinched < 0) return;
  std::vector<int> fan_roots;
  for (std::size_t c = 0; c < 3 * triangles.size(); ++c)
    if (triangles[c / 3][c % 3] == pinched) fan_roots.push_back(static_cast<int>(fans.find(c)));
  std::ranges::sort(fan_roots);
  const auto fan_count = std::ranges::distance(fan_roots.begin(), std::unique(fan_roots.begin(), fan_roots.end()));
  fail(surface, "non-manifold " + vertex_name(pinched) + ": its triangles form " + std::to_string(fan_count) +
                    " separate fans instead of one (e.g. " +
                    triangle_name(static_cast<std::size_t>(triangle_of_vertex[static_cast<std::size_t>(pinched)])) +
                    " and " + triangle_name(static_cast<std::size_t>(other_triangle)) + " are in different fans)");
}

// An open surface must be a disk; a closed one a sphere (genus 0), the only closed surfaces supported.
void check_disk_or_sphere(const TriangleSurface& surface) {
  detail::TopologyScratch scratch;
  const detail::TriangleTopology topology = detail::triangle_topology(surface.triangles, scratch);
  const std::string euler = "Euler characteristic V - E + F = " + std::to_string(topology.vertices) + " - " +
                            std::to_string(topology.edges) + " + " + std::to_string(topology.faces) + " = " +
                            std::to_string(topology.euler());
  if (topology.boundary_edges == 0) {
    if (topology.euler() != 2)
      fail(surface, "closed surface of genus " + std::to_string((2 - topology.euler()) / 2) + " (" + euler +
                        " instead of 2): only closed surfaces of genus 0 (spheres) are supported");
    return;
  }
  const int boundary_loops = detail::count_boundary_loops(scratch);
  if (boundary_loops != 1)
    fail(surface, "not a topological disk: " + std::to_string(boundary_loops) +
                      " boundary loops (the surface has holes); exactly 1 is required");
  if (topology.euler() != 1)
    fail(surface, "not a topological disk: " + euler + " instead of 1 (the surface has handles)");
}

}  // namespace

void require_surface_topology(const TriangleSurface& surface) {
  check_elements(surface);
  check_no_duplicate_triangles(surface);
  const std::vector<EdgeSide> sides = sorted_edge_sides(surface.triangles);
  check_manifold_edges(surface, sides);
  check_consistent_orientation(surface, sides);
  check_single_component(surface);
  check_manifold_vertices(surface, sides);
  check_disk_or_sphere(surface);
}

}  // namespace meccano
