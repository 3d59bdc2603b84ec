#include <meccano/mesh/invariants.hpp>

#include <meccano/mesh/quality.hpp>

#include "geometry/compensated_sum.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>
#include <sstream>

namespace meccano {
namespace {

__extension__ using int128 = __int128;

class Checker {
 public:
  Checker(const TetMesh& mesh, const MeshInvariantOptions& options) : mesh_(mesh), options_(options) {}

  MeshInvariantReport run() {
    check_sizes();
    if (!report_.ok()) return report_;
    check_tets();
    check_faces();
    check_volume();
    return report_;
  }

 private:
  template <class... Parts>
  void problem(const Parts&... parts) {
    if (report_.problem_count++ >= options_.max_reported) return;
    std::ostringstream message;
    (message << ... << parts);
    report_.problems.push_back(message.str());
  }

  void check_sizes() {
    const std::size_t n = mesh_.tets.size();
    if (mesh_.kinds.size() != n || mesh_.neighbours.size() != n || mesh_.face_tags.size() != n)
      problem("per-tet arrays have different sizes");
    if (mesh_.grid.size() != mesh_.points.size()) problem("per-vertex arrays have different sizes");
    for (TetId t = 0; t < mesh_.num_tets(); ++t)
      for (VertexId v : mesh_.tets[t])
        if (v < 0 || v >= mesh_.num_vertices()) problem("tet ", t, " has vertex ", v, " out of range");
  }

  void check_tets() {
    for (TetId t = 0; t < mesh_.num_tets(); ++t) {
      const auto& v = mesh_.tets[t];
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          if (v[i] == v[j]) problem("tet ", t, " repeats vertex ", v[i]);
      // A remeshed tet has no computational shape to check (its grid image may even be inverted); the
      // computational volume still adds up, since a flip keeps the boundary of the tets it replaces.
      const int sign = mesh_.bisectable(t) ? grid_orientation(mesh_, t) : 1;
      if (sign == 0) problem("tet ", t, " is degenerate in computational space");
      else if ((sign < 0) != mesh_.kinds[t].negative())
        problem("tet ", t, " has orientation ", sign, " but records the opposite");
      if (options_.physical) {
        const auto o = mesh_.oriented_tet(t);
        const double volume =
            signed_volume(mesh_.points[o[0]], mesh_.points[o[1]], mesh_.points[o[2]], mesh_.points[o[3]]);
        physical_volume_.add(volume);
        if (!(volume > 0.0)) {
          ++report_.inverted_physical;
          problem("tet ", t, " is inverted or flat in physical space (volume ", volume, ")");
        }
      }
    }
  }

  // The box side (0..5) that all three grid points lie on, or -1.
  int box_side_of(const std::array<VertexId, 3>& face) const {
    const MeccanoGrid& grid = mesh_.meccano;
    const unsigned shared = grid.box_planes(mesh_.grid[face[0]]) & grid.box_planes(mesh_.grid[face[1]]) &
                            grid.box_planes(mesh_.grid[face[2]]);
    return shared == 0 ? -1 : std::countr_zero(shared);
  }

  // Twice the area of a face lying on a plane normal to `axis`, exactly.
  int128 twice_area_on_plane(const std::array<VertexId, 3>& face, int axis) const {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    const GridPoint& a = mesh_.grid[face[0]];
    const GridPoint& b = mesh_.grid[face[1]];
    const GridPoint& c = mesh_.grid[face[2]];
    const int128 cross = int128{b[u] - a[u]} * (c[w] - a[w]) - int128{b[w] - a[w]} * (c[u] - a[u]);
    return cross < 0 ? -cross : cross;
  }

  // Each tet face against its recorded neighbour, without sorting the 4n faces (a sort took 15 % of a
  // moved interface's step): a face with a neighbour must be that tet's face too, in the opposite
  // orientation, and the neighbour must point back; a face without one lies on a box side. With every
  // tet positively oriented (check_tets), the faces then cancel in pairs except the box sides', which
  // they tile exactly: the tets cover the box once, so no face can belong to three tets either.
  void check_faces() {
    std::array<int128, 6> side_area{};
    for (TetId t = 0; t < mesh_.num_tets(); ++t)
      for (int f = 0; f < 4; ++f) {
        const TetId n = mesh_.neighbours[t][f];
        if (n == no_tet) {
          check_boundary_face(t, f, side_area);
        } else if (n < 0 || n >= mesh_.num_tets() || n == t) {
          problem("tet ", t, " face ", f, " has neighbour ", n, ", not another tet");
        } else if (t < n || !points_back(t, f, n)) {
          check_interior_face(t, f, n);  // once per pair, and wherever n does not point back
        }
      }
    const auto& cells = mesh_.meccano.cells;
    for (int side = 0; side < 6; ++side) {
      const int axis = side / 2;
      const int128 expected = int128{2} * cells[(axis + 1) % 3] * cells[(axis + 2) % 3] * grid_cell * grid_cell;
      if (side_area[side] != expected)
        problem("boundary faces do not tile box side ", box_side_name(static_cast<BoxSide>(side)));
    }
  }

  // The local face of tet n with the vertices of tet t's face f, if it has one.
  std::optional<int> matching_face(TetId t, int f, TetId n) const {
    const std::array<VertexId, 3> face = mesh_.outward_face(t, f);
    int outside = -1, count = 0;
    for (int g = 0; g < 4; ++g)
      if (std::find(face.begin(), face.end(), mesh_.tets[n][g]) == face.end()) {
        outside = g;
        ++count;
      }
    return count == 1 ? std::optional<int>(outside) : std::nullopt;
  }

  bool points_back(TetId t, int f, TetId n) const {
    const std::optional<int> g = matching_face(t, f, n);
    return g && mesh_.neighbours[n][*g] == t;
  }

  void check_interior_face(TetId t, int f, TetId n) {
    const std::optional<int> g = matching_face(t, f, n);
    if (!g) {
      problem("tet ", t, " face ", f, " records tet ", n, " as its neighbour, which does not hold that face");
      return;
    }
    if (mesh_.neighbours[n][*g] != t) {
      problem("tets ", t, " and ", n, " share a face but are not recorded as each other's neighbours");
      return;
    }
    ++report_.interior_faces;
    const std::array<VertexId, 3> a = mesh_.outward_face(t, f), b = mesh_.outward_face(n, *g);
    const auto at = static_cast<int>(std::find(b.begin(), b.end(), a[0]) - b.begin());
    if (b[(at + 1) % 3] != a[2]) problem("tets ", t, " and ", n, " lie on the same side of their shared face");
    const FaceTag tag = mesh_.face_tags[t][f];
    if (is_box_side_tag(tag)) problem("interior face of tet ", t, " carries a box-side tag");
    if (tag != mesh_.face_tags[n][*g])
      problem("interior face between tets ", t, " and ", n, " is tagged differently on each side");
  }

  void check_boundary_face(TetId t, int f, std::array<int128, 6>& side_area) {
    ++report_.boundary_faces;
    const std::array<VertexId, 3> face = mesh_.outward_face(t, f);  // the order matters to neither use
    const int side = box_side_of(face);
    if (side < 0) {
      problem("tet ", t, " face ", f, " has no neighbour but is not on the box boundary (a hole)");
      return;
    }
    side_area[side] += twice_area_on_plane(face, side / 2);
    if (mesh_.face_tags[t][f] != box_side_tag(static_cast<BoxSide>(side)))
      problem("boundary face of tet ", t, " is not tagged ", box_side_name(static_cast<BoxSide>(side)));
  }

  void check_volume() {
    int128 six_volumes = 0;
    for (TetId t = 0; t < mesh_.num_tets(); ++t) {
      const auto o = mesh_.oriented_tet(t);
      std::array<std::array<int128, 3>, 3> e{};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) e[r][c] = int128{mesh_.grid[o[r + 1]][c]} - mesh_.grid[o[0]][c];
      six_volumes += e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    }
    const auto& cells = mesh_.meccano.cells;
    const int128 expected = int128{6} * cells[0] * cells[1] * cells[2] * grid_cell * grid_cell * grid_cell;
    if (six_volumes != expected) problem("computational volume differs from the box volume");
    if (options_.physical) {
      report_.physical_volume = physical_volume_.value();
      const Eigen::Vector3d extent = mesh_.meccano.box.extent();
      const double box_volume = extent.prod();
      if (std::abs(report_.physical_volume - box_volume) > 1e-10 * box_volume)
        problem("physical volume ", report_.physical_volume, " differs from the box volume ", box_volume);
    }
  }

  const TetMesh& mesh_;
  const MeshInvariantOptions& options_;
  MeshInvariantReport report_;
  CompensatedSum physical_volume_;
};

}  // namespace

std::string MeshInvariantReport::summary() const {
  std::ostringstream out;
  out << problem_count << " problem(s)";
  for (const auto& p : problems) out << "\n  " << p;
  if (problem_count > static_cast<std::int64_t>(problems.size()))
    out << "\n  ... and " << problem_count - static_cast<std::int64_t>(problems.size()) << " more";
  return out.str();
}

MeshInvariantReport verify_mesh(const TetMesh& mesh, const MeshInvariantOptions& options) {
  return Checker(mesh, options).run();
}

}  // namespace meccano
