// The immersed surface S as the demo takes it: one interface of the deal.II adapter
// (meccano::DealiiInterface, meccano/dealii_mesh.hpp), three corner points per triangle, oriented like
// S, whatever made the mesh (the module in the same process, or an MSH file from any mesher); with
// what the demo measures and writes of it.
#pragma once

#include <meccano/dealii_mesh.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace solver_demo {

inline Eigen::Vector3d to_eigen(const dealii::Point<3>& p) { return {p[0], p[1], p[2]}; }

// Corner i (0, 1, 2) of triangle t, and the triangle's centroid.
inline Eigen::Vector3d corner(const meccano::DealiiInterface& interface, std::size_t t, int i) {
  return to_eigen(interface.corners[3 * t + static_cast<std::size_t>(i)]);
}
inline Eigen::Vector3d centroid(const meccano::DealiiInterface& interface, std::size_t t) {
  return (corner(interface, t, 0) + corner(interface, t, 1) + corner(interface, t, 2)) / 3.0;
}
// Its normal by the right-hand rule (S's), of length twice its area.
inline Eigen::Vector3d triangle_normal(const meccano::DealiiInterface& interface, std::size_t t) {
  return (corner(interface, t, 1) - corner(interface, t, 0)).cross(corner(interface, t, 2) - corner(interface, t, 0));
}

double interface_area(const meccano::DealiiInterface& interface);

// The triangles as a VTU file (atomic write), corners shared where they coincide, with one value per
// triangle for each field.
using TriangleField = std::pair<std::string, std::vector<double>>;
void write_interface_vtu(const meccano::DealiiInterface& interface, const std::vector<TriangleField>& fields,
                         const std::string& path);

}  // namespace solver_demo
