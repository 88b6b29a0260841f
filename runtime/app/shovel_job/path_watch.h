// The safety supervisor's watch while the machine drives to its goal (seed §5.2; docs/main_job.md):
// the sensor watchdog (no motion on a stale map, nor on one from a degraded sensor) and the
// look-ahead along the rest of the planned path, for obstacles the path was not planned round (a
// person who stepped onto it). It stops the machine, and lets it drive on once the reason has
// been gone for a while.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "runtime/app/plant_machine.h"
#include "runtime/app/safety_supervisor.h"
#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/app/shovel_job/navigation_goal.h"
#include "runtime/app/stop_hold.h"
#include "runtime/control/speed_pid.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

/// Where the machine was when the last stop began, how fast it went, how far it went after.
struct StopRecord {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double speed = 0;   ///< [m/s]
  double travel = 0;  ///< farthest from `xy` since [m]
  void Begin(const Eigen::Vector2d& hinge_xy, double speed_now) {
    xy = hinge_xy;
    speed = std::abs(speed_now);
  }
  void Track(const Eigen::Vector2d& hinge_xy) { travel = std::max(travel, (hinge_xy - xy).norm()); }
};

struct PathWatchConfig {
  double safety_distance = 0;   ///< [m]
  double planning_margin = 0;   ///< [m]
  double resume_clearance = 0;  ///< more clearance needed to drive on than to stop [m]
  double resume_after = 0;      ///< the reason gone this long before driving on [s]
  double decision_rate = 20;    ///< [Hz]
  double max_deceleration = 1;  ///< of the speed profile [m/s²]
};

/// Distance from the bucket's front edge along the rest of the planned path to the first of
/// `sure_cells` within `tube` of it that the path was not planned round, looking `horizon`
/// ahead of the front axle [m] (+inf when none); `blocking` receives that cell.
double ObstacleAheadOnPath(const NavigationGoal& nav,
                           const std::vector<Eigen::Vector2d>& sure_cells,
                           const perception::GridMap& map, const Eigen::Vector2d& front_axle,
                           double front_beyond_axle, double tube, double horizon,
                           Eigen::Vector2d* blocking);

class PathWatch {
 public:
  explicit PathWatch(const PathWatchConfig& config) : config_(config), hold_(config.resume_after) {}

  /// One 20 Hz check while navigating: `degraded` from the last map update, `sensed` what the
  /// machine senses, `truth` where it is (the stop record), `world` for the log's truth.
  void Check(double time, const std::string& degraded, const control::Proprioception& sensed,
             const plant::MachineState& truth, const model::MachineDescription& machine,
             const NavigationGoal& nav, const std::vector<Eigen::Vector2d>& sure_cells,
             const perception::GridMap& map, const plant::World& world,
             SafetySupervisor& supervisor, PlantMachine& machine_io, control::SpeedPid& speed_pid,
             StopRecord& stops, double t0, const CycleLog& log);

 private:
  PathWatchConfig config_;
  StopHold hold_;
};

}  // namespace autoshovel::app
