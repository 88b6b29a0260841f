// How far the underside of the linkage is from known obstacle boxes (excavator seed §4.4: the
// planned motions must keep away from what is known to be in the workspace, the truck above
// all). Used by
// the script parameters' predictions to keep the truck clearance margin.
//
// The underside is a strip per link (its lower chain, extruded across the link's width) sampled
// at spacing s along and across, so every point of the strip lies within s/√2 of a sample and
// the sampled distance over-estimates the true one by at most s/√2 (distance is 1-Lipschitz).
// At the envelope's spacing (0.25 m) that is 0.18 m, too coarse for a 0.3 m margin; sampling
// everything at a few centimetres is too slow for a prediction. So each link is first measured
// at the envelope's spacing and re-measured at `fine_spacing` only when it comes within
// `refine_within` of a box: below refine_within − s/√2 the result is accurate to fine_spacing/√2.
#pragma once

#include <vector>

#include "runtime/control/excavator/linkage_envelope.h"
#include "runtime/control/excavator/obstacle_box.h"

namespace autoshovel::control {

/// Smallest signed distance from any of `points` to any of `boxes` [m] (+inf without boxes):
/// ObstacleBox::SignedDistance with each box's rotation computed once.
double MinClearance(const std::vector<EnvelopePoint>& points,
                    const std::vector<ObstacleBox>& boxes);

class LinkageClearance {
 public:
  /// Keeps a reference to `envelope` (it must outlive this). Throws std::invalid_argument on an
  /// invalid box, a non-positive fine spacing or refine_within.
  LinkageClearance(const LinkageEnvelope& envelope, std::vector<ObstacleBox> boxes,
                   double fine_spacing = 0.05, double refine_within = 1.0);

  /// Smallest distance from the underside at q (base frame) to the boxes [m]; +inf without boxes.
  double operator()(const JointVector& q) const { return Refined(q, refine_within_); }

  /// On the envelope's own samples only: never below the true distance, at most coarse_error()
  /// above it.
  double Coarse(const JointVector& q) const;
  /// Links whose coarse distance is below `within` re-measured on the fine samples.
  double Refined(const JointVector& q, double within) const;

  /// How much a refined result may over-estimate the true distance [m].
  double accuracy() const;
  /// How much a coarse result may over-estimate it [m].
  double coarse_error() const;

 private:
  const LinkageEnvelope& envelope_;
  std::vector<ObstacleBox> boxes_;
  double fine_spacing_;
  double refine_within_;
  double LinkDistance(const ArmPlanePins& pins, int link, double spacing) const;

  mutable std::vector<EnvelopePoint> scratch_;
};

}  // namespace autoshovel::control
