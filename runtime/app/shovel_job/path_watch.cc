#include "runtime/app/shovel_job/path_watch.h"

#include <cmath>

#include "runtime/app/shovel_job/sure_cell_report.h"
#include "runtime/perception/machine_footprint.h"
#include "runtime/prediction/volume_estimation.h"

namespace autoshovel::app {

double ObstacleAheadOnPath(const NavigationGoal& nav,
                           const std::vector<Eigen::Vector2d>& sure_cells,
                           const perception::GridMap& map, const Eigen::Vector2d& front_axle,
                           double front_beyond_axle, double tube, double horizon,
                           Eigen::Vector2d* blocking) {
  double ahead = INFINITY;
  if (!nav.goal || sure_cells.empty()) return ahead;
  const std::vector<planning::PathSample> path = planning::SamplePath(nav.goal->path, 0.2);
  std::size_t k0 = 0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    if ((path[k].xy - front_axle).norm() < (path[k0].xy - front_axle).norm()) k0 = k;
  }
  const Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>& planned = nav.planned_obstacles;
  std::vector<Eigen::Vector2d> near;
  for (const Eigen::Vector2d& c : sure_cells) {
    // Within two cells of one it was planned round: more of that obstacle, come into view as
    // the machine drove on (a parked loader's far side), not a newcomer.
    perception::Index i;
    bool planned_round = false;
    if (map.IndexOf(c, i)) {
      for (int dx = -2; dx <= 2 && !planned_round; ++dx) {
        for (int dy = -2; dy <= 2 && !planned_round; ++dy) {
          const int x = i.x() + dx, y = i.y() + dy;
          planned_round =
              x >= 0 && y >= 0 && x < planned.rows() && y < planned.cols() && planned(x, y);
        }
      }
    }
    if (!planned_round && (c - front_axle).norm() < horizon + tube) near.push_back(c);
  }
  for (std::size_t k = k0; k < path.size() && std::isinf(ahead); ++k) {
    const double along = path[k].s - path[k0].s;
    if (along > horizon) break;
    // From the bucket's front edge on: beside the body lie its own returns' fringe (the map's
    // cells straddle the self-filter's outline) and what the planner kept clear.
    if (along < front_beyond_axle - 0.3) continue;
    for (const Eigen::Vector2d& c : near) {
      if ((c - path[k].xy).norm() < tube) {
        ahead = along - front_beyond_axle;
        *blocking = c;
        break;
      }
    }
  }
  return ahead;
}

void PathWatch::Check(double time, const std::string& degraded,
                      const control::Proprioception& sensed, const plant::MachineState& truth,
                      const model::MachineDescription& machine, const NavigationGoal& nav,
                      const std::vector<Eigen::Vector2d>& sure_cells,
                      const perception::GridMap& map, const plant::World& world,
                      SafetySupervisor& supervisor, PlantMachine& machine_io,
                      control::SpeedPid& speed_pid, StopRecord& stops, double t0,
                      const CycleLog& log) {
  std::string stale = supervisor.StaleSensors(time);
  if (!degraded.empty()) stale += (stale.empty() ? "" : ", ") + degraded;
  // A tube of the body's half width plus half the safety distance round the rest of the planned
  // path (one beside it makes the 7 Hz re-selection plan round them). The distance is from the
  // bucket's front edge along the path.
  const double v = std::max(0.0, sensed.speed);
  const double stopping = v / config_.decision_rate + v * v / (2 * config_.max_deceleration);
  const double reach = prediction::TipInBase(machine, sensed.q_boom, sensed.q_bucket).x();
  const double lf = machine.chassis.hinge_to_front_axle;
  const double front_beyond_axle = reach + 0.3 - lf;
  const perception::MachineFootprint body = perception::LoaderFootprint(
      machine, sensed.hinge_xy, sensed.heading, sensed.articulation, reach);
  const double tube = body.half_width + config_.safety_distance / 2;
  const double needed = config_.safety_distance + config_.planning_margin + stopping +
                        map.resolution() + (supervisor.stopped() ? config_.resume_clearance : 0.0);
  const Eigen::Vector2d axle =
      sensed.hinge_xy + lf * Eigen::Vector2d(std::cos(sensed.heading), std::sin(sensed.heading));
  Eigen::Vector2d blocking_cell = Eigen::Vector2d::Zero();
  const double ahead = ObstacleAheadOnPath(nav, sure_cells, map, axle, front_beyond_axle, tube,
                                           front_beyond_axle + needed + 1.0, &blocking_cell);
  const bool blocked = ahead < needed;
  const std::string why = !stale.empty() ? "sensor watchdog: " + stale
                          : blocked ? "obstacle " + Fixed(ahead, 2) + " m ahead on the path; " +
                                          SureCellReport(map, blocking_cell, world)
                                    : "";
  const std::string was = supervisor.reason();
  switch (hold_.Update(time, why, supervisor)) {
    case StopHold::Change::kStopped:
      machine_io.HoldStop(true);
      stops.Begin(truth.hinge_xy, truth.speed);
      log.Say("stop at t = " + Fixed(time - t0, 2) + " s: " + why);
      break;
    case StopHold::Change::kResumed:
      log.Say("drives on at t = " + Fixed(time - t0, 2) + " s (was: " + was + ")");
      machine_io.HoldStop(false);
      speed_pid.Reset(sensed.speed);  // its integral wound up against the brake
      break;
    case StopHold::Change::kNone:
      break;
  }
  if (supervisor.stopped()) stops.Track(truth.hinge_xy);
}

}  // namespace autoshovel::app
