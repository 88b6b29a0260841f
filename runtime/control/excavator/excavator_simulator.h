// The four joint models of joint_model.h run together with their command latencies: the
// prediction of where the linkage is going that the excavator seed uses in §4.4 (script
// parameters) and §4.5 (obstacle look-ahead). A command issued at time t acts on joint j from t +
// L_j; until then the joint follows the command before it. The look-ahead copies the simulator
// (state and commands still in flight) and runs the copy forward; the tests use one as the machine
// itself.
#pragma once

#include <deque>

#include "runtime/control/excavator/excavator_joints.h"
#include "runtime/control/excavator/joint_model.h"

namespace autoshovel::control {

class ExcavatorSimulator {
 public:
  /// Starts at rest-or-moving `initial` at time 0, holding its positions (as if the last command
  /// had been where the joints are). `integration_step` [s] bounds the step of Advance (the
  /// joints themselves are integrated in sub-steps of at most 5 ms, so the motion hardly
  /// depends on it).
  /// Throws std::invalid_argument on invalid models, a non-finite state or step.
  ExcavatorSimulator(const ExcavatorJointModels& models, const ExcavatorState& initial,
                     double integration_step = 0.01);

  /// Issues `command` now. Throws std::invalid_argument when a position is not finite (NaN must
  /// never reach the joints; a stop carries no positions and is always accepted).
  void Command(const ExcavatorCommand& command);

  /// Advances by `duration` [s] >= 0 in steps no longer than the integration step.
  void Advance(double duration);

  /// Replaces joint positions and rates by measured ones, keeping the commands in flight.
  void Resync(const ExcavatorState& measured);

  const ExcavatorState& state() const { return state_; }
  double time() const { return time_; }
  const ExcavatorJointModels& models() const { return models_; }
  double integration_step() const { return integration_step_; }
  /// Changes the integration step (a prediction may integrate more coarsely than the mirror it
  /// was copied from). Throws std::invalid_argument unless positive.
  void set_integration_step(double step);
  /// The command acting on `joint` now (after its latency).
  const ExcavatorCommand& EffectiveCommand(ExcavatorJoint joint) const;
  /// Whether the latest command issued is a stop.
  bool stopping() const { return !issued_.empty() && issued_.back().command.stop; }

 private:
  struct Issued {
    double time;
    ExcavatorCommand command;
  };
  void Step(double dt);
  void Prune();

  ExcavatorJointModels models_;
  ExcavatorState state_;
  double time_ = 0;
  double integration_step_;
  double max_latency_ = 0;
  std::deque<Issued> issued_;  ///< oldest first; the first is in effect for every joint
};

}  // namespace autoshovel::control
