#include "runtime/app/shovel_job/control_task.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace autoshovel::app {

ControlTask::ControlTask(const model::MachineDescription& machine,
                         const control::ScoopCycleOptions& options)
    : machine_(machine),
      options_(options),
      boom_pid_(options.boom_gains,
                machine.hydraulics.actuators[machine.ActuatorOfJoint(0)].valve.dead_zone),
      bucket_pid_(options.bucket_gains,
                  machine.hydraulics.actuators[machine.ActuatorOfJoint(1)].valve.dead_zone),
      speed_pid_(options.speed_gains) {
  speed_pid_.Reset(0.0);
  command_.valve.assign(machine.hydraulics.actuators.size(), 0.0);
}

void ControlTask::Steer(NavigationGoal& nav, const control::Proprioception& s) {
  if (!nav.follower) return;
  const control::SteeringCommand steer =
      nav.follower->Update(s.hinge_xy, s.heading, s.articulation);
  remaining_ = steer.remaining;
  max_cross_track_ = std::max(max_cross_track_, std::abs(steer.cross_track));
  articulation_rate_ = steer.articulation_rate;
  target_speed_ = steer.speed;
}

void ControlTask::Navigate(PlantMachine& machine_io, const control::Proprioception& s) {
  speed_pid_.SetTarget(target_speed_);
  const control::DriveCommand drive = speed_pid_.Update(s.speed, options_.tick);
  command_.drive = drive.drive;
  command_.brake = drive.brake;
  command_.articulation_rate = articulation_rate_;
  command_.valve[machine_.ActuatorOfJoint(0)] =
      boom_pid_.Update(options_.attack_pose.boom, s.q_boom, s.qd_boom, options_.tick);
  command_.valve[machine_.ActuatorOfJoint(1)] =
      bucket_pid_.Update(options_.attack_pose.bucket, s.q_bucket, s.qd_bucket, options_.tick);
  std::string why;
  machine_io.Command(command_, &why);
}

void ControlTask::Hold(PlantMachine& machine_io) {
  command_.drive = 0, command_.brake = 1, command_.articulation_rate = 0;
  std::fill(command_.valve.begin(), command_.valve.end(), 0.0);
  std::string why;
  machine_io.Command(command_, &why);
}

bool ControlTask::BrakeToRest(PlantMachine& machine_io, double speed) {
  command_.drive = 0, command_.brake = 1, command_.articulation_rate = 0;
  std::string why;
  machine_io.Command(command_, &why);
  return std::abs(speed) < 0.01;
}

bool ControlTask::Scoop(control::ScoopCycle& scoop, PlantMachine& machine_io) {
  // Navigation keeps steering (the path, then straight on along the entry heading) for as long
  // as the scoop cycle drives forward: through approach and crowd, and through the scoop phase,
  // where the drive keeps crowding through the hydraulic delay and then decelerates over a metre
  // or more. Holding the articulation there instead drove an arc: a frame still articulated
  // 18.6° from correcting the approach swung the heading 11° off the planned line in 4 s and
  // took the bucket to 0.38 m from a side wall the selection had planned 0.65 m from
  // (docs/campaigns.md). Levelling, shaking and retreat hold it.
  const std::string phase = scoop.phase_name();
  const bool steering = phase == "approach" || phase == "crowd" || phase == "scoop";
  machine_io.SetSteeringOverride(steering ? articulation_rate_ : 0.0);
  return scoop.Tick(machine_io);
}

}  // namespace autoshovel::app
