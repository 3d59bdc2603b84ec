#include "kinked_graph.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace solver_demo {
namespace {

int axis_a(const KinkedGraph& graph) { return (graph.height_axis + 1) % 3; }
int axis_b(const KinkedGraph& graph) { return (graph.height_axis + 2) % 3; }

// A vector of the plane (x_a, x_b), and t's component, as a vector of R³.
Eigen::Vector3d spatial(const KinkedGraph& graph, const Eigen::Vector2d& planar, double along_t) {
  Eigen::Vector3d v;
  v[axis_a(graph)] = planar.x();
  v[axis_b(graph)] = planar.y();
  v[graph.height_axis] = along_t;
  return v;
}

// b = e^z sin(2x + y): nonzero on the box sides, and −Δb = (4 + 1 − 1) b.
ValueAndGradient smooth_part(const Eigen::Vector3d& p) {
  const double e = std::exp(p.z()), s = std::sin(2.0 * p.x() + p.y()), c = std::cos(2.0 * p.x() + p.y());
  return {e * s, {2.0 * e * c, e * c, e * s}};
}

// ∇d = e_t − ∇s.
Eigen::Vector3d height_gradient(const KinkedGraph& graph, const PlanarValue& s) {
  return spatial(graph, -s.gradient, 1.0);
}

}  // namespace

Eigen::Vector2d planar_coordinates(const KinkedGraph& graph, const Eigen::Vector3d& p) {
  return {p[axis_a(graph)], p[axis_b(graph)]};
}

Eigen::Vector3d graph_point(const KinkedGraph& graph, const Eigen::Vector3d& p) {
  const Eigen::Vector2d ab = planar_coordinates(graph, p);
  return spatial(graph, ab, graph.height(ab).value);
}

Eigen::Vector3d graph_normal(const KinkedGraph& graph, const Eigen::Vector3d& p) {
  return height_gradient(graph, graph.height(planar_coordinates(graph, p))).normalized();
}

ValueAndGradient kinked_solution(const KinkedGraph& graph, const Eigen::Vector3d& p) {
  ValueAndGradient u = smooth_part(p);
  const Eigen::Vector2d ab = planar_coordinates(graph, p);
  const PlanarValue w = graph.cutoff(ab);
  if (w.value == 0.0) return u;
  // The kink term k = −w |d|: ∇k = −σ (d ∇w + w ∇d).
  const PlanarValue s = graph.height(ab);
  const double d = p[graph.height_axis] - s.value, sigma = d >= 0.0 ? 1.0 : -1.0;
  u.value -= w.value * std::abs(d);
  u.gradient -= sigma * (d * spatial(graph, w.gradient, 0.0) + w.value * height_gradient(graph, s));
  return u;
}

double kinked_right_hand_side(const KinkedGraph& graph, const Eigen::Vector3d& p) {
  const double smooth = 4.0 * smooth_part(p).value;
  const Eigen::Vector2d ab = planar_coordinates(graph, p);
  const PlanarValue w = graph.cutoff(ab);
  if (w.value == 0.0) return smooth;
  // −Δk = σ Δ(w d) = σ (d Δw + 2 ∇w·∇d + w Δd), with ∇w·∇d = −∇w·∇s and Δd = −Δs.
  const PlanarValue s = graph.height(ab);
  const double d = p[graph.height_axis] - s.value, sigma = d >= 0.0 ? 1.0 : -1.0;
  return smooth + sigma * (d * w.laplacian - 2.0 * w.gradient.dot(s.gradient) - w.value * s.laplacian);
}

double kinked_interface_source(const KinkedGraph& graph, const Eigen::Vector3d& p) {
  // On S, ∇k = ∓ w ∇d from the front and the back, and ∇d = |∇d| n: the jump ∂u/∂n|⁻ − ∂u/∂n|⁺ is 2 w |∇d|.
  const Eigen::Vector2d ab = planar_coordinates(graph, p);
  return 2.0 * graph.cutoff(ab).value * height_gradient(graph, graph.height(ab)).norm();
}

meccano::TriangleSurface triangulate_graph(const KinkedGraph& graph, const Eigen::Vector2d& origin,
                                           const Eigen::Vector2d& extent, int n_a, int n_b, const std::string& name) {
  meccano::TriangleSurface surface;
  surface.name = name;
  for (int j = 0; j <= n_b; ++j)
    for (int i = 0; i <= n_a; ++i) {
      const Eigen::Vector2d ab(origin.x() + extent.x() * i / n_a, origin.y() + extent.y() * j / n_b);
      surface.points.push_back(spatial(graph, ab, graph.height(ab).value));
    }
  // Counter-clockwise in (x_a, x_b), so the right-hand normal points towards +t.
  for (int j = 0; j < n_b; ++j)
    for (int i = 0; i < n_a; ++i) {
      const int a = j * (n_a + 1) + i, b = a + 1, c = a + n_a + 2, d = a + n_a + 1;
      if ((i + j) % 2 == 0) {
        surface.triangles.push_back({a, b, c});
        surface.triangles.push_back({a, c, d});
      } else {
        surface.triangles.push_back({a, b, d});
        surface.triangles.push_back({b, c, d});
      }
    }
  return surface;
}

PlanarValue fourth_power(const PlanarValue& B) {
  const double b = B.value;
  return {b * b * b * b, 4.0 * b * b * b * B.gradient,
          12.0 * b * b * B.gradient.squaredNorm() + 4.0 * b * b * b * B.laplacian};
}

SurfaceMatch match_graph(const meccano::DealiiInterface& interface, const KinkedGraph& graph,
                         const Eigen::Vector2d& origin, const Eigen::Vector2d& extent) {
  SurfaceMatch match = match_surface(interface, [&graph](const Eigen::Vector3d& p) { return graph_point(graph, p); });
  const Eigen::Vector2d margin = Eigen::Vector2d::Constant(match.tolerance);
  const auto over_rectangle = [&](const dealii::Point<3>& corner) {
    const Eigen::Vector2d ab = planar_coordinates(graph, to_eigen(corner));
    return (ab.array() >= (origin - margin).array()).all() && (ab.array() <= (origin + extent + margin).array()).all();
  };
  if (!std::all_of(interface.corners.begin(), interface.corners.end(), over_rectangle))
    match.max_deviation = std::numeric_limits<double>::infinity();
  return match;
}

}  // namespace solver_demo
