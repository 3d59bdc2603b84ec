#include <meccano/quality.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace meccano {
namespace {

Eigen::Matrix3d edge_matrix(const TetPoints& p) {
  Eigen::Matrix3d a;
  a << p[1] - p[0], p[2] - p[0], p[3] - p[0];
  return a;
}

double signed_mean_ratio(double determinant, double frobenius_squared) {
  if (frobenius_squared <= 0.0) return 0.0;
  const double magnitude = 3.0 * std::cbrt(determinant * determinant) / frobenius_squared;
  return determinant < 0.0 ? -magnitude : magnitude;
}

}  // namespace

double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double mean_ratio_equilateral(const TetPoints& p) {
  // The closed form of 3|σ|^(2/3)/||S||^2 for S = A W^-1, W the unit equilateral tet.
  double sum_squared_edges = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) sum_squared_edges += (p[i] - p[j]).squaredNorm();
  const double volume = signed_volume(p[0], p[1], p[2], p[3]);
  if (sum_squared_edges <= 0.0) return 0.0;
  const double magnitude = 12.0 * std::cbrt(9.0 * volume * volume) / sum_squared_edges;
  return volume < 0.0 ? -magnitude : magnitude;
}

double mean_ratio_relative(const TetPoints& physical, const TetPoints& computational) {
  const Eigen::Matrix3d s = edge_matrix(physical) * edge_matrix(computational).inverse();
  return signed_mean_ratio(s.determinant(), s.squaredNorm());
}

std::array<double, 6> dihedral_angles_deg(const TetPoints& p) {
  // The dihedral angle at edge (i, j) is the angle between the two faces containing it, measured
  // inside the tet: pi minus the angle between their outward normals.
  static constexpr std::array<std::array<int, 4>, 6> edges{
      {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}}};
  std::array<double, 6> angles{};
  for (int e = 0; e < 6; ++e) {
    const auto [i, j, k, l] = edges[e];
    const Eigen::Vector3d axis = (p[j] - p[i]).normalized();
    Eigen::Vector3d u = p[k] - p[i];
    Eigen::Vector3d w = p[l] - p[i];
    u -= u.dot(axis) * axis;
    w -= w.dot(axis) * axis;
    const double cosine = std::clamp(u.dot(w) / (u.norm() * w.norm()), -1.0, 1.0);
    angles[e] = std::acos(cosine) * 180.0 / std::numbers::pi;
  }
  return angles;
}

TetPoints oriented_points(const TetMesh& mesh, TetId t) {
  const auto v = mesh.oriented_tet(t);
  return {mesh.points[v[0]], mesh.points[v[1]], mesh.points[v[2]], mesh.points[v[3]]};
}

TetPoints oriented_computational_points(const TetMesh& mesh, TetId t) {
  const auto v = mesh.oriented_tet(t);
  TetPoints p;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) p[i][k] = static_cast<double>(mesh.grid[v[i]][k]) / static_cast<double>(grid_cell);
  return p;
}

}  // namespace meccano
