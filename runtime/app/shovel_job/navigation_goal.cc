#include "runtime/app/shovel_job/navigation_goal.h"

#include "runtime/perception/semantic_map.h"

namespace autoshovel::app {

void NavigationGoal::Start(const planning::ShovelCandidate& candidate, bool new_goal,
                           const ShovelPointTask& selection_task, const planning::Pose2& now,
                           const perception::GridMap& map, const planning::LoaderGeometry& loader) {
  goal = candidate;
  if (new_goal) {
    selection = selection_task.last_selection();
    baseline = selection_task.last_baseline();
    from = now;
  }
  follower.emplace(planning::SamplePath(candidate.path, 0.1), loader);
  const Eigen::MatrixXf& cls = map["class"];
  planned_obstacles = (cls.array() == static_cast<float>(perception::CellClass::kObstacle));
}

}  // namespace autoshovel::app
