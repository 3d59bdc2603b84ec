#include "interface_triangles.hpp"

#include <meccano/io/atomic_file.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

namespace solver_demo {

double interface_area(const meccano::DealiiInterface& interface) {
  double area = 0.0;
  for (std::size_t t = 0; t < interface.triangles(); ++t) area += 0.5 * triangle_normal(interface, t).norm();
  return area;
}

SurfaceMatch match_surface(const meccano::DealiiInterface& interface, const SurfaceProjection& project) {
  SurfaceMatch match;
  if (interface.corners.empty()) {
    match.max_deviation = std::numeric_limits<double>::infinity();
    return match;
  }
  double edge_sum = 0.0;
  for (std::size_t t = 0; t < interface.triangles(); ++t)
    for (int i = 0; i < 3; ++i) edge_sum += (corner(interface, t, i) - corner(interface, t, (i + 1) % 3)).norm();
  match.tolerance = 0.05 * edge_sum / static_cast<double>(interface.corners.size());
  for (const dealii::Point<3>& p : interface.corners)
    match.max_deviation = std::max(match.max_deviation, (project(to_eigen(p)) - to_eigen(p)).norm());
  return match;
}

NormalError normal_error(const meccano::DealiiInterface& interface,
                         const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& exact_normal) {
  NormalError error;
  double area_sum = 0.0, weighted_sum = 0.0;
  for (std::size_t t = 0; t < interface.triangles(); ++t) {
    const Eigen::Vector3d normal = triangle_normal(interface, t);
    const double cosine = std::abs(normal.normalized().dot(exact_normal(centroid(interface, t))));
    const double angle = std::acos(std::min(1.0, cosine)) * 180.0 / std::numbers::pi;
    error.per_triangle_deg.push_back(angle);
    error.max_deg = std::max(error.max_deg, angle);
    area_sum += normal.norm();
    weighted_sum += normal.norm() * angle;
  }
  error.mean_deg = area_sum > 0.0 ? weighted_sum / area_sum : 0.0;
  return error;
}

void write_interface_vtu(const meccano::DealiiInterface& interface, const std::vector<TriangleField>& fields,
                         const std::string& path) {
  // The corners are copies of the mesh's vertices: equal coordinates are one node.
  std::map<std::array<double, 3>, std::size_t> node_of_point;
  std::vector<std::array<double, 3>> nodes;
  std::vector<std::size_t> connectivity;
  for (const dealii::Point<3>& p : interface.corners) {
    const std::array<double, 3> point{p[0], p[1], p[2]};
    const auto [found, added] = node_of_point.emplace(point, nodes.size());
    if (added) nodes.push_back(point);
    connectivity.push_back(found->second);
  }
  const std::size_t triangles = interface.triangles();
  meccano::write_file_atomically(path, [&](std::ostream& out) {
    out.precision(17);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << nodes.size() << "\" NumberOfCells=\"" << triangles
        << "\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const auto& [x, y, z] : nodes) out << x << ' ' << y << ' ' << z << '\n';
    out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (std::size_t t = 0; t < triangles; ++t)
      out << connectivity[3 * t] << ' ' << connectivity[3 * t + 1] << ' ' << connectivity[3 * t + 2] << '\n';
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 1; i <= triangles; ++i) out << 3 * i << '\n';
    out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < triangles; ++i) out << "5\n";  // VTK_TRIANGLE
    out << "</DataArray>\n</Cells>\n<CellData>\n";
    for (const auto& [name, values] : fields) {
      out << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (const double value : values) out << value << '\n';
      out << "</DataArray>\n";
    }
    out << "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  });
}

}  // namespace solver_demo
