#include <meccano/stages/sequence.hpp>

#include <meccano/error.hpp>
#include <meccano/mesh/node_correspondence.hpp>

#include <algorithm>
#include <chrono>
#include <sstream>
#include <utility>

namespace meccano {
namespace {

// "equilateral minimum 0.31 against 0.35": how `moved` fell below `inserted` by more than `loss`, or empty.
std::string quality_loss(const QualitySummary& moved, const QualitySummary& inserted, double loss) {
  std::ostringstream why;
  if (moved.meccano.min < inserted.meccano.min - loss)
    why << "meccano minimum " << moved.meccano.min << " against " << inserted.meccano.min;
  else if (moved.equilateral.min < inserted.equilateral.min - loss)
    why << "equilateral minimum " << moved.equilateral.min << " against " << inserted.equilateral.min;
  return why.str();
}

}  // namespace

SurfaceSequence::SurfaceSequence(TetMesh meccano, InsertionOptions options, SequenceOptions sequence)
    : meccano_(std::move(meccano)), options_(std::move(options)), sequence_(std::move(sequence)) {}

std::string SurfaceSequence::why_not_moved(const std::vector<TriangleSurface>& surfaces) const {
  if (surfaces.size() != surfaces_.size()) return "the number of surfaces changed";
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    if (surfaces[s].name != surfaces_[s].name) return "surface " + std::to_string(s + 1) + " was renamed";
    if (surfaces[s].points.size() != surfaces_[s].points.size() || surfaces[s].triangles != surfaces_[s].triangles)
      return "the triangulation of " + surfaces[s].name + " changed";
    double farthest = 0.0;
    for (std::size_t i = 0; i < surfaces[s].points.size(); ++i)
      farthest = std::max(farthest, (surfaces[s].points[i] - surfaces_[s].points[i]).norm());
    const double resolution = last_->result.surfaces[s].resolution;
    if (farthest > sequence_.max_move_in_resolutions * resolution) {
      std::ostringstream why;
      why << surfaces[s].name << " moved by " << farthest / resolution << " l_r, more than "
          << sequence_.max_move_in_resolutions;
      return why.str();
    }
    const double change = surface_area(surfaces[s]) / inserted_areas_[s] - 1.0;
    if (std::abs(change) > sequence_.max_area_change) {
      std::ostringstream why;
      why << "the area of " << surfaces[s].name << " changed by " << 100 * change
          << " % since it was inserted, more than " << 100 * sequence_.max_area_change << " %";
      return why.str();
    }
  }
  return {};
}

std::optional<InsertionResult> SurfaceSequence::try_moving(const std::vector<TriangleSurface>& surfaces,
                                                           std::string& why) const {
  why = why_not_moved(surfaces);
  if (!why.empty()) return std::nullopt;
  std::string failures;
  for (const MoveOptions& move : sequence_.moves) {
    std::string failure;
    bool lost_quality = false;
    try {
      InsertionResult moved = move_surfaces(last_->result, surfaces, options_, move);
      failure = quality_loss(moved.quality_after_smoothing, inserted_quality_, sequence_.max_quality_loss);
      if (failure.empty()) return moved;
      failure = "lost quality: " + failure;
      lost_quality = true;
    } catch (const MeshingError& error) {
      failure = std::string("failed: ") + error.what();
    }
    failures += (failures.empty() ? "moving " : "; moving again ") + failure;
    if (lost_quality && !sequence_.retry_after_quality_loss) break;
  }
  why = failures;
  return std::nullopt;
}

const SequenceStep& SurfaceSequence::advance(std::vector<TriangleSurface> surfaces) {
  const auto start = std::chrono::steady_clock::now();
  SequenceStep step;
  step.index = last_ ? last_->index + 1 : 0;
  std::optional<InsertionResult> moved;
  if (last_ && !sequence_.always_insert) moved = try_moving(surfaces, step.inserted_because);
  if (moved) {
    step.kind = StepKind::moved;
    step.result = std::move(*moved);
  } else {
    step.result = insert_surfaces(meccano_, surfaces, options_);
    // Above the improvement's threshold the worst tets are as an insertion left them, which varies from
    // step to step by more than the loss allowed: the threshold caps the reference.
    const double cap = options_.improve == Improvement::none ? 1.0 : options_.improvement.threshold;
    const QualitySummary& quality = step.result.quality_after_smoothing;
    if (!last_) inserted_quality_.meccano.min = inserted_quality_.equilateral.min = cap;
    inserted_quality_.meccano.min = std::min(inserted_quality_.meccano.min, quality.meccano.min);
    inserted_quality_.equilateral.min = std::min(inserted_quality_.equilateral.min, quality.equilateral.min);
    inserted_areas_.clear();
    for (const TriangleSurface& surface : surfaces) inserted_areas_.push_back(surface_area(surface));
  }
  if (last_) {
    step.previous_node = match_previous_nodes(last_->result.mesh, step.result.mesh);
    step.nodes_unchanged = count_unchanged_nodes(step.previous_node);
  } else {
    step.previous_node.assign(step.result.mesh.points.size(), no_previous_node);
  }
  step.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  last_ = std::move(step);
  surfaces_ = std::move(surfaces);
  return *last_;
}

}  // namespace meccano
