// The crowd look-ahead on the map (crowd_lookahead.h; docs/main_job.md): while the scoop cycle
// drives into the pile, the front edge of what the scoop will sweep must keep the safety distance
// plus the planning margin plus the stopping distance from the map's sure obstacle cells ahead,
// and the whole machine where it will stand once stopped the same from those beside; closer,
// crowding ends (a pile against a wall is dug up to the wall's safety distance, never into it).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/control/scoop_cycle.h"
#include "runtime/perception/grid_map.h"
#include "runtime/perception/machine_footprint.h"
#include "runtime/plant/machine_state.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

struct CrowdWatchConfig {
  double safety_distance = 0;   ///< [m]
  double planning_margin = 0;   ///< [m]
  double decision_rate = 20;    ///< [Hz]
  double max_deceleration = 1;  ///< of the speed profile [m/s²]
  control::StrategyParameters strategy;
};

class CrowdWatch {
 public:
  explicit CrowdWatch(const CrowdWatchConfig& config) : config_(config) {}

  /// The map's sure obstacle cells before contact (centres, `resolution` apart).
  void SetObstacles(std::vector<Eigen::Vector2d> cells, double resolution) {
    cells_ = std::move(cells);
    resolution_ = resolution;
  }

  /// One 20 Hz check while the scoop cycle crowds or scoops: ends crowding (once) through
  /// `scoop` when too close. `s`: the machine; `footprint`: its outline now.
  void Check(const plant::MachineState& s, const perception::MachineFootprint& footprint,
             const model::MachineDescription& machine, control::ScoopCycle& scoop,
             const perception::GridMap& map, const plant::World& world, const CycleLog& log);

 private:
  CrowdWatchConfig config_;
  std::vector<Eigen::Vector2d> cells_;
  double resolution_ = 0;
  bool stop_requested_ = false;
};

}  // namespace autoshovel::app
