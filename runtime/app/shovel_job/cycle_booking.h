// The recorder's part of a cycle of the main job: its row of the results database (phases,
// energy, trigger, crowding sample, V1/V1+V2 and tip samples), its figures, and the summary line.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/app/shovel_job/fault_schedule.h"
#include "runtime/app/shovel_job/navigation_goal.h"
#include "runtime/app/shovel_run.h"

namespace autoshovel::app {

/// How the cycle ended, as the machine and the loop saw it.
struct CycleEnd {
  bool scooped = false;        ///< the scoop cycle was started (out.scoop holds its result)
  double t0 = 0;               ///< machine clock at the cycle's start [s]
  double time = 0;             ///< machine clock at its end [s]
  double navigation_time = 0;  ///< when it never scooped: the whole cycle [s]
  double energy = 0;           ///< the machine's energy counters [J]
  double payload = 0;          ///< in the bucket at the end [m³]
  double min_clearance = 0;    ///< [m], simulation truth
  int violations = 0;
  Eigen::Vector2d start_xy = Eigen::Vector2d::Zero();  ///< the cycle's start pose
  double start_heading = 0;
};

/// Fills `out.record` from the scoop result and how the cycle ended.
void BookCycle(const CycleEnd& end, const FaultSchedule& faults,
               const model::MachineDescription& machine, const NavigationGoal& nav,
               CycleOutcome& out);

/// Writes the cycle's figures into `figures_dir` (map layers, scored candidates, V1 and V1+V2,
/// tip path) and lists them in `out`.
void WriteCycleFigures(const std::filesystem::path& figures_dir, const perception::GridMap& map,
                       const std::vector<perception::ExtractedPile>& piles,
                       const NavigationGoal& nav, bool chen2024,
                       const planning::LoaderGeometry& loader, bool scooped, CycleOutcome& out);

/// The cycle's closing lines on the log.
struct CycleStats {
  double path_error = 0;     ///< largest cross-track error [m]
  double scoop_advance = 0;  ///< farthest past the planned contact [m]
  long map_updates = 0;
  double map_seconds = 0;
  long selections = 0;
  double selection_seconds = 0;
};
void SayCycleSummary(const CycleOutcome& out, bool scooped, const std::string& site,
                     double min_clearance, const CycleStats& stats, const CycleLog& log);

}  // namespace autoshovel::app
