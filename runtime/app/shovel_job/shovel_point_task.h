// The main job's shovel point selection (seed §5, Eq. (11)–(18)), run at 7 Hz on the map until
// the machine commits to a goal: piles extracted from the map, candidates scored and their paths
// planned, the best one kept whose planned clearance holds; while driving, whether the goal
// being driven to still stands or gives way to a better one.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "runtime/perception/grid_map.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/planning/chen2024_baseline.h"
#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::app {

/// The goal after a re-selection: drive to `candidate`, as a new goal or as the same goal on
/// its re-planned path; `log` says why a new goal was taken ("" when kept).
struct GoalChange {
  const planning::ShovelCandidate* candidate = nullptr;
  bool new_goal = false;
  std::string log;
};

class ShovelPointTask {
 public:
  /// `min_planned_clearance`: the least planned clearance from obstacles a goal must keep [m];
  /// `chen2024`: rank by the baseline of Chen et al. (2024) instead of Eq. (18);
  /// `in_site`: whether a pile's centroid lies in the cycle's work area.
  ShovelPointTask(const planning::ShovelPointConfig& config, double min_planned_clearance,
                  bool chen2024, const planning::LoaderGeometry& loader,
                  std::function<bool(const Eigen::Vector2d&)> in_site);

  /// Selects on the map from the machine's believed pose; the best candidate, or null when none
  /// is feasible and clear enough. The result stays valid until the next call.
  const planning::ShovelCandidate* Select(perception::GridMap& grid, const Eigen::Vector3d& plane,
                                          const planning::Pose2& T_world_hinge);
  /// Why no point was selected at `site`, for the cycle's failure.
  std::string NoPointReason(const std::string& site) const;
  /// The log line of a first selection.
  std::string SelectedText(const planning::ShovelCandidate& best) const;
  /// The goal being driven to, found again among the last selection's candidates: kept on its
  /// re-planned path, or given up for `best` when it is infeasible now, too close to an
  /// obstacle, or beaten by 0.05 in F (Eq. (18) only).
  GoalChange Reconsider(const planning::ShovelCandidate& goal,
                        const planning::ShovelCandidate& best) const;

  const planning::ShovelPointConfig& config() const { return config_; }
  const planning::ShovelPointResult& last_selection() const { return last_selection_; }
  const std::vector<planning::Chen2024Candidate>& last_baseline() const { return last_baseline_; }
  const std::vector<perception::ExtractedPile>& last_piles() const { return last_piles_; }
  long selections() const { return selections_; }
  /// Replaces the last selection (tests of Reconsider without a map).
  void SetLastSelectionForTest(planning::ShovelPointResult selection) {
    last_selection_ = std::move(selection);
  }
  double seconds() const { return seconds_; }  ///< wall time spent [s]

 private:
  planning::ShovelPointConfig config_;
  double min_planned_clearance_;
  bool chen2024_;
  const planning::LoaderGeometry& loader_;
  std::function<bool(const Eigen::Vector2d&)> in_site_;
  planning::ShovelPointResult last_selection_;
  std::vector<planning::Chen2024Candidate> last_baseline_;
  std::vector<perception::ExtractedPile> last_piles_;
  long selections_ = 0;
  double seconds_ = 0;
};

}  // namespace autoshovel::app
