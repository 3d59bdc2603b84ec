// Element quality, measured two ways (DEVELOPERS.md, "Standards"):
//   - mean ratio against the element's computational (meccano) counterpart: the paper's measure,
//     q = 3 |σ|^(2/3) / ||S||_F^2 with S = A_physical · A_computational^-1 and σ = det S; q = 1 for a
//     tet that is a scaled, rotated copy of its counterpart;
//   - mean ratio against an equilateral tet, q = 12 (3V)^(2/3) / Σ l_i^2, comparable with Gmsh's ICN
//     and TetGen's figures.
// Both are signed: negative for an inverted tet. Dihedral angles are in degrees.
// Point arguments are in positive orientation order (TetMesh::oriented_tet).
#pragma once

#include <meccano/tet_mesh.hpp>

#include <Eigen/Core>

#include <array>

namespace meccano {

using TetPoints = std::array<Eigen::Vector3d, 4>;

double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d);
double mean_ratio_equilateral(const TetPoints& p);
double mean_ratio_relative(const TetPoints& physical, const TetPoints& computational);
std::array<double, 6> dihedral_angles_deg(const TetPoints& p);

// Per-tet helpers on a mesh (positively oriented order; computational points in cell units).
TetPoints oriented_points(const TetMesh& mesh, TetId t);
TetPoints oriented_computational_points(const TetMesh& mesh, TetId t);

}  // namespace meccano
