#include "runtime/app/shovel_job/person_fault.h"

#include <cmath>

namespace autoshovel::app {

void PersonOnPathFault::Update(const FaultSchedule& faults, const planning::ShovelCandidate* goal,
                               const plant::MachineState& truth, double hinge_to_front_axle,
                               double time, const CycleLog& log) {
  const plant::FaultSpec* person = faults.Active(plant::FaultKind::kPersonEntersPath, time);
  if (person != nullptr && !placed_ && goal != nullptr) {
    // On the planned path, `ahead_m` beyond the point of it nearest the front axle now.
    const std::vector<planning::PathSample> path = planning::SamplePath(goal->path, 0.1);
    const Eigen::Vector2d front_axle =
        truth.hinge_xy +
        hinge_to_front_axle * Eigen::Vector2d(std::cos(truth.heading), std::sin(truth.heading));
    std::size_t nearest = 0;
    for (std::size_t k = 0; k < path.size(); ++k) {
      if ((path[k].xy - front_axle).norm() < (path[nearest].xy - front_axle).norm()) nearest = k;
    }
    std::size_t at = nearest;
    while (at + 1 < path.size() && path[at].s - path[nearest].s < person->ahead_m) ++at;
    plant::OrientedBox box;
    box.name = "person (fault " + person->where + ")";
    box.center = {path[at].xy.x(), path[at].xy.y(), 0.9};
    box.half_extents = {0.3, 0.3, 0.9};
    box.semantic_class = core::SemanticClass::kPerson;
    boxes_.push_back(box);
    placed_ = true;
    log.Say("a person steps onto the path at t = " + Fixed(time - faults.t0(), 2) + " s at (" +
            Fixed(box.center.x(), 2) + ", " + Fixed(box.center.y(), 2) + "), " +
            Fixed(path[at].s - path[nearest].s, 1) + " m ahead along it (fault)");
  }
  if (placed_ && person == nullptr && !boxes_.empty()) {
    // The fault's window ended: the person walks off (the map forgets them as it sees the
    // ground there again).
    boxes_.clear();
    log.Say("the person leaves at t = " + Fixed(time - faults.t0(), 2) + " s (fault)");
  }
}

}  // namespace autoshovel::app
