// The immersed surface S as the demo takes it: one interface of the deal.II adapter
// (meccano::DealiiInterface, meccano/dealii_mesh.hpp), three corner points per triangle, oriented like
// S, whatever made the mesh (the module in the same process, or an MSH file from any mesher); with
// what the demo measures and writes of it.
#pragma once

#include <meccano/dealii_mesh.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace solver_demo {

inline Eigen::Vector3d to_eigen(const dealii::Point<3>& p) { return {p[0], p[1], p[2]}; }

// A map onto a known surface S: a point of S near p (the one over p, or the closest).
using SurfaceProjection = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

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

// Whether `interface` is a known surface S: every corner of its triangles within `tolerance` of its point
// `project(corner)` on S. The tolerance is relative to the mesh: 5 % of the interface's mean edge length,
// far below the distance to any other surface the demo meets, far above the sag of a fine triangulation
// of S, on which the module puts S_h's vertices.
struct SurfaceMatch {
  double max_deviation = 0.0;  // max |project(p) − p| over the corners (∞ where a corner is excluded)
  double tolerance = 0.0;
  bool matches() const { return max_deviation <= tolerance; }
};
SurfaceMatch match_surface(const meccano::DealiiInterface& interface, const SurfaceProjection& project);

// Angles between the triangles' normals and S's normal `exact_normal(centroid)` (S's normal at the point of S
// nearest the triangle's centroid, or over it), as unoriented lines: a triangle's orientation is a property of
// the file, not of the approximation.
struct NormalError {
  double max_deg = 0.0;
  double mean_deg = 0.0;                 // area-weighted
  std::vector<double> per_triangle_deg;  // in the order of the interface's triangles
};
NormalError normal_error(const meccano::DealiiInterface& interface,
                         const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& exact_normal);

// The triangles as a VTU file (atomic write), corners shared where they coincide, with one value per
// triangle for each field.
using TriangleField = std::pair<std::string, std::vector<double>>;
void write_interface_vtu(const meccano::DealiiInterface& interface, const std::vector<TriangleField>& fields,
                         const std::string& path);

}  // namespace solver_demo
