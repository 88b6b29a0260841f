// The hand-over from navigation to the scoop cycle (seed Algorithm 3): at the handover distance
// the map as it stands before contact is frozen for Eq. (19), the pile's material is taken from
// the yard's inventory, the trigger chosen and the scoop cycle started.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/app/shovel_job/fault_schedule.h"
#include "runtime/app/shovel_run.h"
#include "runtime/control/scoop_cycle.h"
#include "runtime/control/scoop_triggers.h"
#include "runtime/perception/grid_map.h"
#include "runtime/plant/scenario.h"
#include "runtime/prediction/volume_estimation.h"

namespace autoshovel::optimal {
class WarmScoopSolver;
}

namespace autoshovel::app {

/// The elevation layer as the regular grid the volume estimation reads (unknown cells NaN).
prediction::HeightGrid HeightGridOf(const perception::GridMap& map);

/// What the scoop cycle needs to outlive it. Not movable once started: the cycle holds
/// references to the pre-contact map, the material and the trigger.
struct ScoopHandover {
  const plant::Pile* pile = nullptr;  ///< the site's pile nearest the shovel point
  const model::Material* material = nullptr;
  prediction::HeightGrid pre_contact;  ///< the map before contact, which the scoop cycle reads
  std::unique_ptr<control::ScoopTrigger> trigger;
  std::unique_ptr<control::ScoopCycle> scoop;

  ScoopHandover() = default;
  ScoopHandover(const ScoopHandover&) = delete;
  ScoopHandover& operator=(const ScoopHandover&) = delete;
};

struct ScoopHandoverInputs {
  const ShovelRunOptions& options;
  const model::MachineDescription& machine;
  const generated::MachineFunctions& functions;
  const prediction::PenetrationPredictor& predictor;
  optimal::WarmScoopSolver& optimal_solver;
  const control::ScoopCycleOptions& scoop_options;
  const std::vector<plant::Pile>& piles;
  std::function<bool(const Eigen::Vector2d&)> in_site;
  const std::string& site_name;
};

/// Starts the scoop cycle on `machine_io` for the goal at `goal_xy`; returns "" or why it could
/// not (no pile in the site, a material the machine does not know).
std::string StartScoopCycle(const ScoopHandoverInputs& in, const Eigen::Vector2d& goal_xy,
                            const perception::GridMap& map, const FaultSchedule& faults,
                            control::ScoopMachine& machine_io, ScoopHandover& handover,
                            const CycleLog& log);

}  // namespace autoshovel::app
