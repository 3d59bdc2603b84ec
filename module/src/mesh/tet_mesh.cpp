#include <meccano/mesh/tet_mesh.hpp>

#include <meccano/error.hpp>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <numeric>
#include <string>

namespace meccano {

const char* box_side_name(BoxSide side) {
  static constexpr const char* names[] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  return names[static_cast<int>(side)];
}

Eigen::Vector3d MeccanoGrid::to_physical(const GridPoint& g) const {
  const double scale = 1.0 / static_cast<double>(grid_cell);
  Eigen::Vector3d p = box.min + Eigen::Vector3d(cell_size.x() * static_cast<double>(g[0]) * scale,
                                                cell_size.y() * static_cast<double>(g[1]) * scale,
                                                cell_size.z() * static_cast<double>(g[2]) * scale);
  // min + cells · (extent / cells) may round away from max: the upper box planes are exactly the box's,
  // as the surfaces clipped to them are.
  const std::uint8_t planes = box_planes(g);
  for (int k = 0; k < 3; ++k)
    if (planes & (1u << (2 * k + 1))) p[k] = box.max[k];
  return p;
}

std::uint8_t MeccanoGrid::box_planes(const GridPoint& g) const {
  const GridPoint upper = upper_corner();
  std::uint8_t planes = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (g[axis] == 0) planes |= static_cast<std::uint8_t>(1u << (2 * axis));
    if (g[axis] == upper[axis]) planes |= static_cast<std::uint8_t>(1u << (2 * axis + 1));
  }
  return planes;
}

GridPoint MeccanoGrid::upper_corner() const {
  return {cells[0] * grid_cell, cells[1] * grid_cell, cells[2] * grid_cell};
}

VertexId TetMesh::add_vertex(const Eigen::Vector3d& point, const GridPoint& grid_point) {
  points.push_back(point);
  grid.push_back(grid_point);
  return static_cast<VertexId>(points.size() - 1);
}

void TetMesh::reserve_tets(std::size_t count) {
  tets.reserve(count);
  kinds.reserve(count);
  neighbours.reserve(count);
  face_tags.reserve(count);
}

std::array<VertexId, 4> TetMesh::oriented_tet(TetId t) const {
  auto v = tets[t];
  if (kinds[t].negative()) std::swap(v[2], v[3]);
  return v;
}

std::array<VertexId, 3> TetMesh::outward_face(TetId t, int f) const {
  const auto& v = tets[t];
  const auto& local = face_vertices[f];
  if (kinds[t].negative()) return {v[local[0]], v[local[2]], v[local[1]]};
  return {v[local[0]], v[local[1]], v[local[2]]};
}

std::array<Eigen::Vector3d, 4> TetMesh::tet_points(TetId t) const {
  const auto& v = tets[t];
  return {points[v[0]], points[v[1]], points[v[2]], points[v[3]]};
}

double TetMesh::longest_edge(TetId t) const {
  const auto p = tet_points(t);
  double longest = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (p[i] - p[j]).squaredNorm());
  return std::sqrt(longest);
}

int TetMesh::level(TetId t) const {
  if (!bisectable(t)) return -1;
  const GridPoint& a = grid[tets[t][0]];
  const GridPoint& b = grid[tets[t][1]];
  std::int64_t squared = 0;
  for (int axis = 0; axis < 3; ++axis) squared += (a[axis] - b[axis]) * (a[axis] - b[axis]);
  // squared = (3 - type) * 4^(grid_bits - k) at level 3k + type.
  const int type = kinds[t].type();
  const auto power = static_cast<std::uint64_t>(squared / (3 - type));
  const int k = grid_bits - std::countr_zero(power) / 2;
  return 3 * k + type;
}

int TetMesh::face_towards(TetId t, TetId neighbour) const {
  const auto& n = neighbours[t];
  for (int i = 0; i < 4; ++i)
    if (n[i] == neighbour) return i;
  return -1;
}

VertexTets vertex_to_tets(const TetMesh& mesh) {
  VertexTets result;
  result.offsets.assign(mesh.num_vertices() + 1, 0);
  for (const auto& tet : mesh.tets)
    for (VertexId v : tet) ++result.offsets[v + 1];
  for (int v = 0; v < mesh.num_vertices(); ++v) result.offsets[v + 1] += result.offsets[v];
  result.tets.resize(result.offsets.back());
  std::vector<int> fill(result.offsets.begin(), result.offsets.end() - 1);
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (VertexId v : mesh.tets[t]) result.tets[fill[v]++] = t;
  return result;
}

std::vector<TetId> tets_around_edge(const TetMesh& mesh, TetId start, VertexId a, VertexId b) {
  // Walk across the faces that contain (a, b): those opposite the other two vertices. Walk one way
  // until back at `start` (interior edge) or at the boundary; in the latter case walk the other way too.
  auto walk = [&](TetId from, int first_exit, std::vector<TetId>& out) -> bool {
    TetId previous = from;
    TetId current = mesh.neighbours[from][first_exit];
    while (current != no_tet && current != from) {
      out.push_back(current);
      const auto& v = mesh.tets[current];
      TetId next = no_tet;
      for (int i = 0; i < 4; ++i) {
        if (v[i] == a || v[i] == b) continue;
        const TetId across = mesh.neighbours[current][i];
        if (across != previous) next = across;
      }
      previous = current;
      current = next;
    }
    return current == from;
  };
  const auto& v = mesh.tets[start];
  std::array<int, 2> exits{};
  int count = 0;
  for (int i = 0; i < 4; ++i)
    if (v[i] != a && v[i] != b) exits[count++] = i;
  assert(count == 2);
  std::vector<TetId> around{start};
  if (!walk(start, exits[0], around)) {
    std::vector<TetId> other_way;
    walk(start, exits[1], other_way);
    around.insert(around.begin(), other_way.rbegin(), other_way.rend());
  }
  return around;
}

}  // namespace meccano

namespace meccano {

int grid_orientation(const TetMesh& mesh, TetId t) {
  __extension__ using int128 = __int128;
  const auto& v = mesh.tets[t];
  const GridPoint& o = mesh.grid[v[0]];
  std::array<std::array<int128, 3>, 3> e{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) e[r][c] = int128{mesh.grid[v[r + 1]][c]} - int128{o[c]};
  // Differences are below 2^41 for boxes of up to 1024 cells a side, so the products fit in 127 bits.
  const int128 det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
  return (det > 0) - (det < 0);
}

// A counting sort on each face's smallest vertex, then a sort of each vertex's few faces: 1.75x as fast
// as one comparison sort of all 4 n faces, which was 8 % of an insertion (five invariant checks). Serial:
// an OpenMP loop here made the test suite 3x slower on two cores (thousands of small meshes, each a
// parallel region beside another test's threads).
std::vector<FaceRecord> sorted_face_records(std::span<const std::array<VertexId, 4>> tets) {
  auto face_key = [&](TetId t, int f) {
    std::array<VertexId, 3> key{};
    for (int k = 0; k < 3; ++k) key[k] = tets[t][face_vertices[f][k]];
    std::sort(key.begin(), key.end());
    return key;
  };
  VertexId vertices = 0;
  for (const auto& tet : tets) vertices = std::max(vertices, *std::ranges::max_element(tet) + 1);
  std::vector<std::size_t> start(static_cast<std::size_t>(vertices) + 1, 0);
  for (TetId t = 0; t < static_cast<TetId>(tets.size()); ++t)
    for (int f = 0; f < 4; ++f) ++start[face_key(t, f)[0] + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<FaceRecord> faces(4 * tets.size());
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  for (TetId t = 0; t < static_cast<TetId>(tets.size()); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::array<VertexId, 3> key = face_key(t, f);
      faces[next[key[0]]++] = {key, t, f};
    }
  const auto by_key = [](const FaceRecord& a, const FaceRecord& b) { return a.key < b.key; };
  for (VertexId v = 0; v < vertices; ++v)
    std::sort(faces.begin() + static_cast<std::ptrdiff_t>(start[v]),
              faces.begin() + static_cast<std::ptrdiff_t>(start[v + 1]), by_key);
  return faces;
}

void build_neighbours(TetMesh& mesh) {
  mesh.neighbours.assign(mesh.tets.size(), {no_tet, no_tet, no_tet, no_tet});
  const auto faces = sorted_face_records(mesh.tets);
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i > 2)
      throw MeshingError("face (" + std::to_string(faces[i].key[0]) + ", " + std::to_string(faces[i].key[1]) + ", " +
                         std::to_string(faces[i].key[2]) + ") is shared by " + std::to_string(j - i) + " tets");
    if (j - i == 2) {
      mesh.neighbours[faces[i].tet][faces[i].local_face] = faces[i + 1].tet;
      mesh.neighbours[faces[i + 1].tet][faces[i + 1].local_face] = faces[i].tet;
    }
    i = j;
  }
}

}  // namespace meccano
