// The truck-loading script of the excavator seed §4.4, Fig. 14: one rule list per joint (swing,
// boom, stick, bucket). A rule's left-hand side is a condition on the excavator's state (joint
// positions); its right-hand side is a desired joint position sent to that joint's low-level
// controller. Every joint has a script of its own, and of each script one rule at a time is in
// force: a joint's rules are steps taken in order. The first rule of every joint becomes active
// when the script starts, the moment digging has finished; at each evaluation (10 Hz, the
// seed's rate) a joint moves on to its next rule when that rule's condition holds, one rule per
// evaluation at most, and its active rule's command is sent. Rules never go back, so a condition
// such as "swing below 60°" in a later rule refers to the swing on its way back (the boom's
// lowering rule of Fig. 14 is read the same way, see script_parameters.h).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "runtime/control/excavator/excavator_joints.h"

namespace autoshovel::control {

enum class Comparison { kAbove, kBelow, kNear };

/// One term of a left-hand side: joint `joint` > value, < value, or within `tolerance` of it.
struct ConditionTerm {
  ExcavatorJoint joint = ExcavatorJoint::kSwing;
  Comparison comparison = Comparison::kAbove;
  double value = 0;      ///< [rad]
  double tolerance = 0;  ///< kNear only [rad]

  bool Holds(const JointVector& q) const;
  std::string ToString() const;  ///< e.g. "swing > 31.0°"
};

struct ScriptRule {
  std::string action;                    ///< what it does, e.g. "swing to truck"
  std::vector<ConditionTerm> condition;  ///< all must hold; empty only for the first rule
  double command = 0;                    ///< desired position of the script's joint [rad]
};

struct JointScript {
  ExcavatorJoint joint = ExcavatorJoint::kSwing;
  std::vector<ScriptRule> rules;
};

/// What one evaluation gives.
struct ScriptOutput {
  ExcavatorCommand command;  ///< a stop when the state cannot be evaluated
  std::array<int, kNumExcavatorJoints> active_rule{};
  std::string reason;  ///< why it stopped ("" otherwise)
};

class LoadingScript {
 public:
  static constexpr double kPeriod = 0.1;  ///< the seed's rule evaluation rate, 10 Hz [s]

  /// `scripts` indexed by joint (scripts[JointIndex(j)].joint == j). Throws
  /// std::invalid_argument naming the joint and rule when a script is empty, its first rule has
  /// a condition or a later one has none, or a value is not finite. Starts with every joint on
  /// its first rule (digging has just finished).
  explicit LoadingScript(std::array<JointScript, kNumExcavatorJoints> scripts);

  /// One evaluation on measured joint positions `q`. A non-finite q gives a stop with the reason
  /// and changes nothing (NaN never reaches a command).
  ScriptOutput Step(const JointVector& q);

  int active_rule(ExcavatorJoint joint) const { return active_[JointIndex(joint)]; }
  /// The active rules' commands.
  JointVector Commands() const;
  /// Every joint on its last rule.
  bool AtFinalRules() const;
  /// On the last rules, every joint within `position_tolerance` [rad] of its command and slower
  /// than `velocity_tolerance` [rad/s]: the pass is over and digging may start.
  bool Finished(const ExcavatorState& state, double position_tolerance,
                double velocity_tolerance) const;
  const JointScript& script(ExcavatorJoint joint) const { return scripts_[JointIndex(joint)]; }
  /// The scripts as a table in the order of Fig. 14 (swing, boom, stick, bucket), degrees.
  std::string Describe() const;

 private:
  std::array<JointScript, kNumExcavatorJoints> scripts_;
  std::array<int, kNumExcavatorJoints> active_{};
};

}  // namespace autoshovel::control
