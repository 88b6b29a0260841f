// Step 3 of truck recognition (excavator seed §4.1, after Grimson 1990): an interpretation tree
// assigns scene regions to the model's faces. Level k of the tree decides face k: one of the
// regions that pass the face's unary constraints and are not used by another face, or "none"
// (the face is hidden or missing, e.g. a floor below high walls, a body without tailgate). The
// tree is searched depth-first; a branch is cut as soon as the new pairing violates a pairwise
// constraint with any pairing above it (truck_model.h: the parameter ranges are checked at every
// level), and, once an interpretation has been verified, as soon as the branch can no longer match
// as many faces as it did (the seed keeps the verified interpretation with the largest number of
// matched faces).
//
// Every complete interpretation with at least `min_matched_faces` faces, the two side walls among
// them, is handed to the verifier (bed_verification.h); the best verified one wins: most faces,
// then the verifier's score.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <vector>

#include "runtime/perception/truck/planar_regions.h"
#include "runtime/perception/truck/truck_model.h"

namespace autoshovel::perception {

/// Model face → scene region (index into the region vector), -1 where the face is "none".
struct Interpretation {
  std::array<int, kNumBedFaces> region{-1, -1, -1, -1, -1};

  int operator[](BedFace face) const { return region[static_cast<std::size_t>(FaceIndex(face))]; }
  int& operator[](BedFace face) { return region[static_cast<std::size_t>(FaceIndex(face))]; }
  int NumMatched() const;
};

/// Verifies a complete interpretation: a score (larger is better) or nullopt if it fails.
using InterpretationVerifier = std::function<std::optional<double>(const Interpretation&)>;

struct InterpretationTreeParams {
  /// Hard cap on expanded nodes, against pathological clutter; the search then reports
  /// truncation and returns the best found so far.
  long max_nodes = 200000;
};

struct InterpretationSearchResult {
  bool found = false;
  Interpretation best;
  double best_score = 0;
  long nodes = 0;          ///< tree nodes expanded
  int complete = 0;        ///< complete interpretations handed to the verifier
  int verified = 0;        ///< of those, the ones that passed
  bool truncated = false;  ///< max_nodes was reached
  /// Regions passing each face's unary constraints (the branching factor of each level).
  std::array<int, kNumBedFaces> candidates{0, 0, 0, 0, 0};
};

/// Throws std::invalid_argument if the model or the parameters are invalid or `verify` is empty.
InterpretationSearchResult SearchInterpretationTree(const std::vector<PlanarRegion>& regions,
                                                    const TruckBedModel& model,
                                                    const GroundEstimate& ground,
                                                    const InterpretationVerifier& verify,
                                                    const InterpretationTreeParams& params = {});

}  // namespace autoshovel::perception
