#include <meccano/mesh/cube_meccano.hpp>

#include <meccano/error.hpp>
#include <meccano/mesh/bisection.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>

namespace meccano {
namespace {

void check_box(const Box& box) {
  if (const std::string defect = box_defect(box); !defect.empty()) throw InputError("invalid box: " + defect);
}

// Tags every face without a neighbour by the box side its vertices lie on.
void tag_box_sides(TetMesh& mesh) {
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      if (mesh.neighbours[t][f] != no_tet) continue;
      unsigned shared = 0x3f;
      for (const int local : face_vertices[f]) shared &= mesh.meccano.box_planes(mesh.grid[mesh.tets[t][local]]);
      if (shared != 0) mesh.face_tags[t][f] = box_side_tag(static_cast<BoxSide>(std::countr_zero(shared)));
    }
}

}  // namespace

std::string box_defect(const Box& box) {
  for (int k = 0; k < 3; ++k)
    if (!(box.min[k] < box.max[k]) || !std::isfinite(box.max[k] - box.min[k])) {
      std::ostringstream defect;
      defect << "on axis "
             << "xyz"[k] << " the minimum " << box.min[k] << " must be below the maximum " << box.max[k];
      if (box.min[k] < box.max[k]) defect << " by a finite extent";
      return defect.str();
    }
  return "";
}

std::array<int, 3> cells_for_box(const Box& box) {
  check_box(box);
  const Eigen::Vector3d extent = box.extent();
  const double edge = extent.minCoeff();
  std::array<int, 3> cells{};
  for (int k = 0; k < 3; ++k) {
    const double count = std::max(1.0, std::round(extent[k] / edge));
    // Said in terms of the box: the count is a number the caller never gave.
    if (count > max_cells_per_axis) {
      std::ostringstream ratio;
      ratio << extent[k] / edge;
      throw InputError("the box is " + ratio.str() + " times longer along " + "xyz"[k] +
                       " than its shortest side: cells as close to cubes as possible would be more than " +
                       std::to_string(max_cells_per_axis) + " along it; give the cell counts");
    }
    cells[k] = static_cast<int>(count);
  }
  return cells;
}

TetMesh make_cube_meccano(const Box& box, const std::array<int, 3>& cells, int level) {
  check_box(box);
  for (int k = 0; k < 3; ++k)
    if (cells[k] < 1 || cells[k] > max_cells_per_axis)
      throw InputError("invalid cell count " + std::to_string(cells[k]) + " on axis " + "xyz"[k] + " (allowed: 1 to " +
                       std::to_string(max_cells_per_axis) + ")");
  if (level < 0) throw InputError("invalid level " + std::to_string(level) + " (must be 0 or more)");

  TetMesh mesh;
  mesh.meccano.box = box;
  mesh.meccano.cells = cells;
  for (int k = 0; k < 3; ++k) mesh.meccano.cell_size[k] = box.extent()[k] / cells[k];

  const int nx = cells[0] + 1, ny = cells[1] + 1, nz = cells[2] + 1;
  auto node = [&](int i, int j, int k) { return static_cast<VertexId>(i + nx * (j + ny * k)); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const GridPoint g{i * grid_cell, j * grid_cell, k * grid_cell};
        mesh.add_vertex(mesh.meccano.to_physical(g), g);
      }

  static constexpr std::array<std::array<int, 3>, 6> axis_orders{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  const std::size_t num_cells = static_cast<std::size_t>(cells[0]) * cells[1] * cells[2];
  mesh.reserve_tets(6 * num_cells << level);
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i)
        for (const auto& order : axis_orders) {
          std::array<int, 3> step{0, 0, 0};
          std::array<VertexId, 4> path{};
          path[0] = node(i, j, k);
          for (int s = 0; s < 3; ++s) {
            step[order[s]] = 1;
            path[s + 1] = node(i + step[0], j + step[1], k + step[2]);
          }
          mesh.tets.push_back({path[0], path[3], path[2], path[1]});
          mesh.kinds.push_back(TetKind::make(0, false));
          mesh.face_tags.push_back({no_face_tag, no_face_tag, no_face_tag, no_face_tag});
          mesh.kinds.back() = TetKind::make(0, grid_orientation(mesh, mesh.num_tets() - 1) < 0);
        }
  build_neighbours(mesh);
  tag_box_sides(mesh);
  refine_uniformly(mesh, level);
  return mesh;
}

TetMesh make_cube_meccano(const Box& box, int level) { return make_cube_meccano(box, cells_for_box(box), level); }

double longest_edge_at_level(const MeccanoGrid& meccano, int level) {
  const Box cell{Eigen::Vector3d::Zero(), meccano.cell_size};
  const TetMesh refined = make_cube_meccano(cell, {1, 1, 1}, level % 3);
  double longest = 0.0;
  for (TetId t = 0; t < refined.num_tets(); ++t) longest = std::max(longest, refined.longest_edge(t));
  return std::ldexp(longest, -(level / 3));
}

int level_for_resolution(const MeccanoGrid& meccano, double resolution) {
  if (!(resolution > 0.0))
    throw InputError("the resolution l_r must be positive (got " + std::to_string(resolution) + ")");
  // Each three levels halve the edges; start near the answer and step to it.
  const double diagonal = meccano.cell_size.norm();
  int level = std::max(0, 3 * static_cast<int>(std::floor(std::log2(diagonal / resolution))) - 3);
  while (level > 0 && longest_edge_at_level(meccano, level - 1) < resolution) --level;
  while (longest_edge_at_level(meccano, level) >= resolution) {
    if (++level > finest_level) {
      std::ostringstream message;
      message << "the resolution l_r = " << resolution << " is too fine for the meccano's cells (edge "
              << meccano.cell_size.maxCoeff() << "): at most " << grid_bits - 4 << " halvings of a cell edge";
      throw InputError(message.str());
    }
  }
  return level;
}

}  // namespace meccano
