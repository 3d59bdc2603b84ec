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

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
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

// Floors on a tet's shape (issue 18's targets): every dihedral angle within [min_dihedral_deg,
// max_dihedral_deg] and the equilateral mean ratio at least mean_ratio. 0°, 180° or 0 turn a floor off.
struct ShapeFloors {
  double min_dihedral_deg = 15.0, max_dihedral_deg = 150.0, mean_ratio = 0.40;
  bool angles_off() const { return min_dihedral_deg <= 0.0 && max_dihedral_deg >= 180.0; }
};
// A tet's shape as ratios to the floors, 1 where a floor is just met: per dihedral angle θ (edges 01, 02,
// 03, 12, 13, 23) min(θ / min_dihedral_deg, (180° − θ) / (180° − max_dihedral_deg)), then the equilateral
// mean ratio over mean_ratio (negative for an inverted tet). A floor that is off gives +infinity.
std::array<double, 7> shape_over_floors(const TetPoints& p, const ShapeFloors& floors);
// The smallest of them: below 1 when the tet misses a floor, not positive when it is inverted.
double worst_shape_over_floors(const TetPoints& p, const ShapeFloors& floors);

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
// Thresholds of the low-quality counts.
inline constexpr std::array<double, 3> low_quality_thresholds{0.1, 0.2, 0.3};

struct QualitySummary {
  std::int64_t tets = 0;
  std::int64_t inverted = 0;                        // tets with non-positive (or non-finite) signed volume
  QualityStatistics meccano;                        // mean ratio against the computational counterpart (the paper's)
  QualityStatistics equilateral;                    // mean ratio against the equilateral tet (Gmsh/TetGen's)
  std::array<std::int64_t, 3> equilateral_below{};  // tets below each of low_quality_thresholds
  // Over the non-inverted tets; 0 and 180, the angles of a flat tet, when there are none.
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  QualityHistogram meccano_histogram, equilateral_histogram;
};

// The summary built one tet at a time, for the tets of a TetMesh (summarize_quality) and for tets known
// only by their points (a mesh file's, another mesher's), so that the same tets give the same figures.
// Statistics are updated by Welford's rule and merged by Chan et al.'s: the spread of values that are all
// nearly 1 survives, unlike with a sum of squares.
class QualityAccumulator {
 public:
  // Throws std::invalid_argument if histogram_bins < 1.
  explicit QualityAccumulator(int histogram_bins = 20);
  // A tet's points in positive orientation and, if it has one, its meccano counterpart's; without one
  // its meccano quality is its equilateral one.
  void add(const TetPoints& physical, const TetPoints* computational = nullptr);
  void merge(const QualityAccumulator& other);
  QualitySummary summary() const;

 private:
  struct Moments {  // count, mean, sum of squared deviations and minimum
    std::int64_t count = 0;
    double mean = 0, squared_deviations = 0, min = std::numeric_limits<double>::infinity();

    void add(double q) {
      ++count;
      const double delta = q - mean;
      mean += delta / static_cast<double>(count);
      squared_deviations += delta * (q - mean);
      min = std::min(min, q);
    }
    void merge(const Moments& other);
  };
  void add_quality(double q_meccano, double q_equilateral);

  Moments meccano_, equilateral_;
  std::int64_t inverted_ = 0;
  std::array<std::int64_t, 3> equilateral_below_{};
  double largest_cosine_ = -1.0, smallest_cosine_ = 1.0;  // over the dihedral angles of valid tets
  std::vector<std::int64_t> meccano_bins_, equilateral_bins_;
};

// The summary of tets 0 .. tet_count - 1, add_tet(t, accumulator) adding tet t. Fixed chunks of tets are
// each summed alone, in parallel, and merged in chunk order: bit-identical for any number of threads.
QualitySummary summarize_tet_quality(std::int64_t tet_count,
                                     const std::function<void(std::int64_t, QualityAccumulator&)>& add_tet,
                                     int histogram_bins = 20);

// summarize_tet_quality over the mesh's tets. An empty mesh gives zero statistics.
// Throws std::invalid_argument if histogram_bins < 1.
QualitySummary summarize_quality(const TetMesh& mesh, int histogram_bins = 20);

}  // namespace meccano
