// Verification of a complete interpretation (excavator seed §4.1: a closer consistency check of
// the truck's parameters than the tree's, and the corner points of the opening). The tree only
// checked centroids, extents and angles of regions pairwise, within tolerances; here the fitted bed
// (bed_fit.h) must hold up as a whole:
//   1. dimensions: length, width and, when measurable, wall height, floor height and rim height
//      above the ground lie in the model's ranges;
//   2. planarity against the fitted rectangle: each wall's returns lie close to its fitted side;
//   3. coverage: the near outside face, which the scanner sees whole, spans most of the length,
//      and the floor seen lies within the bed's outline (not a flat beyond it: the chassis seen
//      through the gap to the cab);
//   4. free space: an empty bed is an empty box with solid sides and a floor, so a return
//      contradicts the interpretation when it lies
//        - inside the box (away from walls and floor by a margin, up to some height above the
//          rim),
//        - beyond the near wall although its beam crossed the wall's rectangle (the wall has a
//          hole: e.g. the gap between a headboard and a cab mistaken for one bed),
//        - below the lowest possible floor although its beam came in through the opening.
//      This separates an open bed from a solid block whose faces happen to line up, from two
//      free-standing walls, and from a bed stretched to a cab's rear face;
//   5. a chassis: the model's floor stands at least floor_height.min above the ground, so the
//      bed's near outside face, seen whole, must not reach the ground along most of its length
//      (wheels reach it, the gaps between axles do not). An open box standing on the ground (a
//      skip) is not a truck even where its walls hide its floor;
//   6. front and rear: every truck has its cab ahead of the headboard. Returns in a box ahead of
//      each end decide which end is the front when no end wall was matched (and must then be
//      there at all), and reject an interpretation whose "tailgate" has the cab behind it.
// The score (support, minus a penalty per contradicting return, plus a little for cab evidence
// ahead rather than behind) ranks verified interpretations that match the same number of faces.
#pragma once

#include <string>
#include <vector>

#include "runtime/perception/truck/bed_fit.h"
#include "runtime/perception/truck/scanline.h"

namespace autoshovel::perception {

struct VerificationParams {
  double dimension_tolerance = 0.1;  ///< slack on the model's ranges [m]
  double max_face_rms = 0.08;        ///< RMS of a wall's returns about its fitted side [m]
  double min_near_coverage = 0.5;    ///< fraction of the length the near outside face spans
  /// The free-space tests keep this distance from walls and floor: several σ of range noise plus
  /// the wall-thickness uncertainty [m].
  double free_space_margin = 0.2;
  double free_space_height_above_rim = 1.0;  ///< the free box reaches this far above the rim [m]
  int max_violations = 15;                   ///< contradicting returns allowed (outliers) ...
  double max_violation_fraction = 0.01;      ///< ... or this fraction of the support, if larger
  double violation_penalty = 10;             ///< score lost per contradicting return
  /// Score per return of cab evidence ahead of the front beyond that behind the rear: between
  /// interpretations that differ only in which end wall is which, the one with the cab ahead.
  double cab_weight = 0.1;
  /// A near-wall scanline whose lowest return is within this height of the ground touches it [m].
  double ground_contact_height = 0.3;
  /// Largest fraction of the near wall's scanlines that may touch the ground (5.).
  double max_ground_contact = 0.8;
  double cab_search_length = 3.5;  ///< length of the box searched ahead of each end [m]
  /// Returns that count as a cab: needed ahead of one end when no end wall was matched, and
  /// behind the tailgate to overrule a matched end wall.
  int min_cab_points = 20;
};

/// Throws std::invalid_argument naming the offending field.
void Validate(const VerificationParams& params);

struct BedVerification {
  bool passed = false;
  std::string reason;             ///< why it failed (empty when passed)
  int support_points = 0;         ///< returns on the matched faces
  int free_space_violations = 0;  ///< returns contradicting an empty bed (4.)
  int cab_points_front = 0;
  int cab_points_rear = 0;
  double near_coverage = 0;
  double ground_contact = 0;  ///< fraction of near-wall scanlines touching the ground (5.)
  double score = 0;
};

/// Checks `fit` and settles which end is the front (6.): it may turn the fit round, and takes the
/// nominal wall thickness off a front end that came from the near wall's extent (bed_fit.h).
/// Needs the scanlines for the free-space tests.
BedVerification VerifyBed(BedFit& fit, const std::vector<LineSegment>& segments,
                          const std::vector<Scanline>& scanlines, const TruckBedModel& model,
                          const VerificationParams& params = {});

}  // namespace autoshovel::perception
