// One cycle of the main job (docs/architecture.md), wired from its components on the multi-rate
// executive as in the seed's Fig. 2:
//
//   sensors ──7 Hz──> semantic elevation map ──> shovel point selection ──> navigation goal
//   goal ──100 Hz──> path follower + speed/joint PIDs ──> machine
//   handover ──> scoop cycle (trigger, V1 + V2, strategy) ──100 Hz──> machine
//   20 Hz: safety supervisor (watchdog, path and crowd look-ahead, joints), clearance record
//   end: recorder (the database row, figures, log)
//
// The machine here is the simulated one (plant + simulated sensors, PlantMachine).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "runtime/app/shovel_run.h"
#include "runtime/perception/lens_dirt_monitor.h"
#include "runtime/planning/shovel_point_selection.h"
#include "runtime/plant/scenario.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/sensors/rng.h"

namespace autoshovel::optimal {
class WarmScoopSolver;
}
namespace autoshovel::sensors {
class RaycastScene;
}
namespace autoshovel::recording {
class RecordingWriter;
}
namespace autoshovel::perception {
class ElevationMap;
class SemanticMap;
}  // namespace autoshovel::perception

namespace autoshovel::app {

/// Where cycles dig: a bin holding piles, or the open yard (piles outside bins).
struct Site {
  std::string name;
  int bin = -1;  ///< into Scenario::bins; −1: the open yard
  Eigen::Vector2d start_xy = Eigen::Vector2d::Zero();
  double start_heading = 0;
};

/// What a run keeps from cycle to cycle and lends each cycle.
struct CycleResources {
  const ShovelRunOptions& options;
  plant::Scenario& scenario;
  const model::MachineDescription& machine;
  const generated::MachineFunctions& functions;
  const prediction::PenetrationPredictor& predictor;
  const planning::LoaderGeometry& loader;
  const planning::ShovelPointConfig& selection;  ///< Eq. (18) weights
  const std::vector<plant::FaultSpec>& faults;
  const std::string& segmenter;
  sensors::RaycastScene& scene;
  perception::ElevationMap& map;
  perception::SemanticMap& semantic;
  sensors::Rng& rng;
  perception::LensDirtMonitor& lens_dirt;
  optimal::WarmScoopSolver& optimal_solver;
  /// Where every map update's frames go (ShovelRunOptions::record_dir); null: nowhere.
  recording::RecordingWriter* recorder = nullptr;
};

/// Runs cycle `index` at `site`, its plant starting at machine time `start_clock`; `end_clock`
/// receives the time it ended. `figures_dir`: where its PNGs go (empty: none); `progress`: the
/// log (may be null).
CycleOutcome RunShovelCycle(CycleResources& resources, const Site& site, int index,
                            double start_clock, double* end_clock,
                            const std::filesystem::path& figures_dir, std::ostream* progress);

/// The main job's components grouped by the executive task that runs them, at the rates of
/// `options`, and the data flowing between them, as Graphviz DOT (`autoshovel architecture`;
/// docs/architecture.md). Drawn from the task table the cycle registers on its executive.
std::string ShovelJobArchitectureDot(const ShovelRunOptions& options);

}  // namespace autoshovel::app
