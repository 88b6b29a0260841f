#include "runtime/control/excavator/excavator_simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::control {

ExcavatorSimulator::ExcavatorSimulator(const ExcavatorJointModels& models,
                                       const ExcavatorState& initial, double integration_step)
    : models_(models), state_(initial), integration_step_(integration_step) {
  Validate(models_);
  set_integration_step(integration_step);
  Resync(initial);
  for (const JointModelParams& p : models_) max_latency_ = std::max(max_latency_, p.latency);
  // Before any command the joints hold where they are: an issued hold at -infinity.
  issued_.push_back({-1e300, ExcavatorCommand{initial.q, false}});
}

void ExcavatorSimulator::set_integration_step(double step) {
  if (!(std::isfinite(step) && step > 0)) {
    throw std::invalid_argument("ExcavatorSimulator: integration_step must be positive");
  }
  integration_step_ = step;
}

void ExcavatorSimulator::Command(const ExcavatorCommand& command) {
  if (!command.stop) {
    const int bad = FirstNonFinite(command.position);
    if (bad >= 0) {
      throw std::invalid_argument("ExcavatorSimulator: non-finite command for the " +
                                  std::string(JointName(kAllExcavatorJoints[bad])));
    }
  }
  issued_.push_back({time_, command});
}

void ExcavatorSimulator::Resync(const ExcavatorState& measured) {
  if (FirstNonFinite(measured.q) >= 0 || FirstNonFinite(measured.qd) >= 0) {
    throw std::invalid_argument("ExcavatorSimulator: non-finite joint state");
  }
  state_ = measured;
}

const ExcavatorCommand& ExcavatorSimulator::EffectiveCommand(ExcavatorJoint joint) const {
  const double latency = models_[JointIndex(joint)].latency;
  // The newest command whose latency has passed (1 ns slack against rounding of the clock).
  for (auto it = issued_.rbegin(); it != issued_.rend(); ++it) {
    if (it->time + latency <= time_ + 1e-9) return it->command;
  }
  return issued_.front().command;
}

void ExcavatorSimulator::Advance(double duration) {
  if (!(std::isfinite(duration) && duration >= 0)) {
    throw std::invalid_argument("ExcavatorSimulator::Advance: duration must be >= 0");
  }
  // Steps end where a command takes effect on some joint, so that the trajectory does not depend
  // on where the integration grid happens to fall against the latencies.
  const double end = time_ + duration;
  while (end - time_ > 1e-12) {
    double next = std::min(end, time_ + integration_step_);
    for (const Issued& issued : issued_) {
      for (const JointModelParams& p : models_) {
        const double effect = issued.time + p.latency;
        if (effect > time_ + 1e-9 && effect < next - 1e-9) next = effect;
      }
    }
    Step(next - time_);
    time_ = next;  // exact, against the accumulation of rounding in Step
  }
  Prune();
}

void ExcavatorSimulator::Step(double dt) {
  // The joints are integrated in sub-steps of at most kJointStep whatever the caller's step, so
  // that a prediction stepping 20 ms and a machine stepping 10 ms follow the same motion (the
  // proportional approach is otherwise integrated with an error of dt/2τ of the remaining
  // distance). Commands cannot change inside a step: Advance ends steps where they take effect.
  constexpr double kJointStep = 0.005;
  const int substeps = std::max(1, static_cast<int>(std::ceil(dt / kJointStep - 1e-9)));
  const double h = dt / substeps;
  for (ExcavatorJoint joint : kAllExcavatorJoints) {
    const int j = JointIndex(joint);
    const ExcavatorCommand& command = EffectiveCommand(joint);
    JointMotion motion{state_.q[j], state_.qd[j]};
    for (int i = 0; i < substeps; ++i) {
      motion = StepJoint(models_[j], motion, command.position[j], command.stop, h);
    }
    state_.q[j] = motion.position;
    state_.qd[j] = motion.velocity;
  }
  time_ += dt;
}

void ExcavatorSimulator::Prune() {
  // Keep the newest command that is in effect for every joint and everything after it.
  while (issued_.size() > 1 && issued_[1].time + max_latency_ <= time_ + 1e-9) {
    issued_.pop_front();
  }
}

}  // namespace autoshovel::control
