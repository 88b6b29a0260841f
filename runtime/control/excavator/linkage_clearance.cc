#include "runtime/control/excavator/linkage_clearance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace autoshovel::control {

double MinClearance(const std::vector<EnvelopePoint>& points,
                    const std::vector<ObstacleBox>& boxes) {
  double clearance = std::numeric_limits<double>::infinity();
  for (const ObstacleBox& box : boxes) {
    const double c = std::cos(box.yaw), s = std::sin(box.yaw);
    const double half_height = 0.5 * (box.z_max - box.z_min);
    const double mid_height = 0.5 * (box.z_max + box.z_min);
    for (const EnvelopePoint& p : points) {
      const double dx = p.p.x() - box.center.x(), dy = p.p.y() - box.center.y();
      const double ox = std::abs(c * dx + s * dy) - box.half_extents.x();
      const double oy = std::abs(-s * dx + c * dy) - box.half_extents.y();
      const double oz = std::abs(p.p.z() - mid_height) - half_height;
      const double px = std::max(ox, 0.0), py = std::max(oy, 0.0), pz = std::max(oz, 0.0);
      const double d =
          std::sqrt(px * px + py * py + pz * pz) + std::min(std::max({ox, oy, oz}), 0.0);
      clearance = std::min(clearance, d);
    }
  }
  return clearance;
}

LinkageClearance::LinkageClearance(const LinkageEnvelope& envelope, std::vector<ObstacleBox> boxes,
                                   double fine_spacing, double refine_within)
    : envelope_(envelope),
      boxes_(std::move(boxes)),
      fine_spacing_(fine_spacing),
      refine_within_(refine_within) {
  for (const ObstacleBox& box : boxes_) Validate(box, "LinkageClearance");
  if (!(std::isfinite(fine_spacing) && fine_spacing > 0) ||
      !(std::isfinite(refine_within) && refine_within > 0)) {
    throw std::invalid_argument("LinkageClearance: fine_spacing and refine_within must be > 0");
  }
}

double LinkageClearance::LinkDistance(const ArmPlanePins& pins, int link, double spacing) const {
  scratch_.clear();
  envelope_.AppendLinkUnderside(pins, static_cast<LinkageLink>(link), spacing,
                                Eigen::Isometry3d::Identity(), scratch_);
  return MinClearance(scratch_, boxes_);
}

double LinkageClearance::Coarse(const JointVector& q) const {
  if (boxes_.empty()) return std::numeric_limits<double>::infinity();
  const ArmPlanePins pins = envelope_.kinematics().Pins(q);
  double clearance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    clearance = std::min(clearance, LinkDistance(pins, k, envelope_.config().max_spacing));
  }
  return clearance;
}

double LinkageClearance::Refined(const JointVector& q, double within) const {
  if (boxes_.empty()) return std::numeric_limits<double>::infinity();
  const ArmPlanePins pins = envelope_.kinematics().Pins(q);
  double clearance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    double d = LinkDistance(pins, k, envelope_.config().max_spacing);
    if (d < within) d = LinkDistance(pins, k, fine_spacing_);
    clearance = std::min(clearance, d);
  }
  return clearance;
}

double LinkageClearance::coarse_error() const {
  return envelope_.config().max_spacing / std::sqrt(2.0);
}

double LinkageClearance::accuracy() const { return fine_spacing_ / std::sqrt(2.0); }

}  // namespace autoshovel::control
