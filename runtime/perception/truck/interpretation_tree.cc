#include "runtime/perception/truck/interpretation_tree.h"

#include <algorithm>
#include <stdexcept>

namespace autoshovel::perception {
namespace {

class Search {
 public:
  Search(const std::vector<PlanarRegion>& regions, const TruckBedModel& model,
         const GroundEstimate& ground, const InterpretationVerifier& verify,
         const InterpretationTreeParams& params)
      : regions_(regions),
        model_(model),
        verify_(verify),
        params_(params),
        used_(regions.size(), false) {
    // Unary constraints once per (face, region): they shrink every level's branching factor.
    for (BedFace face : kAllBedFaces) {
      auto& list = candidates_[static_cast<std::size_t>(FaceIndex(face))];
      for (int r = 0; r < static_cast<int>(regions.size()); ++r) {
        if (ground.found && r == ground.region) continue;
        if (UnaryConsistent(model, face, regions[r], ground)) list.push_back(r);
      }
      result_.candidates[static_cast<std::size_t>(FaceIndex(face))] = static_cast<int>(list.size());
    }
  }

  InterpretationSearchResult Run() {
    Expand(0, 0);
    return result_;
  }

 private:
  // §4.1: depth-first search over model-to-scene region matches; constraints checked at every
  // level prune it.
  void Expand(int level, int matched) {
    if (result_.nodes >= params_.max_nodes) {
      result_.truncated = true;
      return;
    }
    ++result_.nodes;
    if (level == kNumBedFaces) {
      Leaf(matched);
      return;
    }
    // Bound: even matching every remaining face cannot reach the minimum or the best verified.
    const int reachable = matched + (kNumBedFaces - level);
    if (reachable < model_.min_matched_faces) return;
    if (result_.found && reachable < result_.best.NumMatched()) return;

    const BedFace face = kAllBedFaces[static_cast<std::size_t>(level)];
    for (int r : candidates_[static_cast<std::size_t>(level)]) {
      if (used_[r] || !ConsistentWithAssigned(face, r)) continue;
      current_[face] = r;
      used_[r] = true;
      Expand(level + 1, matched + 1);
      used_[r] = false;
      current_[face] = -1;
      if (result_.truncated) return;
    }
    // The wildcard branch: the face is not seen. The side walls are required (truck_model.h).
    if (!IsRequired(face)) Expand(level + 1, matched);
  }

  bool ConsistentWithAssigned(BedFace face, int r) const {
    for (BedFace other : kAllBedFaces) {
      const int assigned = current_[other];
      if (other == face || assigned < 0) continue;
      if (!PairConsistent(model_, face, regions_[r], other, regions_[assigned])) return false;
    }
    return true;
  }

  // §4.1: each complete interpretation is verified; most model regions matched, then the
  // verification score, selects.
  void Leaf(int matched) {
    if (matched < model_.min_matched_faces) return;
    if (result_.found && matched < result_.best.NumMatched()) return;
    ++result_.complete;
    const std::optional<double> score = verify_(current_);
    if (!score) return;
    ++result_.verified;
    const bool better = !result_.found || matched > result_.best.NumMatched() ||
                        (matched == result_.best.NumMatched() && *score > result_.best_score);
    if (better) {
      result_.found = true;
      result_.best = current_;
      result_.best_score = *score;
    }
  }

  const std::vector<PlanarRegion>& regions_;
  const TruckBedModel& model_;
  const InterpretationVerifier& verify_;
  const InterpretationTreeParams& params_;
  std::array<std::vector<int>, kNumBedFaces> candidates_;
  std::vector<bool> used_;
  Interpretation current_;
  InterpretationSearchResult result_;
};

}  // namespace

int Interpretation::NumMatched() const {
  return static_cast<int>(
      std::count_if(region.begin(), region.end(), [](int r) { return r >= 0; }));
}

InterpretationSearchResult SearchInterpretationTree(const std::vector<PlanarRegion>& regions,
                                                    const TruckBedModel& model,
                                                    const GroundEstimate& ground,
                                                    const InterpretationVerifier& verify,
                                                    const InterpretationTreeParams& params) {
  Validate(model);
  if (params.max_nodes <= 0) {
    throw std::invalid_argument("InterpretationTreeParams: max_nodes must be positive");
  }
  if (!verify) throw std::invalid_argument("SearchInterpretationTree: the verifier is empty");
  return Search(regions, model, ground, verify, params).Run();
}

}  // namespace autoshovel::perception
