// Atomic actions of the scooping phase, wheel-loader seed §6.2: "Retracting the bucket to a
// designated angle and lifting the boom to a designated angle can be considered as two distinct
// atomic actions." An action moves one joint by a travel [rad] from where its target stood when
// the action began; the other joint's target is held. The joint PIDs (joint_pid.h) execute it.
#pragma once

#include <string>

namespace autoshovel::control {

/// Position targets of a two-link loader arm [rad] (model joint order: boom, bucket).
struct ArmTargets {
  double boom = 0;
  double bucket = 0;
};

/// The joint ranges an action may command [rad]: the description's limits, less margins.
struct ArmLimits {
  double boom_max = 0;    ///< highest boom target
  double bucket_max = 0;  ///< racked-back bucket target
};

enum class AtomicKind { kRetractBucket, kLiftBoom };

struct AtomicAction {
  AtomicKind kind = AtomicKind::kRetractBucket;
  double travel = 0;  ///< joint travel, ≥ 0 (retract = bucket towards racked, lift = boom up) [rad]
  double pause = 0;  ///< hold after reaching the target before the next action [s]
};

AtomicAction RetractBucket(double travel, double pause = 0);
AtomicAction LiftBoom(double travel, double pause = 0);
const char* ToString(AtomicKind kind);

/// The targets once `action` is applied to `start`, clipped to `limits`. Throws
/// std::invalid_argument for a negative or non-finite travel.
ArmTargets TargetsAfter(const AtomicAction& action, const ArmTargets& start,
                        const ArmLimits& limits);

}  // namespace autoshovel::control
