// Quality measures and summaries: dihedral angles of known tets, the untouched meccano (q = 1 against
// its counterpart, Kuhn class values against the equilateral tet), inverted tets counted as 0, agreement
// with a direct serial computation, independence of the thread count, and the histogram CSV.

#include <meccano/error.hpp>
#include <meccano/mesh/bisection.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/quality.hpp>
#include <meccano/report/quality_csv.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <sstream>

namespace meccano {
namespace {

namespace fs = std::filesystem;

// Equilateral mean ratio 12 (3V)^(2/3) / Σ l² of the 3 similarity classes of Kossaczky bisection of a
// unit Kuhn cell, indexed by Kossaczky type: the Kuhn tet (V = 1/6, Σ l² = 10), its child across the
// cell diagonal (V = 1/12, Σ l² = 6.25) and that child's child (V = 1/24, Σ l² = 3.75).
const std::array<double, 3> kuhn_class_quality{12 * std::cbrt(0.25) / 10, 12 * std::cbrt(1.0 / 16) / 6.25,
                                               12 * 0.25 / 3.75};

VertexId vertex_at(const TetMesh& mesh, const Eigen::Vector3d& point) {
  for (VertexId v = 0; v < mesh.num_vertices(); ++v)
    if ((mesh.points[v] - point).norm() < 1e-12) return v;
  ADD_FAILURE() << "no vertex at " << point.transpose();
  return 0;
}

// The summary computed serially, tet by tet, from the public per-tet measures (statistics in long double).
QualitySummary summarize_directly(const TetMesh& mesh, int bins) {
  QualitySummary s;
  s.tets = mesh.num_tets();
  s.meccano_histogram.counts.assign(bins, 0);
  s.equilateral_histogram.counts.assign(bins, 0);
  std::vector<double> meccano, equilateral;
  double min_angle = 180, max_angle = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    const auto p = oriented_points(mesh, t);
    const bool inverted = signed_volume(p[0], p[1], p[2], p[3]) <= 0;
    s.inverted += inverted;
    meccano.push_back(inverted ? 0.0 : mean_ratio_relative(p, oriented_computational_points(mesh, t)));
    equilateral.push_back(inverted ? 0.0 : mean_ratio_equilateral(p));
    ++s.meccano_histogram.counts[std::min(bins - 1, static_cast<int>(meccano.back() * bins))];
    ++s.equilateral_histogram.counts[std::min(bins - 1, static_cast<int>(equilateral.back() * bins))];
    if (inverted) continue;
    for (double angle : dihedral_angles_deg(p)) {
      min_angle = std::min(min_angle, angle);
      max_angle = std::max(max_angle, angle);
    }
  }
  const auto statistics = [](const std::vector<double>& q) {
    const long double n = static_cast<long double>(q.size());
    const long double mean = std::accumulate(q.begin(), q.end(), 0.0L) / n;
    long double squares = 0;
    for (double x : q) squares += (x - mean) * (x - mean);
    return QualityStatistics{*std::min_element(q.begin(), q.end()), static_cast<double>(mean),
                             static_cast<double>(std::sqrt(squares / n))};
  };
  s.meccano = statistics(meccano);
  s.equilateral = statistics(equilateral);
  s.min_dihedral_deg = min_angle;
  s.max_dihedral_deg = max_angle;
  return s;
}

void expect_near(const QualityStatistics& actual, const QualityStatistics& expected, double tolerance) {
  EXPECT_NEAR(actual.min, expected.min, tolerance);
  EXPECT_NEAR(actual.mean, expected.mean, tolerance);
  EXPECT_NEAR(actual.std, expected.std, tolerance);
}

void expect_matches_direct_computation(const QualitySummary& s, const TetMesh& mesh) {
  const QualitySummary direct = summarize_directly(mesh, static_cast<int>(s.meccano_histogram.counts.size()));
  EXPECT_EQ(s.tets, direct.tets);
  EXPECT_EQ(s.inverted, direct.inverted);
  expect_near(s.meccano, direct.meccano, 1e-12);
  expect_near(s.equilateral, direct.equilateral, 1e-12);
  EXPECT_NEAR(s.min_dihedral_deg, direct.min_dihedral_deg, 1e-9);
  EXPECT_NEAR(s.max_dihedral_deg, direct.max_dihedral_deg, 1e-9);
  EXPECT_EQ(s.meccano_histogram.counts, direct.meccano_histogram.counts);
  EXPECT_EQ(s.equilateral_histogram.counts, direct.equilateral_histogram.counts);
}

void expect_equal(const QualitySummary& a, const QualitySummary& b) {
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.inverted, b.inverted);
  for (const auto& [x, y] : {std::pair{a.meccano, b.meccano}, std::pair{a.equilateral, b.equilateral}}) {
    EXPECT_EQ(x.min, y.min);
    EXPECT_EQ(x.mean, y.mean);
    EXPECT_EQ(x.std, y.std);
  }
  EXPECT_EQ(a.min_dihedral_deg, b.min_dihedral_deg);
  EXPECT_EQ(a.max_dihedral_deg, b.max_dihedral_deg);
  EXPECT_EQ(a.meccano_histogram.counts, b.meccano_histogram.counts);
  EXPECT_EQ(a.equilateral_histogram.counts, b.equilateral_histogram.counts);
}

std::int64_t sum(const QualityHistogram& h) {
  return std::accumulate(h.counts.begin(), h.counts.end(), std::int64_t{0});
}

// Moves every node inside the box by a random offset of up to `amplitude` per coordinate.
void perturb_interior_nodes(TetMesh& mesh, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-amplitude, amplitude);
  const Box& box = mesh.meccano.box;
  for (Eigen::Vector3d& x : mesh.points)
    if (((x - box.min).array() > 1e-12).all() && ((box.max - x).array() > 1e-12).all())
      x += Eigen::Vector3d(offset(rng), offset(rng), offset(rng));
}

TEST(DihedralAngles, MatchTheCornerAndRegularTets) {
  const double corner_face = std::acos(1 / std::sqrt(3.0)) * 180 / std::numbers::pi;
  const std::array<double, 6> corner_angles{90, 90, 90, corner_face, corner_face, corner_face};
  const TetPoints corner{Eigen::Vector3d{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const TetPoints mirrored{corner[0], corner[2], corner[1], corner[3]};  // inverted order, same angles
  for (const auto& p : {corner, mirrored}) {
    const auto angles = dihedral_angles_deg(p);
    for (int e = 0; e < 6; ++e) EXPECT_NEAR(angles[e], corner_angles[e], 1e-12) << "edge " << e;
  }
  const TetPoints regular{Eigen::Vector3d{1, 1, 1}, {-1, 1, -1}, {1, -1, -1}, {-1, -1, 1}};
  const double regular_angle = std::acos(1.0 / 3) * 180 / std::numbers::pi;
  for (double angle : dihedral_angles_deg(regular)) EXPECT_NEAR(angle, regular_angle, 1e-12);
  EXPECT_NEAR(mean_ratio_equilateral(regular), 1.0, 1e-15);
}

// The shape ratios: 1 where a tet meets its floors exactly, each angle's ratio from its own dihedral angle,
// +infinity for floors that are off, and not positive for an inverted or flat tet.
TEST(ShapeOverFloors, MeasureEachAngleAndTheMeanRatioAgainstTheirFloors) {
  const double corner_face = std::acos(1 / std::sqrt(3.0)) * 180 / std::numbers::pi;
  const TetPoints corner{Eigen::Vector3d{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const ShapeFloors exact{corner_face, 90.0, mean_ratio_equilateral(corner)};  // the corner's angles: 54.7° and 90°
  for (double ratio : shape_over_floors(corner, exact)) EXPECT_NEAR(ratio, 1.0, 1e-12);

  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  const ShapeFloors floors;
  for (int trial = 0; trial < 20; ++trial) {
    TetPoints p;
    for (auto& x : p) x = {coordinate(rng), coordinate(rng), coordinate(rng)};
    if (signed_volume(p[0], p[1], p[2], p[3]) < 0) std::swap(p[0], p[1]);
    const auto angles = dihedral_angles_deg(p);
    const auto ratios = shape_over_floors(p, floors);
    for (int e = 0; e < 6; ++e)
      EXPECT_NEAR(ratios[e], std::min(angles[e] / 15.0, (180.0 - angles[e]) / 30.0), 1e-12) << "edge " << e;
    EXPECT_NEAR(ratios[6], mean_ratio_equilateral(p) / 0.40, 1e-12);
    EXPECT_EQ(worst_shape_over_floors(p, floors), *std::min_element(ratios.begin(), ratios.end()));
  }

  for (double ratio : shape_over_floors(corner, {0.0, 180.0, 0.0}))
    EXPECT_EQ(ratio, std::numeric_limits<double>::infinity());
  const TetPoints inverted{corner[0], corner[2], corner[1], corner[3]};
  EXPECT_LT(worst_shape_over_floors(inverted, floors), 0.0);
  const TetPoints flat{corner[0], corner[1], corner[2], Eigen::Vector3d{0.3, 0.3, 0.0}};
  EXPECT_LE(worst_shape_over_floors(flat, floors), 0.0);
}

// worst_shape_over_floors takes two arc cosines where shape_over_floors takes six: the same value, to the
// bit, on well-shaped tets, slivers, needles and caps, with either angle floor off.
TEST(ShapeOverFloors, TheWorstRatioIsExactlyTheSmallestOfTheSeven) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0), squash(1e-6, 1.0);
  for (const ShapeFloors& floors : {ShapeFloors{}, ShapeFloors{20.0, 180.0, 0.3}, ShapeFloors{0.0, 140.0, 0.0}}) {
    for (int trial = 0; trial < 2000; ++trial) {
      TetPoints p;
      for (auto& x : p) x = {coordinate(rng), coordinate(rng), coordinate(rng)};
      const int flattened = trial % 4;  // 0: as drawn; else one coordinate (or vertex) squashed
      if (flattened == 1) p[3].z() = p[0].z() + squash(rng) * (p[3].z() - p[0].z());
      if (flattened == 2) p[1] = p[0] + squash(rng) * (p[1] - p[0]);
      if (flattened == 3)
        for (auto& x : p) x.y() *= squash(rng);
      const auto ratios = shape_over_floors(p, floors);
      EXPECT_EQ(worst_shape_over_floors(p, floors), *std::min_element(ratios.begin(), ratios.end())) << trial;
    }
  }
}

TEST(QualitySummary, UntouchedCubeHasMeccanoQualityOneAndKuhnClassValues) {
  std::array<int, 3> rounded{};
  for (int c = 0; c < 3; ++c) rounded[c] = static_cast<int>(std::lround(kuhn_class_quality[c] * 1000));
  EXPECT_EQ(rounded, (std::array<int, 3>{756, 762, 800}));  // the notes' §1.5 figures

  for (int level = 0; level <= 6; ++level) {
    SCOPED_TRACE("level " + std::to_string(level));
    const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, level);
    const QualitySummary s = summarize_quality(mesh);
    EXPECT_EQ(s.tets, mesh.num_tets());
    EXPECT_EQ(s.inverted, 0);
    expect_near(s.meccano, {1, 1, 0}, 1e-12);
    const double q = kuhn_class_quality[level % 3];  // a uniform level holds one class
    expect_near(s.equilateral, {q, q, 0}, 1e-12);
    EXPECT_EQ(s.meccano_histogram.counts.size(), 20u);
    EXPECT_EQ(s.meccano_histogram.counts.back(), s.tets);  // q = 1 goes to the last bin
    EXPECT_EQ(*std::max_element(s.equilateral_histogram.counts.begin(), s.equilateral_histogram.counts.end()), s.tets);
    EXPECT_GE(s.min_dihedral_deg, 45 - 1e-9);  // the bounds of the Kuhn classes
    EXPECT_LE(s.max_dihedral_deg, 120 + 1e-9);
  }
}

TEST(QualitySummary, NonCubicCellsAreTheirOwnCounterparts) {
  for (const Box& box : {Box{{0, 0, 0}, {1, 1.3, 1}}, Box{{-1, 2, 0.5}, {0, 3.3, 1.1}}}) {
    const TetMesh mesh = make_cube_meccano(box, 2);
    const QualitySummary s = summarize_quality(mesh);
    expect_near(s.meccano, {1, 1, 0}, 1e-12);
    EXPECT_EQ(s.meccano_histogram.counts.back(), s.tets);
    EXPECT_LT(s.equilateral.mean, kuhn_class_quality[2]);  // stretched Kuhn tets are worse than cubic ones
  }
}

TEST(QualitySummary, LocallyRefinedCubeHasTheMeanOfItsClassCounts) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 2);
  std::mt19937 rng(7);
  for (int round = 0; round < 6; ++round) {
    std::uniform_int_distribution<TetId> pick(0, mesh.num_tets() - 1);
    std::vector<TetId> marked;
    for (int i = 0; i < 20; ++i) marked.push_back(pick(rng));
    refine_marked(mesh, marked);
  }
  std::array<std::int64_t, 3> class_count{};
  for (TetId t = 0; t < mesh.num_tets(); ++t) ++class_count[mesh.kinds[t].type()];
  ASSERT_GE(std::count_if(class_count.begin(), class_count.end(), [](std::int64_t n) { return n > 0; }), 2);
  double mean = 0, variance = 0;
  const auto n = static_cast<double>(mesh.num_tets());
  for (int c = 0; c < 3; ++c) mean += static_cast<double>(class_count[c]) * kuhn_class_quality[c] / n;
  for (int c = 0; c < 3; ++c)
    variance += static_cast<double>(class_count[c]) * std::pow(kuhn_class_quality[c] - mean, 2) / n;
  double lowest = 1;
  for (int c = 0; c < 3; ++c)
    if (class_count[c] > 0) lowest = std::min(lowest, kuhn_class_quality[c]);

  const QualitySummary s = summarize_quality(mesh);
  expect_near(s.meccano, {1, 1, 0}, 1e-12);
  expect_near(s.equilateral, {lowest, mean, std::sqrt(variance)}, 1e-12);
}

TEST(QualitySummary, InvertedTetsCountAsZero) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 3);
  mesh.points[vertex_at(mesh, {0.5, 0.5, 0.5})] = {1.4, 0.5, 0.5};  // through the xmax side
  const QualitySummary s = summarize_quality(mesh, 10);
  EXPECT_GE(s.inverted, 1);
  EXPECT_EQ(s.meccano.min, 0.0);
  EXPECT_EQ(s.equilateral.min, 0.0);
  EXPECT_GE(s.meccano_histogram.counts[0], s.inverted);
  EXPECT_EQ(sum(s.meccano_histogram), s.tets);
  EXPECT_EQ(sum(s.equilateral_histogram), s.tets);
  EXPECT_GT(s.min_dihedral_deg, 0.0);
  EXPECT_LT(s.max_dihedral_deg, 180.0);

  expect_matches_direct_computation(s, mesh);
}

TEST(QualitySummary, AllInvertedOrEmptyMeshesReportZeroQualityAndFlatAngles) {
  TetMesh mirrored = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 1);
  for (Eigen::Vector3d& x : mirrored.points) x.x() = -x.x();
  const QualitySummary s = summarize_quality(mirrored, 5);
  EXPECT_EQ(s.inverted, s.tets);
  expect_near(s.meccano, {0, 0, 0}, 0);
  expect_near(s.equilateral, {0, 0, 0}, 0);
  EXPECT_EQ(s.meccano_histogram.counts, (std::vector<std::int64_t>{s.tets, 0, 0, 0, 0}));
  EXPECT_EQ(s.min_dihedral_deg, 0.0);
  EXPECT_EQ(s.max_dihedral_deg, 180.0);

  const QualitySummary empty = summarize_quality(TetMesh{}, 3);
  EXPECT_EQ(empty.tets, 0);
  expect_near(empty.meccano, {0, 0, 0}, 0);
  EXPECT_EQ(empty.equilateral_histogram.counts, (std::vector<std::int64_t>{0, 0, 0}));
  EXPECT_THROW(summarize_quality(mirrored, 0), std::invalid_argument);
}

TEST(QualitySummary, IsIdenticalForAnyThreadCountAndMatchesADirectComputation) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 12);  // 49 152 tets, several chunks
  perturb_interior_nodes(mesh, 0.02, 3);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const QualitySummary one = summarize_quality(mesh, 7);
  for (int n : {2, 3, 8}) {
    SCOPED_TRACE(std::to_string(n) + " threads");
    omp_set_num_threads(n);
    expect_equal(summarize_quality(mesh, 7), one);
  }
  omp_set_num_threads(threads);
  EXPECT_GT(one.inverted, 0);  // the perturbation is large enough to fold some tets
  EXPECT_LT(one.inverted, one.tets / 10);
  expect_matches_direct_computation(one, mesh);
}

class HistogramCsv : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("meccano-quality-" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

using Labelled = std::vector<std::pair<std::string, const QualitySummary*>>;

std::string read_text(const fs::path& file) {
  std::ostringstream text;
  text << std::ifstream(file).rdbuf();
  return text.str();
}

TEST_F(HistogramCsv, HasBinEdgesAndTwoColumnsPerLabel) {
  QualitySummary before, after;
  before.meccano_histogram.counts = {3, 1, 0, 0};
  before.equilateral_histogram.counts = {0, 2, 2, 0};
  after.meccano_histogram.counts = {0, 0, 1, 3};
  after.equilateral_histogram.counts = {0, 0, 4, 0};
  const Labelled labelled{{"before_smoothing", &before}, {"after-smoothing", &after}};
  const fs::path file = dir_ / "hist.csv";
  write_quality_histograms_csv(file, labelled);
  EXPECT_EQ(read_text(file),
            "bin_low,bin_high,before_smoothing_meccano,before_smoothing_equilateral,after-smoothing_meccano,"
            "after-smoothing_equilateral\n"
            "0,0.25,3,0,0,0\n"
            "0.25,0.5,1,2,0,0\n"
            "0.5,0.75,0,2,1,4\n"
            "0.75,1,0,0,3,0\n");
}

TEST_F(HistogramCsv, ErrorsNameTheFileAndLeaveNoFile) {
  const QualitySummary twenty = summarize_quality(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0));
  const QualitySummary ten = summarize_quality(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), 10);
  const auto message = [&](const fs::path& file, const Labelled& labelled) {
    try {
      write_quality_histograms_csv(file, labelled);
    } catch (const std::exception& error) {
      return std::string(error.what());
    }
    return std::string("nothing thrown");
  };
  const fs::path file = dir_ / "hist.csv";
  EXPECT_NE(message(file, {{"a", &twenty}, {"b", &ten}}).find(file.string()), std::string::npos);
  EXPECT_NE(message(file, {{"a,b", &twenty}}).find("label 'a,b'"), std::string::npos);
  EXPECT_NE(message(file, {}).find(file.string()), std::string::npos);
  EXPECT_FALSE(fs::exists(file));

  const fs::path unwritable = dir_ / "missing" / "hist.csv";
  EXPECT_THROW(write_quality_histograms_csv(unwritable, Labelled{{"a", &twenty}}), InputError);
  EXPECT_NE(message(unwritable, {{"a", &twenty}}).find(unwritable.string()), std::string::npos);
}

}  // namespace
}  // namespace meccano
