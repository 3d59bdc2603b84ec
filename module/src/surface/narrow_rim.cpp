#include <meccano/surface/narrow_rim.hpp>

#include <meccano/geometry/geometry.hpp>

#include "mesh/topology_helpers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

namespace meccano {
namespace {

// The rim as loops walked edge after edge: each rim vertex's loop and arc length from its loop's start.
struct RimLoops {
  std::vector<int> next;       // per vertex: the rim vertex after it on its loop, -1 off the rim
  std::vector<int> loop;       // per vertex: its loop, -1 off the rim
  std::vector<double> arc;     // per vertex: arc length from its loop's start to it
  std::vector<double> length;  // per loop: its perimeter
};

RimLoops walk_rim(const TriangleSurface& surface) {
  detail::TopologyScratch scratch;
  detail::triangle_topology(surface.triangles, scratch);
  const std::size_t n = surface.points.size();
  std::vector<std::array<int, 2>> rim_neighbours(n, {-1, -1});
  for (const auto& [a, b] : scratch.boundary) {
    rim_neighbours[a][rim_neighbours[a][0] < 0 ? 0 : 1] = b;
    rim_neighbours[b][rim_neighbours[b][0] < 0 ? 0 : 1] = a;
  }
  RimLoops rim{std::vector<int>(n, -1), std::vector<int>(n, -1), std::vector<double>(n, 0.0), {}};
  for (int start = 0; start < static_cast<int>(n); ++start) {
    if (rim_neighbours[start][0] < 0 || rim.loop[start] >= 0) continue;
    const int id = static_cast<int>(rim.length.size());
    double arc = 0.0;
    int previous = -1;
    int v = start;
    do {
      rim.loop[v] = id;
      rim.arc[v] = arc;
      const int after = rim_neighbours[v][0] != previous ? rim_neighbours[v][0] : rim_neighbours[v][1];
      rim.next[v] = after;
      arc += (surface.points[after] - surface.points[v]).norm();
      previous = v;
      v = after;
    } while (v != start);
    rim.length.push_back(arc);
  }
  return rim;
}

}  // namespace

std::vector<double> rim_widths(const TriangleSurface& surface, double up_to) {
  const RimLoops rim = walk_rim(surface);
  // The rim edges, each named by its first vertex along its loop, sorted by their smaller x: the edges
  // within up_to of a point x start between x.x - up_to - the longest rim edge and x.x + up_to.
  std::vector<std::pair<double, int>> edges;
  double longest = 0.0;
  for (int a = 0; a < static_cast<int>(surface.points.size()); ++a) {
    if (rim.loop[a] < 0) continue;
    const Eigen::Vector3d& p = surface.points[a];
    const Eigen::Vector3d& q = surface.points[rim.next[a]];
    edges.emplace_back(std::min(p.x(), q.x()), a);
    longest = std::max(longest, std::abs(p.x() - q.x()));
  }
  std::sort(edges.begin(), edges.end());
  std::vector<double> widths(surface.points.size(), std::numeric_limits<double>::infinity());
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(up_to);
  for (const auto& [ignored, v] : edges) {
    const Eigen::Vector3d& x = surface.points[v];
    const auto first = std::lower_bound(edges.begin(), edges.end(), std::pair{x.x() - up_to - longest, -1});
    for (auto edge = first; edge != edges.end() && edge->first <= x.x() + up_to; ++edge) {
      const int a = edge->second;
      const Eigen::Vector3d& p = surface.points[a];
      const Eigen::Vector3d& q = surface.points[rim.next[a]];
      if (((x - margin).array() > p.cwiseMax(q).array()).any() || ((x + margin).array() < p.cwiseMin(q).array()).any())
        continue;
      double t = 0.0;
      const double distance = std::sqrt(squared_distance_to_segment(x, p, q, &t));
      if (distance >= std::min(up_to, widths[v])) continue;
      bool across = rim.loop[a] != rim.loop[v];
      if (!across) {
        const double length = rim.length[rim.loop[v]];
        const double along = std::abs(rim.arc[a] + t * (q - p).norm() - rim.arc[v]);
        across = std::min(along, length - along) > 2.0 * distance;
      }
      if (across) widths[v] = distance;
    }
  }
  return widths;
}

}  // namespace meccano
