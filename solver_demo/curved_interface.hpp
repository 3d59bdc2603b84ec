// Cells curved onto a surface S known as a formula, for elements of degree 2.
//
// Why    S_h's faces are chords of S, O(h²) away from it: a source layer or a coefficient jump displaced by
//        O(h²) perturbs u by O(h²) everywhere, which caps P2's L2 rate at 2 (doc/solver.md). With S_h's
//        vertices on S and the midpoints of its edges on S too, a degree-2 mapping represents S to O(h³).
// What   with_interface_on_surface: a copy of a mesh with the vertices of one interface moved onto S by
//        `project` (in the vertices and in every interface's corners). The module leaves them on the
//        triangulation of S the mesh was made from, within its sag of S: far less than a cell's size, so no
//        cell turns over.
//        InterfaceEdgeManifold: the manifold for a degree-2 MappingFE: the new point halfway along an edge
//        of S_h is `project` of the chord's midpoint; every other point is the weighted mean of its
//        surrounding points, as on a flat cell. MappingFE asks the cell's manifold for all of the cell's
//        support points (a cell, its faces and its lines must share one manifold id, checked in Debug),
//        so every cell takes this manifold, and an edge of S_h is recognised by its two end points, which
//        every cell around it shares.
//        curve_cells_onto_surface: gives every cell, face and line of a triangulation that manifold (after
//        the interface's faces have been found by their manifold id: this resets it).
// Input  the interface's corners after with_interface_on_surface, so that they are the triangulation's
//        vertices exactly.
#pragma once

#include "interface_triangles.hpp"

#include <meccano/dealii_mesh.hpp>

#include <deal.II/grid/manifold.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace solver_demo {

meccano::DealiiMesh with_interface_on_surface(const meccano::DealiiMesh& mesh, const std::string& interface_name,
                                              const SurfaceProjection& project);

void curve_cells_onto_surface(dealii::Triangulation<3>& triangulation, const meccano::DealiiInterface& interface,
                              const SurfaceProjection& project);

class InterfaceEdgeManifold : public dealii::Manifold<3> {
 public:
  InterfaceEdgeManifold(const meccano::DealiiInterface& interface, SurfaceProjection project);

  std::unique_ptr<dealii::Manifold<3>> clone() const override;
  dealii::Point<3> get_new_point(const dealii::ArrayView<const dealii::Point<3>>& points,
                                 const dealii::ArrayView<const double>& weights) const override;

 private:
  using Edge = std::array<double, 6>;  // the end points' coordinates, the lexicographically smaller first
  static Edge edge(const dealii::Point<3>& a, const dealii::Point<3>& b);

  std::vector<Edge> edges;  // S_h's, sorted
  SurfaceProjection project;
};

}  // namespace solver_demo
