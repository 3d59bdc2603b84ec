// Element quality, measured two ways (notes §4.1):
//   - mean ratio against the element's computational (meccano) counterpart: the paper's measure,
//     q = 3 |σ|^(2/3) / ||S||_F^2 with S = A_physical · A_computational^-1 and σ = det S; q = 1 for a
//     tet that is a scaled, rotated copy of its counterpart;
//   - mean ratio against an equilateral tet, q = 12 (3V)^(2/3) / Σ l_i^2, comparable with Gmsh's ICN
//     and TetGen's figures.
// Both are signed: negative for an inverted tet. Dihedral angles are in degrees.
// Point arguments are in positive orientation order (TetMesh::oriented_tet).
//
// Mesh summaries follow the authors' SUS code (notes §4.4): an inverted tet (signed volume not
// positive, or not finite) counts as quality 0 in the statistics and in histogram bin 0.
#pragma once

#include <meccano/mesh/tet_mesh.hpp>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace meccano {

using TetPoints = std::array<Eigen::Vector3d, 4>;

double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d);
double mean_ratio_equilateral(const TetPoints& p);
// Its cube, 15552 V^2 / (Σ l_i^2)^3 with the sign of V: the same order without a cube root, for code
// that only compares qualities.
double mean_ratio_equilateral_cubed(const TetPoints& p);
double mean_ratio_relative(const TetPoints& physical, const TetPoints& computational);
std::array<double, 6> dihedral_angles_deg(const TetPoints& p);

// Per-tet helpers on a mesh, in positively oriented order. The computational points are the undeformed
// meccano positions in physical units (MeccanoGrid::to_physical), so that an untouched tet is its own
// counterpart (q = 1) even when the meccano cells are not cubes.
TetPoints oriented_points(const TetMesh& mesh, TetId t);
TetPoints oriented_computational_points(const TetMesh& mesh, TetId t);
// The paper's measure of tet t: the mean ratio against its meccano counterpart, or against the
// equilateral tet for a remeshed tet (TetKind::bisectable), which has no counterpart.
double mean_ratio_meccano(const TetMesh& mesh, TetId t);

// A tet is inverted when its physical volume, in its positive orientation, is not positive (flat counts).
bool is_inverted(const TetMesh& mesh, TetId t);
std::int64_t count_inverted(const TetMesh& mesh);

struct QualityStatistics {
  double min = 0, mean = 0, std = 0;  // over all tets; std is the population standard deviation
};
struct QualityHistogram {
  std::vector<std::int64_t> counts;  // bins of width 1/counts.size() over [0, 1]; q = 1 is in the last
};
struct QualitySummary {
  std::int64_t tets = 0;
  std::int64_t inverted = 0;      // tets with non-positive (or non-finite) signed volume
  QualityStatistics meccano;      // mean ratio against the computational counterpart (the paper's)
  QualityStatistics equilateral;  // mean ratio against the equilateral tet (Gmsh/TetGen's)
  // Over the non-inverted tets; 0 and 180, the angles of a flat tet, when there are none.
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  QualityHistogram meccano_histogram, equilateral_histogram;
};

// Bit-identical for any number of OpenMP threads. An empty mesh gives zero statistics.
// Throws std::invalid_argument if histogram_bins < 1.
QualitySummary summarize_quality(const TetMesh& mesh, int histogram_bins = 20);

}  // namespace meccano
