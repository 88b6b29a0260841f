// Atomic actions (seed §6.2): retract the bucket by an angle, lift the boom by an angle.
#include "runtime/control/atomic_actions.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

AtomicAction RetractBucket(double travel, double pause) {
  return {.kind = AtomicKind::kRetractBucket, .travel = travel, .pause = pause};
}

AtomicAction LiftBoom(double travel, double pause) {
  return {.kind = AtomicKind::kLiftBoom, .travel = travel, .pause = pause};
}

const char* ToString(AtomicKind kind) {
  return kind == AtomicKind::kRetractBucket ? "retract_bucket" : "lift_boom";
}

ArmTargets TargetsAfter(const AtomicAction& action, const ArmTargets& start,
                        const ArmLimits& limits) {
  if (!std::isfinite(action.travel) || action.travel < 0) {
    throw std::invalid_argument("atomic action " + std::string(ToString(action.kind)) +
                                ": travel must be finite and >= 0 rad, got " +
                                std::to_string(action.travel));
  }
  ArmTargets out = start;
  if (action.kind == AtomicKind::kRetractBucket) {
    out.bucket = std::max(start.bucket, std::min(start.bucket + action.travel, limits.bucket_max));
  } else {
    out.boom = std::max(start.boom, std::min(start.boom + action.travel, limits.boom_max));
  }
  return out;
}

}  // namespace autoshovel::control
