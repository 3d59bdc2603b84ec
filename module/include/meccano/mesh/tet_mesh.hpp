// The tetrahedral mesh that every pipeline stage shares.
//
// Vertices carry two positions:
//   - `points`: physical coordinates (moved by projection and smoothing);
//   - `grid`:   computational (meccano) coordinates, exact. They are integers in units of
//               2^-grid_bits of a meccano cell edge; every Kossaczky midpoint of the cube meccano is
//               dyadic, so midpoints stay exact, and equal positions hash equal.
// Tets carry:
//   - `tets`: the 4 vertices in Kossaczky order (v0-v1 is the refinement edge);
//   - `kinds`: the Kossaczky type 0/1/2 and whether that vertex order is negatively oriented; or, for a
//              tet made by a topological operation of the improvement stage (stages/improvement.hpp), that it is
//              no longer a Kossaczky simplex and may not be bisected (TetKind::bisectable);
//   - `neighbours`: the tet across face i (face i is opposite vertex i), or no_tet on the box boundary;
//   - `face_tags`: a tag per local face (box side, interface, or none), kept through refinement.
//
// Invariants (checked by verify_mesh, mesh/invariants.hpp): the mesh is conforming (every interior face
// is shared by exactly two tets, which point at each other), boundary faces tile the box sides, every
// tet has non-zero volume and its tracked orientation matches its geometry.
#pragma once

#include <meccano/mesh/box.hpp>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace meccano {

using VertexId = std::int32_t;
using TetId = std::int32_t;
inline constexpr TetId no_tet = -1;

// Computational coordinates: integer multiples of 2^-grid_bits cell edges. 30 bits allow 30 halvings of
// a cell edge (90 bisection levels) and leave room for exact determinants in 128-bit arithmetic.
inline constexpr int grid_bits = 30;
inline constexpr std::int64_t grid_cell = std::int64_t{1} << grid_bits;
using GridPoint = std::array<std::int64_t, 3>;

// Face tags: 0 = untagged, 1..6 = box sides, 7.. = interfaces of immersed surfaces. The mesh files use
// the same numbers for their 2D groups, and domain_tag for the volume (io/mesh_writers.hpp).
inline constexpr int domain_tag = 1;
using FaceTag = std::uint8_t;
inline constexpr FaceTag no_face_tag = 0;
inline constexpr int max_interfaces = 255 - 6;
enum class BoxSide : int { xmin = 0, xmax, ymin, ymax, zmin, zmax };
inline constexpr FaceTag box_side_tag(BoxSide side) { return static_cast<FaceTag>(1 + static_cast<int>(side)); }
inline constexpr FaceTag interface_tag(int surface_index) { return static_cast<FaceTag>(7 + surface_index); }
inline constexpr bool is_box_side_tag(FaceTag tag) { return tag >= 1 && tag <= 6; }
inline constexpr bool is_interface_tag(FaceTag tag) { return tag >= 7; }
inline constexpr int interface_index(FaceTag tag) { return tag - 7; }
const char* box_side_name(BoxSide side);  // "xmin", ..., "zmax"

// Local vertices of face i (opposite vertex i), ordered so that the face normal by the right-hand rule
// points out of a positively oriented tet.
inline constexpr std::array<std::array<int, 3>, 4> face_vertices{{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

// Kossaczky type in bits 0-1, orientation flag in bit 2, bit 3 set for a remeshed tet.
struct TetKind {
  std::uint8_t bits = 0;
  int type() const { return bits & 3; }
  bool negative() const { return (bits & 4) != 0; }
  // False for a tet made by a flip or edge removal: it is not a simplex of the bisection hierarchy, so it has
  // no refinement edge, type, level or meccano counterpart, and bisection refuses it.
  bool bisectable() const { return (bits & 8) == 0; }
  static TetKind make(int type, bool negative) { return {static_cast<std::uint8_t>(type | (negative ? 4 : 0))}; }
  // A remeshed tet, its vertices stored in positive orientation.
  static TetKind remeshed() { return {8}; }
};

// The affine map from computational to physical coordinates of the undeformed meccano:
// x = box.min + cell_size .* grid / grid_cell, and exactly box.max on the upper box planes.
struct MeccanoGrid {
  Box box;
  std::array<int, 3> cells{1, 1, 1};
  Eigen::Vector3d cell_size = Eigen::Vector3d::Ones();

  Eigen::Vector3d to_physical(const GridPoint& g) const;
  GridPoint upper_corner() const;  // grid coordinates of box.max
  // The box planes a grid point lies on, exactly: bit 2 axis for the lower plane, 2 axis + 1 for the upper
  // one (the bit of BoxSide, and of box_sides in surface/box_clipping.hpp); 0 inside the box.
  std::uint8_t box_planes(const GridPoint& g) const;
};

// A face of the mesh as a face of one of its tets: local_face f is the face opposite mesh.tets[tet][f]
// (Kossaczky order, like neighbours and face_tags). A solver that builds its cells from oriented_tet(tet)
// finds that face at index oriented_local_face(tet, local_face) of its own cell.
struct FaceRef {
  TetId tet;
  int local_face;
};

// Per-tet flag of a region of the mesh (V_M, the tets a surface encloses, ...), indexed by TetId; kept in
// step with refinement by region_follows_children (stages/volumetric_approximation.hpp).
using TetRegion = std::vector<std::uint8_t>;

struct TetMesh {
  MeccanoGrid meccano;

  std::vector<Eigen::Vector3d> points;
  std::vector<GridPoint> grid;

  std::vector<std::array<VertexId, 4>> tets;
  std::vector<TetKind> kinds;
  std::vector<std::array<TetId, 4>> neighbours;
  std::vector<std::array<FaceTag, 4>> face_tags;

  int num_vertices() const { return static_cast<int>(points.size()); }
  int num_tets() const { return static_cast<int>(tets.size()); }

  VertexId add_vertex(const Eigen::Vector3d& point, const GridPoint& grid_point);
  void reserve_tets(std::size_t count);

  // The tet's vertices ordered so that it is positively oriented (what file formats expect).
  std::array<VertexId, 4> oriented_tet(TetId t) const;
  // Local face f (opposite tets[t][f]) numbered as in oriented_tet(t): the index k of the vertex
  // oriented_tet(t)[k] it is opposite. oriented_tet swaps the last two vertices of a negatively oriented
  // tet, so faces 2 and 3 swap there.
  int oriented_local_face(TetId t, int f) const { return kinds[t].negative() && f >= 2 ? 5 - f : f; }
  // The vertices of local face f, ordered so that the right-hand normal points out of tet t.
  std::array<VertexId, 3> outward_face(TetId t, int f) const;
  // The physical positions of the tet's vertices, in Kossaczky order.
  std::array<Eigen::Vector3d, 4> tet_points(TetId t) const;
  // Longest physical edge, l_T of the paper.
  double longest_edge(TetId t) const;
  // Bisection level: 0 for the Kuhn tets of a meccano cell, +1 per bisection. Read off the computational
  // length of the refinement edge (a cube diagonal, face diagonal or cube edge of a cube 2^-k cells wide
  // at levels 3k, 3k+1, 3k+2), so it needs no stored history. -1 for a remeshed tet.
  int level(TetId t) const;
  bool bisectable(TetId t) const { return kinds[t].bisectable(); }
  // Index (0..3) of the face of `t` shared with `neighbour`, or -1.
  int face_towards(TetId t, TetId neighbour) const;
};

// Exact orientation of the tet's vertex order in computational coordinates: +1, -1 or 0 (degenerate).
int grid_orientation(const TetMesh& mesh, TetId t);

// Every local face of every tet, keyed by its sorted vertices and sorted by key, so that the tets sharing
// a face are adjacent in the list. Takes the tets alone so that a mesh read from a file can be checked too;
// their vertex ids must not be negative (the list is bucketed by vertex).
struct FaceRecord {
  std::array<VertexId, 3> key;
  TetId tet;
  int local_face;
};
std::vector<FaceRecord> sorted_face_records(std::span<const std::array<VertexId, 4>> tets);

// Fills `neighbours` from the tets alone. Throws MeshingError if a face is shared by more than two tets.
void build_neighbours(TetMesh& mesh);

// Vertex -> incident tets, in compressed row storage.
struct VertexTets {
  std::vector<int> offsets;  // size num_vertices + 1
  std::vector<TetId> tets;
  std::span<const TetId> of(VertexId v) const { return {tets.data() + offsets[v], tets.data() + offsets[v + 1]}; }
};
VertexTets vertex_to_tets(const TetMesh& mesh);

// All tets containing the edge (a, b), found by walking around it from `start`, which must contain it.
std::vector<TetId> tets_around_edge(const TetMesh& mesh, TetId start, VertexId a, VertexId b);

}  // namespace meccano
