#include "runtime/app/shovel_job/crowd_watch.h"

#include <cmath>

#include "runtime/app/crowd_lookahead.h"
#include "runtime/app/shovel_job/sure_cell_report.h"

namespace autoshovel::app {

void CrowdWatch::Check(const plant::MachineState& s, const perception::MachineFootprint& footprint,
                       const model::MachineDescription& machine, control::ScoopCycle& scoop,
                       const perception::GridMap& map, const plant::World& world,
                       const CycleLog& log) {
  // From contact on: before it the planned path (clearance d_min with its margin) holds.
  const std::string phase = scoop.phase_name();
  if (stop_requested_ || (phase != "crowd" && phase != "scoop")) return;
  // The front edge of what the scoop will sweep, and the sure obstacles in the corridor.
  perception::MachineFootprint sweep = footprint;
  sweep.front_length =
      std::max(footprint.front_length, ScoopReach(machine, s.q[0], s.q[1], config_.strategy) + 0.3);
  int nearest = -1;
  const double ahead = DistanceAhead(cells_, s.hinge_xy, s.heading, sweep.half_width,
                                     sweep.front_length, resolution_, &nearest);
  // Stopping takes the decision latency (one 20 Hz period) plus v² / 2 a_dec of the speed
  // profile; in a pile the resistance shortens it, on the floor it does not.
  const double v = std::max(0.0, s.speed);
  const double stopping = v / config_.decision_rate + v * v / (2 * config_.max_deceleration);
  // One more map cell: the wall's face next to a pile's crest is blurred by pile evidence.
  if (ahead < config_.safety_distance + config_.planning_margin + stopping + resolution_) {
    scoop.RequestStop("obstacle_ahead");
    stop_requested_ = true;
    log.Say("obstacle " + Fixed(ahead, 2) + " m ahead on the map (scoop " + phase +
            ", sweep reach " + Fixed(sweep.front_length, 2) + " m, stopping " + Fixed(stopping, 2) +
            " m): crowding ends; " + SureCellReport(map, cells_[nearest], world));
    return;
  }
  // Beside: the whole machine where it will stand once stopped. Entered at an angle to a wall,
  // the body closes on the wall sideways while the corridor ahead stays clear (seed §5.2: the
  // safety distance holds for the area covered during the process).
  perception::MachineFootprint stopped = sweep;
  stopped.hinge_xy += stopping * Eigen::Vector2d(std::cos(s.heading), std::sin(s.heading));
  const double beside = FootprintDistanceToCells(stopped, cells_, resolution_, &nearest);
  if (beside < config_.safety_distance + config_.planning_margin) {
    scoop.RequestStop("obstacle_beside");
    stop_requested_ = true;
    log.Say("obstacle " + Fixed(beside, 2) + " m beside on the map (scoop " + phase +
            ", stopping " + Fixed(stopping, 2) + " m): crowding ends; " +
            SureCellReport(map, cells_[nearest], world));
  }
}

}  // namespace autoshovel::app
