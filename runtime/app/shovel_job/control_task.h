// The main job's 100 Hz control (seed Fig. 2, "control"): while navigating, the path follower
// steers and the speed and joint PIDs hold the attack pose; once handed over, the scoop cycle
// commands the machine, steered along the entry heading while it drives in; at a safe stop the
// machine brakes to rest.
#pragma once

#include <vector>

#include "runtime/app/plant_machine.h"
#include "runtime/app/shovel_job/navigation_goal.h"
#include "runtime/control/joint_pid.h"
#include "runtime/control/scoop_cycle.h"
#include "runtime/control/speed_pid.h"

namespace autoshovel::app {

class ControlTask {
 public:
  ControlTask(const model::MachineDescription& machine, const control::ScoopCycleOptions& options);

  /// Follows the goal's path (when there is a follower): the steering and the speed target.
  void Steer(NavigationGoal& nav, const control::Proprioception& s);
  /// Drives along the path in the attack pose.
  void Navigate(PlantMachine& machine_io, const control::Proprioception& s);
  /// Stands braked with the valves closed (while selecting).
  void Hold(PlantMachine& machine_io);
  /// Brakes to rest; true once at rest.
  bool BrakeToRest(PlantMachine& machine_io, double speed);
  /// The scoop cycle's tick, steered along the path while it drives in; false once it is over.
  bool Scoop(control::ScoopCycle& scoop, PlantMachine& machine_io);

  control::SpeedPid& speed_pid() { return speed_pid_; }
  double target_speed() const { return target_speed_; }
  double remaining() const { return remaining_; }              ///< path left [m]
  double max_cross_track() const { return max_cross_track_; }  ///< [m]

 private:
  const model::MachineDescription& machine_;
  control::ScoopCycleOptions options_;
  control::JointPid boom_pid_;
  control::JointPid bucket_pid_;
  control::SpeedPid speed_pid_;
  core::ActuatorCommand command_;
  double target_speed_ = 0;
  double articulation_rate_ = 0;
  double remaining_ = INFINITY;
  double max_cross_track_ = 0;  ///< largest distance of the front axle from its path [m]
};

}  // namespace autoshovel::app
