// Scooping strategies, wheel-loader seed §6.2 and §7.4.2 (Table 5), as sequences of atomic actions
// (atomic_actions.h):
//  - "Just in & out": "rotating and retracting the bucket to a certain height, followed by lifting
//    the boom to a specific angle": one retract (to racked back) and one lift. Open loop: the
//    trigger (V1 + V2 ≥ V_t) is the only decision.
//  - "Stairway": "slightly lifting the boom, then retracting the bucket by a small angle, pausing
//    for a period, and repeating this process multiple times"; "a feedback loop between atomic
//    actions ... allowing the scooping to be completed once the volume reaches the target value,
//    rather than setting a fixed number of bucket retraction atomic actions."
//  - "Stairway #N" (the baseline of Cao et al. 2023, Table 5): N steps whatever the volume.
// Our readings: one Stairway step is a (lift, retract) pair followed by the pause; the adaptive
// Stairway makes at least one step and then checks the feedback volume before each further step
// (so "Stairway #1" of Table 6 is one step); every strategy ends by racking the bucket back (if a
// step did not already) and lifting the boom by the exit lift: that is how the bucket leaves the
// pile ("followed by lifting the boom"). Then levelling and shaking (FinishingParameters).
#pragma once

#include <optional>
#include <string>

#include "runtime/control/atomic_actions.h"

namespace autoshovel::control {

/// kOptimal: a planned trajectory tracked from contact (ScoopPolicy::kOptimal, scoop_cycle.h).
enum class ScoopStrategy { kJustInOut, kStairway, kStairwayFixed, kOptimal };
const char* ToString(ScoopStrategy strategy);

struct StrategyParameters {
  double exit_boom_lift = 0.35;  ///< boom travel of the final lift [rad]
  double step_boom_lift = 0.05;  ///< boom travel of a Stairway step's lift [rad]
  double step_retract = 0.3;     ///< bucket travel of a Stairway step's retract [rad]
  double step_pause = 0.3;       ///< pause after a Stairway step [s]
  int max_steps = 5;             ///< adaptive Stairway: at most this many steps
  int fixed_steps = 3;           ///< "Stairway #N": N

  std::string Invalid() const;
};

/// The end of a scoop, seed §6.2: "the bucket's upper edge is leveled, and the material is vibrated
/// to prevent overflow during transportation". Our reading: levelling turns the bucket until its
/// opening (cutting edge to the top of the back wall) is horizontal, tilted back by
/// `carry_tilt_back`, and holds it `level_hold`: what stands above the heaped capacity strikes
/// off over the edges. Shaking is `shake_pulses` open-loop pulses of alternating sign on the
/// bucket valve. The bucket is carried at that attitude (racking further back would tip the heap
/// out over the back wall).
struct FinishingParameters {
  double carry_tilt_back = 0;  ///< [rad]
  double level_hold = 0.3;     ///< [s]
  int shake_pulses = 6;        ///< [-]
  double shake_duty = 0.7;     ///< valve duty of a pulse [-]
  double shake_pulse = 0.12;   ///< length of one pulse [s]

  std::string Invalid() const;
};

/// What the scooping phase executes next. Call Next() each time the previous action (and its
/// pause) is over; nullopt means the scoop is complete.
class ScoopSequencer {
 public:
  /// Throws std::invalid_argument for invalid parameters.
  ScoopSequencer(ScoopStrategy strategy, const StrategyParameters& parameters,
                 const ArmLimits& limits);

  /// `targets`: the arm targets now [rad]; `feedback_volume`: the perceived volume now [m³]
  /// (read by the adaptive Stairway between actions); `target_volume`: V_t [m³].
  std::optional<AtomicAction> Next(const ArmTargets& targets, double feedback_volume,
                                   double target_volume);

  ScoopStrategy strategy() const { return strategy_; }
  int actions() const { return actions_; }  ///< atomic actions issued so far
  int steps() const { return steps_; }      ///< Stairway steps issued so far

 private:
  enum class Stage { kSteps, kRackBack, kExitLift, kDone };
  std::optional<AtomicAction> Issue(const AtomicAction& action);

  ScoopStrategy strategy_;
  StrategyParameters parameters_;
  ArmLimits limits_;
  Stage stage_;
  bool lift_next_ = true;  ///< within a step: the lift comes first, then the retract
  int steps_ = 0;
  int actions_ = 0;
};

}  // namespace autoshovel::control
