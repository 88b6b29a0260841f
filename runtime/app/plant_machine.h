// The simulated plant behind the control layer's ScoopMachine interface: what app/ (and the
// closed-loop tests) hand to a ScoopCycle when the machine is simulated. DESIGN.md: only app/
// and tests wire the plant to control.
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include "runtime/control/scoop_cycle.h"
#include "runtime/core/actuator_command.h"
#include "runtime/plant/plant.h"

namespace autoshovel::app {

/// Proprioception is the plant's true state (no sensor noise); the energy and payload meters are
/// the plant's counters. Every command passes through `steering_override` when set: navigation
/// steers while the scoop cycle (which never steers) drives.
class PlantMachine : public control::ScoopMachine {
 public:
  explicit PlantMachine(plant::Plant& plant);

  control::Proprioception Sense() const override;
  bool Command(const core::ActuatorCommand& command, std::string* why) override;
  void Advance(double dt) override { plant_.Advance(dt); }
  void SetPhase(const std::string& phase) override { plant_.SetPhase(phase); }
  double Energy() const override { return plant_.energy().total(); }
  double PayloadVolume() const override { return plant_.bucket().payload_volume(); }

  /// The articulation rate [rad/s] sent with every following command instead of the one the
  /// caller gives; NaN: the caller's.
  void SetSteeringOverride(double articulation_rate) { steering_override_ = articulation_rate; }

  // Faults (plant/fault_spec.h) and the safety interlock.
  /// The localisation's error: Sense() reports the hinge this far off and the heading turned.
  void SetPoseError(const Eigen::Vector2d& offset, double heading) {
    pose_offset_ = offset, heading_offset_ = heading;
  }
  /// The valve of `actuator` stays at neutral whatever is commanded (−1: none).
  void SetStuckValve(int actuator) { stuck_actuator_ = actuator; }
  /// Arm IMU faults on joint `joint` (0 boom, 1 bucket; −1: none): Sense() reports its angle
  /// `bias` too high, or, when `frozen`, the angle it had when the freeze began and a rate of 0.
  void SetJointReadingFault(int joint, double bias, bool frozen);
  /// White noise of 1σ `sigma` [rad] on the reported articulation and arm angles (0: none),
  /// drawn from a generator seeded with `seed` when the noise is switched on.
  void SetAngleNoise(double sigma, std::uint64_t seed);
  /// While held, every command is replaced by a stop: brake on, drive off, valves and steering
  /// at rest (the supervisor's interlock; it holds whatever the caller commands).
  void HoldStop(bool hold) { hold_stop_ = hold; }
  bool holding_stop() const { return hold_stop_; }
  /// The last command as the caller gave it (before faults and the interlock).
  const core::ActuatorCommand& last_command() const { return last_command_; }

  bool all_commands_finite() const { return all_finite_; }
  long commands() const { return commands_; }
  plant::Plant& plant() { return plant_; }

 private:
  plant::Plant& plant_;
  int boom_actuator_;
  int bucket_actuator_;
  double steering_override_;
  bool all_finite_ = true;
  long commands_ = 0;
  Eigen::Vector2d pose_offset_ = Eigen::Vector2d::Zero();
  double heading_offset_ = 0;
  int stuck_actuator_ = -1;
  int faulty_joint_ = -1;
  double joint_bias_ = 0;
  bool joint_frozen_ = false;
  double frozen_q_ = 0;
  double angle_noise_ = 0;
  mutable std::mt19937_64 noise_rng_;
  bool hold_stop_ = false;
  core::ActuatorCommand last_command_;
};

}  // namespace autoshovel::app
