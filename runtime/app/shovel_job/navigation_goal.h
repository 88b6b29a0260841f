// The goal the machine drives to and the path follower on its planned path (seed §5.3); the
// selection it came from is kept for the cycle's candidate figure.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "runtime/app/shovel_job/shovel_point_task.h"
#include "runtime/control/path_follower.h"
#include "runtime/perception/grid_map.h"

namespace autoshovel::app {

struct NavigationGoal {
  std::optional<planning::ShovelCandidate> goal;
  std::optional<control::PathFollower> follower;
  /// The map's obstacle cells when the path was planned: the look-ahead along the path stops
  /// only for the others (those that came after).
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> planned_obstacles;
  planning::ShovelPointResult selection;  ///< the selection that chose the goal
  std::vector<planning::Chen2024Candidate> baseline;
  planning::Pose2 from;  ///< where the machine stood when the goal was chosen

  /// Drives to `candidate` on its path: as a new goal (its selection kept for the figure, from
  /// the pose `now`) or as the same goal on a re-planned path.
  void Start(const planning::ShovelCandidate& candidate, bool new_goal,
             const ShovelPointTask& selection_task, const planning::Pose2& now,
             const perception::GridMap& map, const planning::LoaderGeometry& loader);
};

}  // namespace autoshovel::app
