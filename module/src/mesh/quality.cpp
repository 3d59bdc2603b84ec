#include <meccano/mesh/quality.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

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

// The dihedral angle at edge (i, j) is pi minus the angle between the outward normals of the two faces
// containing the edge, the faces opposite the other two vertices. Flipping every normal (an inverted tet)
// leaves the products unchanged; a degenerate face gives NaN.
std::array<double, 6> dihedral_cosines(const TetPoints& p) {
  static constexpr std::array<std::array<int, 2>, 6> faces_at_edge{
      {{2, 3}, {1, 3}, {1, 2}, {0, 3}, {0, 2}, {0, 1}}};  // edges 01, 02, 03, 12, 13, 23
  std::array<Eigen::Vector3d, 4> normals;
  Eigen::Array4d squared_norms;
  for (int f = 0; f < 4; ++f) {
    const auto [a, b, c] = face_vertices[f];
    normals[f] = (p[b] - p[a]).cross(p[c] - p[a]);
    squared_norms[f] = normals[f].squaredNorm();
  }
  const Eigen::Array4d inverse_norms = squared_norms.sqrt().inverse();  // packed: ~10% faster per tet
  std::array<double, 6> cosines{};
  for (int e = 0; e < 6; ++e) {
    const auto [k, l] = faces_at_edge[e];
    cosines[e] = std::clamp(-normals[k].dot(normals[l]) * inverse_norms[k] * inverse_norms[l], -1.0, 1.0);
  }
  return cosines;
}

double degrees_from_cosine(double cosine) { return std::acos(cosine) * 180.0 / std::numbers::pi; }

}  // namespace

double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

namespace {
double sum_of_squared_edges(const TetPoints& p) {
  double sum = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) sum += (p[i] - p[j]).squaredNorm();
  return sum;
}
}  // namespace

double mean_ratio_equilateral(const TetPoints& p) {
  // The closed form of 3|σ|^(2/3)/||S||^2 for S = A W^-1, W the unit equilateral tet.
  const double sum_squared_edges = sum_of_squared_edges(p);
  const double volume = signed_volume(p[0], p[1], p[2], p[3]);
  if (sum_squared_edges <= 0.0) return 0.0;
  const double magnitude = 12.0 * std::cbrt(9.0 * volume * volume) / sum_squared_edges;
  return volume < 0.0 ? -magnitude : magnitude;
}

double mean_ratio_equilateral_cubed(const TetPoints& p) {
  const double sum_squared_edges = sum_of_squared_edges(p);
  const double volume = signed_volume(p[0], p[1], p[2], p[3]);
  if (sum_squared_edges <= 0.0) return 0.0;
  return 15552.0 * volume * std::abs(volume) / (sum_squared_edges * sum_squared_edges * sum_squared_edges);
}

double mean_ratio_relative(const TetPoints& physical, const TetPoints& computational) {
  const Eigen::Matrix3d s = edge_matrix(physical) * edge_matrix(computational).inverse();
  return signed_mean_ratio(s.determinant(), s.squaredNorm());
}

std::array<double, 6> dihedral_angles_deg(const TetPoints& p) {
  std::array<double, 6> angles = dihedral_cosines(p);
  for (double& angle : angles) angle = degrees_from_cosine(angle);
  return angles;
}

std::array<double, 7> shape_over_floors(const TetPoints& p, const ShapeFloors& floors) {
  constexpr double off = std::numeric_limits<double>::infinity();
  const double below = floors.min_dihedral_deg > 0.0 ? 1.0 / floors.min_dihedral_deg : 0.0;
  const double above = floors.max_dihedral_deg < 180.0 ? 1.0 / (180.0 - floors.max_dihedral_deg) : 0.0;
  std::array<double, 7> ratios{};
  const std::array<double, 6> cosines = dihedral_cosines(p);
  for (int e = 0; e < 6; ++e) {
    const double angle = degrees_from_cosine(cosines[e]);
    ratios[e] = std::isnan(angle)
                    ? 0.0  // a degenerate face
                    : std::min(below > 0.0 ? angle * below : off, above > 0.0 ? (180.0 - angle) * above : off);
  }
  ratios[6] = floors.mean_ratio > 0.0 ? mean_ratio_equilateral(p) / floors.mean_ratio : off;
  return ratios;
}

double worst_shape_over_floors(const TetPoints& p, const ShapeFloors& floors) {
  // The arc cosine decreases, so the smallest angle's ratio comes from the largest cosine and the largest
  // angle's from the smallest: two arc cosines instead of shape_over_floors' six, the same minimum (the
  // whole-mesh scans of the improvement call this on every tet).
  constexpr double off = std::numeric_limits<double>::infinity();
  const std::array<double, 6> cosines = dihedral_cosines(p);
  double angles = 0.0;  // a degenerate face
  if (std::ranges::none_of(cosines, [](double c) { return std::isnan(c); })) {
    const auto [smallest, largest] = std::ranges::minmax(cosines);
    angles =
        std::min(floors.min_dihedral_deg > 0.0 ? degrees_from_cosine(largest) * (1.0 / floors.min_dihedral_deg) : off,
                 floors.max_dihedral_deg < 180.0
                     ? (180.0 - degrees_from_cosine(smallest)) * (1.0 / (180.0 - floors.max_dihedral_deg))
                     : off);
  }
  return std::min(angles, floors.mean_ratio > 0.0 ? mean_ratio_equilateral(p) / floors.mean_ratio : off);
}

TetPoints oriented_points(const TetMesh& mesh, TetId t) {
  const auto v = mesh.oriented_tet(t);
  return {mesh.points[v[0]], mesh.points[v[1]], mesh.points[v[2]], mesh.points[v[3]]};
}

bool is_inverted(const TetMesh& mesh, TetId t) {
  const auto p = oriented_points(mesh, t);
  return signed_volume(p[0], p[1], p[2], p[3]) <= 0.0;
}

std::int64_t count_inverted(const TetMesh& mesh) {
  std::int64_t inverted = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t) inverted += is_inverted(mesh, t);
  return inverted;
}

TetPoints oriented_computational_points(const TetMesh& mesh, TetId t) {
  const auto v = mesh.oriented_tet(t);
  const MeccanoGrid& m = mesh.meccano;
  return {m.to_physical(mesh.grid[v[0]]), m.to_physical(mesh.grid[v[1]]), m.to_physical(mesh.grid[v[2]]),
          m.to_physical(mesh.grid[v[3]])};
}

double mean_ratio_meccano(const TetMesh& mesh, TetId t) {
  const TetPoints p = oriented_points(mesh, t);
  return mesh.bisectable(t) ? mean_ratio_relative(p, oriented_computational_points(mesh, t))
                            : mean_ratio_equilateral(p);
}

void QualityAccumulator::Moments::merge(const Moments& other) {
  if (other.count == 0) return;
  if (count == 0) {
    *this = other;
    return;
  }
  const auto total = static_cast<double>(count + other.count);
  const double delta = other.mean - mean;
  mean += delta * static_cast<double>(other.count) / total;
  squared_deviations +=
      other.squared_deviations + delta * delta * static_cast<double>(count) * static_cast<double>(other.count) / total;
  min = std::min(min, other.min);
  count += other.count;
}

QualityAccumulator::QualityAccumulator(int histogram_bins) {
  if (histogram_bins < 1)
    throw std::invalid_argument("summarize_quality: " + std::to_string(histogram_bins) + " histogram bins");
  meccano_bins_.assign(static_cast<std::size_t>(histogram_bins), 0);
  equilateral_bins_.assign(static_cast<std::size_t>(histogram_bins), 0);
}

void QualityAccumulator::add(const TetPoints& p, const TetPoints* computational) {
  const double volume = signed_volume(p[0], p[1], p[2], p[3]);
  if (!(volume > 0.0 && std::isfinite(volume))) {
    ++inverted_;
    add_quality(0.0, 0.0);
    return;
  }
  // Clamped because rounding may flip the sign of a nearly flat tet's determinant.
  const double q_equilateral = std::max(0.0, mean_ratio_equilateral(p));
  add_quality(computational ? std::max(0.0, mean_ratio_relative(p, *computational)) : q_equilateral, q_equilateral);
  for (double cosine : dihedral_cosines(p)) {
    largest_cosine_ = std::max(largest_cosine_, cosine);
    smallest_cosine_ = std::min(smallest_cosine_, cosine);
  }
}

void QualityAccumulator::add_quality(double q_meccano, double q_equilateral) {
  const auto bins = static_cast<int>(meccano_bins_.size());
  const auto bin_of = [&](double q) {
    return static_cast<std::size_t>(std::min(static_cast<int>(q * bins), bins - 1));
  };
  meccano_.add(q_meccano);
  equilateral_.add(q_equilateral);
  ++meccano_bins_[bin_of(q_meccano)];
  ++equilateral_bins_[bin_of(q_equilateral)];
  for (std::size_t k = 0; k < low_quality_thresholds.size(); ++k)
    equilateral_below_[k] += q_equilateral < low_quality_thresholds[k];
}

void QualityAccumulator::merge(const QualityAccumulator& other) {
  meccano_.merge(other.meccano_);
  equilateral_.merge(other.equilateral_);
  inverted_ += other.inverted_;
  for (std::size_t k = 0; k < equilateral_below_.size(); ++k) equilateral_below_[k] += other.equilateral_below_[k];
  largest_cosine_ = std::max(largest_cosine_, other.largest_cosine_);
  smallest_cosine_ = std::min(smallest_cosine_, other.smallest_cosine_);
  for (std::size_t b = 0; b < meccano_bins_.size(); ++b) {
    meccano_bins_[b] += other.meccano_bins_[b];
    equilateral_bins_[b] += other.equilateral_bins_[b];
  }
}

QualitySummary QualityAccumulator::summary() const {
  QualitySummary summary;
  summary.tets = meccano_.count;
  summary.inverted = inverted_;
  const auto statistics = [](const Moments& m) {
    if (m.count == 0) return QualityStatistics{};
    return QualityStatistics{m.min, m.mean, std::sqrt(m.squared_deviations / static_cast<double>(m.count))};
  };
  summary.meccano = statistics(meccano_);
  summary.equilateral = statistics(equilateral_);
  summary.equilateral_below = equilateral_below_;
  const bool any_valid = summary.inverted < summary.tets;
  summary.min_dihedral_deg = any_valid ? degrees_from_cosine(largest_cosine_) : 0.0;
  summary.max_dihedral_deg = any_valid ? degrees_from_cosine(smallest_cosine_) : 180.0;
  summary.meccano_histogram.counts = meccano_bins_;
  summary.equilateral_histogram.counts = equilateral_bins_;
  return summary;
}

QualitySummary summarize_tet_quality(std::int64_t tet_count,
                                     const std::function<void(std::int64_t, QualityAccumulator&)>& add_tet,
                                     int histogram_bins) {
  // Fixed chunks, each summed alone and merged in chunk order: the rounding, hence the result, does not
  // depend on the number of threads or on which thread took which chunk.
  constexpr std::int64_t chunk_tets = 4096;
  const std::int64_t chunks = (tet_count + chunk_tets - 1) / chunk_tets;
  std::vector<QualityAccumulator> partial(static_cast<std::size_t>(chunks), QualityAccumulator(histogram_bins));
#pragma omp parallel for schedule(dynamic)
  for (std::int64_t c = 0; c < chunks; ++c) {
    QualityAccumulator chunk(histogram_bins);  // local: threads do not share cache lines while summing
    const std::int64_t end = std::min(tet_count, (c + 1) * chunk_tets);
    for (std::int64_t t = c * chunk_tets; t < end; ++t) add_tet(t, chunk);
    partial[static_cast<std::size_t>(c)] = std::move(chunk);
  }
  QualityAccumulator total(histogram_bins);
  for (const auto& chunk : partial) total.merge(chunk);
  return total.summary();
}

QualitySummary summarize_quality(const TetMesh& mesh, int histogram_bins) {
  return summarize_tet_quality(
      mesh.num_tets(),
      [&](std::int64_t t, QualityAccumulator& quality) {
    const auto tet = static_cast<TetId>(t);
    if (mesh.bisectable(tet)) {
      const TetPoints computational = oriented_computational_points(mesh, tet);
      quality.add(oriented_points(mesh, tet), &computational);
    } else {
      quality.add(oriented_points(mesh, tet));
    }
      },
      histogram_bins);
}

}  // namespace meccano
