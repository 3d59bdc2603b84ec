// A moving interface (issue 20): the surfaces' positions step after step, each step's mesh made from the
// previous step's where it can, at a fraction of the cost of a new insertion.
//
// Input    the meccano mesh, the insertion options and, per step, the surfaces: as many, named alike and in
//          the same order every step, each valid on its own (validate_surfaces).
// Steps    The first step inserts the surfaces (insert_surfaces). A later step whose surfaces keep their
//          triangulations (only points moved) moves the previous step's interface onto them
//          (move_surfaces), trying SequenceOptions::moves in turn: first six rings of nodes follow the
//          interface and the improvement alone restores the mesh around it (a tenth of an insertion's
//          cost on a fault, design.md "A moving interface"); if tets stay inverted, two rings follow and
//          SUS smooths the band before the improvement (after a loss of quality only with
//          `retry_after_quality_loss`: that move has not kept the quality where the first lost it).
//          SUS keeps the paper's measure better on smooth surfaces, but from a valid start on meshes
//          with tiny tets (crease splits) it can tangle them and then costs as much as an insertion,
//          hence second.
//          Away from the interface the mesh stays the previous step's, node for node. The step inserts
//          the surfaces anew instead, from the meccano mesh, when
//            - a triangulation changed (a surface clipped by the box, given clipped, changes its triangulation
//              when one of its vertices crosses a box plane),
//            - a vertex of a surface moved farther than `max_move_in_resolutions` times the l_r it was
//              inserted at since the previous step (then it left the refinement made around it, and a
//              move is not tried: at 1.3 l_r per step every move of the cube example lost quality and
//              cost an insertion's time in vain, design.md "A moving interface"),
//            - a surface's area differs from its area at the last insertion by more than
//              `max_area_change` of it (a growing or shrinking surface stretches or squeezes the refinement
//              made for it: a sphere moved while it grew by 5 l_r kept 0.63 of the tets an insertion
//              gives it, its interface edges longer than the l_r asked for),
//            - the moved interface stays tangled after SUS (it moved too far for the tets beside it), or
//            - its worst tet, by either mean ratio, falls more than `max_quality_loss` below the worst of
//              the steps inserted anew so far, or below the improvement's threshold if that is lower
//              (above it an insertion's worst tets vary from step to step by more than the loss allowed):
//              the refinement around the interface was made for where the surface was then, and the
//              drift since has worn it out.
//          A new insertion refines the meccano mesh anew; the refinement of the old positions is dropped
//          with the old mesh, so the tet count follows the surface instead of growing with its path.
// Output   per step its result, whether it was moved or inserted anew (and why), the seconds, and per node
//          of its mesh the node of the previous step's mesh at the same position (mesh/node_correspondence.hpp).
// Errors   those of insert_surfaces, for a step that must be inserted anew and cannot be.
#pragma once

#include <meccano/mesh/tet_mesh.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/surface/triangle_surface.hpp>

#include <optional>
#include <string>
#include <vector>

namespace meccano {

struct SequenceOptions {
  bool always_insert = false;            // insert every step anew (a baseline for comparisons)
  double max_quality_loss = 0.02;        // in either mean ratio's minimum, against the steps inserted anew
  double max_move_in_resolutions = 1.0;  // a step that moves a surface's vertex farther is inserted anew
  double max_area_change = 0.1;          // as a share of a surface's area at the last insertion
  // The ways a step is moved, tried in turn before it is inserted anew: the cheap one first.
  std::vector<MoveOptions> moves{{.drag_rings = 6, .smooth = false}, {.drag_rings = 2, .smooth = true}};
  // Whether a move that lost quality (rather than failing to untangle) is followed by the next one. The
  // later moves drag fewer rings: since the improvement's ladder, none of them has kept the quality where
  // the first lost it (0 of 4 on the faults and the cube example; their worst meccano tets 0.02-0.06
  // lower still), and each cost an insertion's time before the insertion (doc/comparison.md).
  bool retry_after_quality_loss = false;
};

enum class StepKind { inserted, moved };

struct SequenceStep {
  int index = 0;  // from 0
  StepKind kind = StepKind::inserted;
  std::string inserted_because;  // why a later step was inserted anew; empty for the first step and moved ones
  InsertionResult result;
  std::vector<VertexId> previous_node;  // per node of result.mesh; no_previous_node at step 0 and for new nodes
  std::int64_t nodes_unchanged = 0;     // nodes with a previous node
  double seconds = 0.0;                 // the whole step, node correspondence included
};

class SurfaceSequence {
 public:
  SurfaceSequence(TetMesh meccano, InsertionOptions options, SequenceOptions sequence = {});

  // The next step, at the surfaces' new positions. The previous step's result is released.
  const SequenceStep& advance(std::vector<TriangleSurface> surfaces);

 private:
  // Why `surfaces` cannot be moved from the previous step (empty if they can).
  std::string why_not_moved(const std::vector<TriangleSurface>& surfaces) const;
  std::optional<InsertionResult> try_moving(const std::vector<TriangleSurface>& surfaces, std::string& why) const;

  TetMesh meccano_;
  InsertionOptions options_;
  SequenceOptions sequence_;
  std::optional<SequenceStep> last_;
  std::vector<TriangleSurface> surfaces_;  // the last step's
  QualitySummary inserted_quality_;        // the worst of the steps inserted anew, capped by the threshold
  std::vector<double> inserted_areas_;     // the surfaces' areas at the last step inserted anew
};

}  // namespace meccano
