// The plant as a ScoopMachine (plant_machine.h).
#include "runtime/app/plant_machine.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace autoshovel::app {

PlantMachine::PlantMachine(plant::Plant& plant)
    : plant_(plant),
      boom_actuator_(plant.machine().ActuatorOfJoint(0)),
      bucket_actuator_(plant.machine().ActuatorOfJoint(1)),
      steering_override_(std::nan("")) {}

control::Proprioception PlantMachine::Sense() const {
  const plant::MachineState& s = plant_.state();
  control::Proprioception p;
  p.time = s.time;
  p.hinge_xy = s.hinge_xy + pose_offset_;
  p.heading = std::remainder(s.heading + heading_offset_, 2 * std::numbers::pi);
  p.articulation = s.articulation;
  p.speed = s.speed;
  p.q_boom = s.q[0], p.q_bucket = s.q[1];
  p.qd_boom = s.qd[0], p.qd_bucket = s.qd[1];
  p.boom_pressure = boom_actuator_ >= 0 ? plant_.ActuatorPressure(boom_actuator_, true) : 0.0;
  if (boom_actuator_ >= 0) p.boom_pressure_rod = plant_.ActuatorPressure(boom_actuator_, false);
  p.pump_pressure = plant_.PumpPressure();
  if (bucket_actuator_ >= 0) {
    p.bucket_pressure_cap = plant_.ActuatorPressure(bucket_actuator_, true);
    p.bucket_pressure_rod = plant_.ActuatorPressure(bucket_actuator_, false);
  }
  if (faulty_joint_ >= 0) {
    double& q = faulty_joint_ == 0 ? p.q_boom : p.q_bucket;
    double& qd = faulty_joint_ == 0 ? p.qd_boom : p.qd_bucket;
    if (joint_frozen_) {
      q = frozen_q_, qd = 0;
    } else {
      q += joint_bias_;
    }
  }
  if (angle_noise_ > 0) {
    std::normal_distribution<double> n(0.0, angle_noise_);
    p.articulation += n(noise_rng_);
    p.q_boom += n(noise_rng_);
    p.q_bucket += n(noise_rng_);
  }
  return p;
}

void PlantMachine::SetJointReadingFault(int joint, double bias, bool frozen) {
  if (frozen && (!joint_frozen_ || joint != faulty_joint_) && (joint == 0 || joint == 1)) {
    frozen_q_ = plant_.state().q[joint];  // the reading it had when the freeze began
  }
  faulty_joint_ = joint == 0 || joint == 1 ? joint : -1;
  joint_bias_ = bias;
  joint_frozen_ = frozen && faulty_joint_ >= 0;
}

void PlantMachine::SetAngleNoise(double sigma, std::uint64_t seed) {
  if (sigma > 0 && angle_noise_ <= 0) noise_rng_.seed(seed);
  angle_noise_ = sigma;
}

bool PlantMachine::Command(const core::ActuatorCommand& command, std::string* why) {
  last_command_ = command;
  core::ActuatorCommand sent = command;
  if (std::isfinite(steering_override_)) sent.articulation_rate = steering_override_;
  if (stuck_actuator_ >= 0 && stuck_actuator_ < static_cast<int>(sent.valve.size())) {
    sent.valve[static_cast<std::size_t>(stuck_actuator_)] = 0.0;
  }
  if (hold_stop_) {
    sent.drive = 0, sent.brake = 1, sent.articulation_rate = 0;
    std::fill(sent.valve.begin(), sent.valve.end(), 0.0);
  }
  for (double u : sent.valve) all_finite_ = all_finite_ && std::isfinite(u);
  all_finite_ = all_finite_ && std::isfinite(sent.drive) && std::isfinite(sent.brake) &&
                std::isfinite(sent.articulation_rate);
  ++commands_;
  return plant_.SetCommand(sent, why);
}

}  // namespace autoshovel::app
