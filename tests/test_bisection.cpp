// Kossaczky bisection on the cube meccano: conformity, exact volume, orientation, similarity classes,
// local refinement cost, edge splitting and face-tag inheritance.

#include <meccano/error.hpp>
#include <meccano/mesh/bisection.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/mesh/quality.hpp>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

namespace meccano {
namespace {

const std::vector<Box> test_boxes{
    {{0, 0, 0}, {1, 1, 1}},
    {{-1, 2, 0.5}, {1, 3, 1.5}},  // 2 x 1 x 1 cells
    {{0, 0, 0}, {1, 1.3, 0.6}},   // 2 x 2 x 1 cells of unequal shape
    {{0, 0, 0}, {3, 2, 1}},
};

void expect_valid(const TetMesh& mesh) {
  const auto report = verify_mesh(mesh);
  ASSERT_TRUE(report.ok()) << report.summary();
}

// Computational points in cell units, where every cell holds the Kuhn shapes whatever the box's aspect.
TetPoints cell_unit_points(const TetMesh& mesh, TetId t) {
  const auto v = mesh.oriented_tet(t);
  TetPoints p;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) p[i][k] = static_cast<double>(mesh.grid[v[i]][k]) / static_cast<double>(grid_cell);
  return p;
}

// Sorted edge lengths in computational space, scaled by the longest: equal for similar tets.
std::array<double, 6> shape_signature(const TetMesh& mesh, TetId t) {
  const auto p = cell_unit_points(mesh, t);
  std::array<double, 6> lengths{};
  int e = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) lengths[e++] = (p[i] - p[j]).norm();
  std::sort(lengths.begin(), lengths.end());
  for (double& l : lengths) l = std::round(l / lengths[5] * 1e9) / 1e9;
  return lengths;
}

std::map<std::array<double, 6>, double> similarity_classes(const TetMesh& mesh) {
  std::map<std::array<double, 6>, double> classes;  // signature -> equilateral mean ratio
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    classes.emplace(shape_signature(mesh, t), mean_ratio_equilateral(cell_unit_points(mesh, t)));
  return classes;
}

void expect_kuhn_classes(const std::map<std::array<double, 6>, double>& classes) {
  std::set<int> qualities;
  for (const auto& [signature, q] : classes) qualities.insert(static_cast<int>(std::lround(q * 1000)));
  EXPECT_EQ(classes.size(), 3u);
  EXPECT_EQ(qualities, (std::set<int>{756, 762, 800}));
}

void expect_dihedral_angles_within_kuhn_bounds(const TetMesh& mesh) {
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (double angle : dihedral_angles_deg(cell_unit_points(mesh, t))) {
      ASSERT_GE(angle, 45.0 - 1e-9) << "tet " << t;
      ASSERT_LE(angle, 120.0 + 1e-9) << "tet " << t;
    }
}

// Random marking: batches of random tets, to exercise the recursive closure.
void refine_randomly(TetMesh& mesh, std::mt19937& rng, int batches, int per_batch) {
  for (int b = 0; b < batches; ++b) {
    std::uniform_int_distribution<TetId> pick(0, mesh.num_tets() - 1);
    std::vector<TetId> marked;
    for (int i = 0; i < per_batch; ++i) marked.push_back(pick(rng));
    const auto before = mesh.num_tets();
    const auto bisections = refine_marked(mesh, marked);
    EXPECT_EQ(mesh.num_tets(), before + bisections);
    EXPECT_GE(bisections, 1);
  }
}

TEST(CubeMeccano, CellsAreAsCloseToCubesAsPossible) {
  EXPECT_EQ(cells_for_box({{0, 0, 0}, {2, 1, 1}}), (std::array<int, 3>{2, 1, 1}));
  EXPECT_EQ(cells_for_box({{0, 0, 0}, {1, 1, 1}}), (std::array<int, 3>{1, 1, 1}));
  EXPECT_EQ(cells_for_box({{0, 0, 0}, {3, 2, 1}}), (std::array<int, 3>{3, 2, 1}));
  EXPECT_EQ(cells_for_box({{0, 0, 0}, {1, 1.3, 0.6}}), (std::array<int, 3>{2, 2, 1}));
  EXPECT_THROW(cells_for_box({{0, 0, 0}, {1, 0, 1}}), InputError);
  try {
    cells_for_box({{0, 0, 0}, {2000, 1, 1}});
    ADD_FAILURE() << "no error for a 2000:1 box";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("longer along x than its shortest side"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, {0, 1, 1}), InputError);
  EXPECT_THROW(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, -1), InputError);
}

TEST(CubeMeccano, UniformLevelsHaveSixTimesTwoToTheLevelTetsPerCellAndStayValid) {
  for (const Box& box : test_boxes) {
    const auto cells = cells_for_box(box);
    const std::int64_t cell_count = std::int64_t{cells[0]} * cells[1] * cells[2];
    for (int level : {0, 1, 2, 3, 5, 8}) {
      const TetMesh mesh = make_cube_meccano(box, level);
      EXPECT_EQ(mesh.num_tets(), (6 * cell_count) << level);
      expect_valid(mesh);
    }
  }
}

TEST(CubeMeccano, UniformRefinementKeepsThreeSimilarityClassesAndKuhnAngles) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 0);
  std::map<std::array<double, 6>, double> all_classes;
  for (int level = 0; level <= 9; ++level) {
    const auto classes = similarity_classes(mesh);
    EXPECT_EQ(classes.size(), 1u) << "uniform level " << level << " mixes shapes";
    all_classes.insert(classes.begin(), classes.end());
    expect_dihedral_angles_within_kuhn_bounds(mesh);
    // The refinement edge v0-v1 is the unique longest edge (so Kossaczky = longest-edge bisection).
    for (TetId t = 0; t < mesh.num_tets(); ++t) {
      const auto signature = shape_signature(mesh, t);
      ASSERT_LT(signature[4], signature[5]);
      const auto& v = mesh.tets[t];
      Eigen::Vector3d d;
      for (int k = 0; k < 3; ++k) d[k] = static_cast<double>(mesh.grid[v[0]][k] - mesh.grid[v[1]][k]);
      const auto p = cell_unit_points(mesh, t);
      double longest = 0;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (p[i] - p[j]).norm());
      ASSERT_NEAR(d.norm() / static_cast<double>(grid_cell), longest, 1e-12);
    }
    refine_uniformly(mesh, 1);
  }
  expect_kuhn_classes(all_classes);
}

TEST(Bisection, RandomLocalRefinementStaysConformingWithThreeClasses) {
  for (std::size_t b = 0; b < test_boxes.size(); ++b)
    for (unsigned seed : {1u, 2u, 3u}) {
      SCOPED_TRACE("box " + std::to_string(b) + " seed " + std::to_string(seed));
      std::mt19937 rng(seed);
      TetMesh mesh = make_cube_meccano(test_boxes[b], 1);
      for (int round = 0; round < 5; ++round) {
        refine_randomly(mesh, rng, 40, 25);  // 1000 random marks per round
        expect_valid(mesh);
      }
      expect_kuhn_classes(similarity_classes(mesh));
      expect_dihedral_angles_within_kuhn_bounds(mesh);
    }
}

TEST(Bisection, LevelCountsTheBisectionsFromTheMacroTet) {
  for (std::size_t b = 0; b < test_boxes.size(); ++b) {
    SCOPED_TRACE("box " + std::to_string(b));
    TetMesh mesh = make_cube_meccano(test_boxes[b], 0);
    std::vector<int> bisections(mesh.tets.size(), 0);  // child 0 keeps its parent's index
    std::mt19937 rng(static_cast<unsigned>(b + 5));
    for (int round = 0; round < 40; ++round) {
      std::vector<TetId> marked;
      for (int k = 0; k < 10; ++k) marked.push_back(std::uniform_int_distribution<TetId>(0, mesh.num_tets() - 1)(rng));
      refine_marked(mesh, marked, [&](TetId parent, TetId) { bisections.push_back(++bisections[parent]); });
    }
    ASSERT_EQ(bisections.size(), mesh.tets.size());
    EXPECT_GT(*std::max_element(bisections.begin(), bisections.end()), 6);
    for (TetId t = 0; t < mesh.num_tets(); ++t) ASSERT_EQ(mesh.level(t), bisections[t]) << "tet " << t;
  }
}

TEST(CubeMeccano, LongestEdgeAtALevelIsTheLongestEdgeOfItsTets) {
  for (std::size_t b = 0; b < test_boxes.size(); ++b) {
    SCOPED_TRACE("box " + std::to_string(b));
    TetMesh mesh = make_cube_meccano(test_boxes[b], 0);
    for (int level = 0; level <= 7; ++level) {
      double longest = 0.0;
      for (TetId t = 0; t < mesh.num_tets(); ++t) longest = std::max(longest, mesh.longest_edge(t));
      EXPECT_NEAR(longest_edge_at_level(mesh.meccano, level), longest, 1e-12 * longest) << "level " << level;
      refine_uniformly(mesh, 1);
    }
  }
}

TEST(CubeMeccano, LevelForResolutionIsTheCoarsestLevelShorterThanIt) {
  const TetMesh mesh = make_cube_meccano(test_boxes[2], 0);  // cells of unequal sides
  for (double resolution : {2.0, 0.9, 0.5, 0.31, 0.3, 0.1, 0.0417, 0.03125, 1e-3}) {
    const int level = level_for_resolution(mesh.meccano, resolution);
    EXPECT_LT(longest_edge_at_level(mesh.meccano, level), resolution) << resolution;
    if (level > 0) {
      EXPECT_GE(longest_edge_at_level(mesh.meccano, level - 1), resolution) << resolution;
    }
  }
  EXPECT_THROW(level_for_resolution(mesh.meccano, 0.0), InputError);
  EXPECT_THROW(level_for_resolution(mesh.meccano, 1e-12), InputError);  // beyond the computational grid
}

TEST(Bisection, TrackedOrientationMatchesGeometryAndBothSignsOccur) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 4);
  int negative = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    ASSERT_EQ(grid_orientation(mesh, t) < 0, mesh.kinds[t].negative());
    negative += mesh.kinds[t].negative();
  }
  EXPECT_GT(negative, 0);
  EXPECT_LT(negative, mesh.num_tets());
}

TEST(Bisection, RefiningTowardAPointCostsLinearlyInTheLevels) {
  const Eigen::Vector3d target(0.3141, 0.2718, 0.5772);
  auto tets_after = [&](int rounds) {
    TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
    for (int r = 0; r < rounds; ++r) {
      std::vector<TetId> marked;
      for (TetId t = 0; t < mesh.num_tets(); ++t) {
        const auto p = mesh.tet_points(t);
        Eigen::Vector3d lo = p[0], hi = p[0];
        for (const auto& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
        if ((target.array() >= lo.array()).all() && (target.array() <= hi.array()).all()) marked.push_back(t);
      }
      refine_marked(mesh, marked);
    }
    expect_valid(mesh);
    return mesh.num_tets();
  };
  const int at30 = tets_after(30);
  const int at60 = tets_after(60);
  // Exponential growth would give 2^30 times more; linear growth about twice as many.
  EXPECT_LT(at60, 3 * at30);
  EXPECT_LT(at60, 60 * 200);
}

TEST(Bisection, SplittingAnyEdgeTerminatesAtItsExactMidpoint) {
  std::mt19937 rng(7);
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 2);
  refine_randomly(mesh, rng, 10, 10);
  for (int trial = 0; trial < 300; ++trial) {
    std::uniform_int_distribution<TetId> pick_tet(0, mesh.num_tets() - 1);
    std::uniform_int_distribution<int> pick_vertex(0, 3);
    const TetId t = pick_tet(rng);
    const int i = pick_vertex(rng);
    const int j = (i + 1 + pick_vertex(rng) % 3) % 4;
    const VertexId a = mesh.tets[t][i], b = mesh.tets[t][j];
    const VertexId m = split_edge(mesh, t, a, b);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(2 * mesh.grid[m][k], mesh.grid[a][k] + mesh.grid[b][k]);
    for (const auto& v : mesh.tets)
      ASSERT_FALSE(std::count(v.begin(), v.end(), a) && std::count(v.begin(), v.end(), b)) << "edge survived";
  }
  expect_valid(mesh);
}

TEST(Bisection, FaceTagsAreInheritedBySubFaces) {
  // Tag the interior faces on the plane x = 1/2 as an interface, refine at random, and check that the
  // tagged faces still tile exactly that plane and nothing else.
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 3);
  const std::int64_t half = grid_cell / 2;
  auto on_plane = [&](TetId t, int f) {
    return std::all_of(face_vertices[f].begin(), face_vertices[f].end(),
                       [&](int local) { return mesh.grid[mesh.tets[t][local]][0] == half; });
  };
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f)
      if (on_plane(t, f)) mesh.face_tags[t][f] = interface_tag(0);
  std::mt19937 rng(11);
  refine_randomly(mesh, rng, 30, 30);
  expect_valid(mesh);
  double tagged_area = 0;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      ASSERT_EQ(on_plane(t, f), mesh.face_tags[t][f] == interface_tag(0)) << "tet " << t << " face " << f;
      if (on_plane(t, f)) {
        const auto face = mesh.outward_face(t, f);
        tagged_area +=
            0.5 *
            (mesh.points[face[1]] - mesh.points[face[0]]).cross(mesh.points[face[2]] - mesh.points[face[0]]).norm();
      }
    }
  EXPECT_NEAR(tagged_area, 2.0, 1e-12);  // both sides of the unit square
}

TEST(Bisection, IncompatibleMacroOrderIsReportedNotLoopedForever) {
  // (p0, p3, p1, p2) instead of (p0, p3, p2, p1): across cells, refinement edges stop matching.
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {2, 1, 1}}, 0);
  for (TetId t = 0; t < mesh.num_tets(); ++t) {
    std::swap(mesh.tets[t][2], mesh.tets[t][3]);
    std::swap(mesh.face_tags[t][2], mesh.face_tags[t][3]);
    mesh.kinds[t] = TetKind::make(0, !mesh.kinds[t].negative());
  }
  build_neighbours(mesh);
  ASSERT_TRUE(verify_mesh(mesh).ok());
  EXPECT_THROW(refine_uniformly(mesh, 8), MeshingError);
}

TEST(Bisection, ChildCallbackReportsEveryNewTet) {
  TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 1);
  std::vector<int> parent_of(mesh.num_tets(), -1);
  const std::vector<TetId> marked{0, 5, 9};
  refine_marked(mesh, marked, [&](TetId parent, TetId child) {
    ASSERT_EQ(child, static_cast<TetId>(parent_of.size()));
    parent_of.push_back(parent);
  });
  EXPECT_EQ(parent_of.size(), mesh.tets.size());
}

// Every local face of every tet appears once, keyed by its sorted vertices, in key order, so that a face's
// tets are neighbours in the list (checked on a locally refined mesh, whose vertices have up to dozens of faces).
TEST(TetMesh, SortedFaceRecordsListEveryLocalFaceOnceInKeyOrder) {
  std::mt19937 rng(7);
  TetMesh mesh = make_cube_meccano(test_boxes[3], 1);
  refine_randomly(mesh, rng, 40, 25);
  const std::vector<FaceRecord> faces = sorted_face_records(mesh.tets);
  ASSERT_EQ(faces.size(), 4 * mesh.tets.size());
  std::vector<int> seen(faces.size(), 0);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const FaceRecord& face = faces[i];
    std::array<VertexId, 3> key{};
    for (int k = 0; k < 3; ++k) key[k] = mesh.tets[face.tet][face_vertices[face.local_face][k]];
    std::sort(key.begin(), key.end());
    EXPECT_EQ(face.key, key) << "record " << i;
    ++seen[4 * static_cast<std::size_t>(face.tet) + face.local_face];
    if (i > 0) {
      EXPECT_LE(faces[i - 1].key, face.key) << "record " << i;
    }
  }
  EXPECT_EQ(std::ranges::count(seen, 1), std::ssize(seen));
}

}  // namespace
}  // namespace meccano
