#include "curved_interface.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace solver_demo {
namespace {

dealii::Point<3> to_point(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

meccano::DealiiMesh with_interface_on_surface(const meccano::DealiiMesh& mesh, const std::string& interface_name,
                                              const SurfaceProjection& project) {
  const auto key = [](const dealii::Point<3>& p) { return std::array<double, 3>{p[0], p[1], p[2]}; };
  std::map<std::array<double, 3>, dealii::Point<3>> on_surface;
  for (const dealii::Point<3>& p : mesh.interface(interface_name).corners)
    on_surface.emplace(key(p), to_point(project(to_eigen(p))));
  const auto move = [&](dealii::Point<3>& p) {
    if (const auto found = on_surface.find(key(p)); found != on_surface.end()) p = found->second;
  };
  meccano::DealiiMesh moved = mesh;
  for (dealii::Point<3>& vertex : moved.vertices) move(vertex);
  for (meccano::DealiiInterface& interface : moved.interfaces)
    for (dealii::Point<3>& p : interface.corners) move(p);
  return moved;
}

void curve_cells_onto_surface(dealii::Triangulation<3>& triangulation, const meccano::DealiiInterface& interface,
                              const SurfaceProjection& project) {
  constexpr dealii::types::manifold_id curved = 0;
  triangulation.set_all_manifold_ids(curved);
  triangulation.set_manifold(curved, InterfaceEdgeManifold(interface, project));
}

InterfaceEdgeManifold::InterfaceEdgeManifold(const meccano::DealiiInterface& interface, SurfaceProjection project_)
    : project(std::move(project_)) {
  for (std::size_t t = 0; t < interface.triangles(); ++t)
    for (std::size_t i = 0; i < 3; ++i)
      edges.push_back(edge(interface.corners[3 * t + i], interface.corners[3 * t + (i + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
}

std::unique_ptr<dealii::Manifold<3>> InterfaceEdgeManifold::clone() const {
  return std::make_unique<InterfaceEdgeManifold>(*this);
}

dealii::Point<3> InterfaceEdgeManifold::get_new_point(const dealii::ArrayView<const dealii::Point<3>>& points,
                                                      const dealii::ArrayView<const double>& weights) const {
  dealii::Point<3> mean;
  std::vector<unsigned int> weighted;
  for (unsigned int i = 0; i < points.size(); ++i) {
    mean += weights[i] * points[i];
    if (std::abs(weights[i]) > 1e-12) weighted.push_back(i);
  }
  const bool midpoint = weighted.size() == 2 && std::abs(weights[weighted[0]] - 0.5) < 1e-12 &&
                        std::abs(weights[weighted[1]] - 0.5) < 1e-12;
  if (midpoint && std::binary_search(edges.begin(), edges.end(), edge(points[weighted[0]], points[weighted[1]])))
    return to_point(project(to_eigen(mean)));
  return mean;
}

InterfaceEdgeManifold::Edge InterfaceEdgeManifold::edge(const dealii::Point<3>& a, const dealii::Point<3>& b) {
  std::array<double, 3> first{a[0], a[1], a[2]}, second{b[0], b[1], b[2]};
  if (second < first) std::swap(first, second);
  return {first[0], first[1], first[2], second[0], second[1], second[2]};
}

}  // namespace solver_demo
