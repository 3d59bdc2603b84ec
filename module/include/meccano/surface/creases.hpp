// Creases of S followed by S_M (beyond the paper, part of step 3): where S folds, a triangle of S_M that
// straddles the fold is a chord across it, and its normal is off both sides' by up to the fold's angle
// (real fault models fold by 10-70 degrees along their triangles' edges). So S_M gets a path of edges
// along every sharp crease of S, and its nodes there stay on the crease through smoothing.
//
// Input    S, its parameterization φ: P -> S (its vertices' parameters), and S_M in P: its triangles over
//          local node ids, their parameters u = φ_M^-1(x_M), which nodes lie on the rim, the
//          orientation of its triangles in P.
// Lines    crease_lines: the interior edges of S whose unit normals differ by more than `angle`, chained
//          into polylines between their ends (vertices with one or more than two such edges, or on the
//          rim of S), closed loops cut anywhere. φ is affine on each triangle of S, so a crease is a
//          polyline in P too, through S's vertices; a point on it maps onto the crease edges in 3D.
// Paths    follow_creases, sharpest line first (the largest angle along it): the S_M edges the line
//          crosses in P, in order along it; of each edge the end nearer the crossing (excluded: rim
//          nodes, nodes joined to a rim node, which could not be smoothed between the rim and the line,
//          and nodes of a line already followed). Consecutive crossings are edges of one triangle,
//          so their chosen ends are joined by an S_M edge: the chosen nodes form a path. A node between
//          two others of the path that make a triangle of S_M with it leaves the path (the triangle
//          would lie flat on the line). Each node's place on the line is the mean arc-length parameter
//          of the crossings that chose it: increasing along the path.
// Snapping every node of a path moves to its place on the line, in order, unless that would fold an S_M
//          triangle in P or leave one with less than a tenth of its area: that node stays where it was,
//          and the path has a gap there.
// Output   per S_M node: its line (or -1) and arc-length parameter, its new parameters; statistics.
//          Smoothing (stages/smoothing.hpp) moves a node on a line along the line only.
// Invariants S_M stays embedded in P (every triangle keeps its orientation); a node on a line lies on it
//          (up to rounding), strictly inside its parameter range; consecutive nodes of a followed path
//          are joined by an S_M edge.
#pragma once

#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace meccano {

// Creases sharper than this (degrees between the unit normals of the two triangles of an edge) are
// followed by default. Straddling a crease of θ tilts an S_M triangle by up to about θ, so this bounds
// the normal deviation of S_M where creases are not followed.
inline constexpr double default_crease_angle = 12.0;

// A polyline of P along crease edges of S, parameterized by arc length in P.
struct CreaseLine {
  std::vector<int> vertices;        // of S, in order
  std::vector<Eigen::Vector2d> uv;  // their parameters
  std::vector<double> arc;          // arc length in P from the first vertex; arc.back() = length
  double angle = 0.0;               // the largest crease angle along it, degrees

  double length() const { return arc.back(); }
  Eigen::Vector2d at(double s) const;         // the point at arc length s, clamped to [0, length]
  Eigen::Vector2d direction(double s) const;  // unit tangent of the segment holding s
  std::size_t segment(double s) const;        // the segment holding s (clamped to the line): uv[i] to uv[i + 1]
};

// The crease polylines of S. `uv` holds S's vertices' parameters; `angle` in degrees (> 0).
std::vector<CreaseLine> crease_lines(const TriangleSurface& surface, std::span<const Eigen::Vector2d> uv, double angle);

struct CreaseStats {
  std::int64_t lines = 0;       // crease lines of S
  std::int64_t crossings = 0;   // S_M edges they cross
  std::int64_t nodes = 0;       // S_M nodes placed on a line
  std::int64_t refused = 0;     // path nodes left off their line (a fold, or a crushed triangle)
  std::int64_t straddling = 0;  // S_M edges a line still crosses between their nodes after snapping
  double sharpest = 0.0;        // the largest crease angle of S, degrees (0 without lines)
};

// Which S_M nodes lie on a crease line, and where on it.
struct CreaseNodes {
  std::vector<CreaseLine> lines;
  std::vector<int> line_of;       // per S_M node: its line, or -1
  std::vector<double> parameter;  // per S_M node on a line: its arc-length parameter
  CreaseStats stats;
};

// A point of P where a crease line crosses an S_M edge between its nodes, neither of which lies on that
// line: S_M's triangles on both sides of the edge straddle the crease there.
struct CreaseCrossing {
  int line;
  double s;            // arc length along the line
  int a, b;            // the edge's nodes (indices of S_M's nodes)
  double r;            // where the crossing lies on the edge: uv[a] + r (uv[b] - uv[a])
  Eigen::Vector2d at;  // the point of P
};

// Every such crossing of `creases`' lines with the edges of S_M's `triangles` at parameters `uv`, in the
// order of the lines and along each line.
std::vector<CreaseCrossing> straddling_crossings(const CreaseNodes& creases,
                                                 std::span<const std::array<int, 3>> triangles,
                                                 std::span<const Eigen::Vector2d> uv);

// Snaps S_M's nodes onto the crease lines (see the header comment); `uv` (per S_M node) is updated.
// `triangles` are S_M's over node ids, `on_rim` flags its rim nodes, `orientation` (+1 or -1) is the sign
// of its triangles' areas in P.
CreaseNodes follow_creases(std::vector<CreaseLine> lines, std::span<const std::array<int, 3>> triangles,
                           std::span<Eigen::Vector2d> uv, std::span<const std::uint8_t> on_rim, int orientation);

}  // namespace meccano
