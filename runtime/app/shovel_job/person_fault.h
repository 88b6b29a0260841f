// The fault "a person steps onto the path" (plant/fault_spec.h) in the simulated yard: while
// the machine drives to its goal, a person appears on the planned path ahead of it, and walks
// off when the fault's window ends. Simulation side: it changes what the sensors see.
#pragma once

#include <vector>

#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/app/shovel_job/fault_schedule.h"
#include "runtime/planning/shovel_point_selection.h"
#include "runtime/plant/machine_state.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

class PersonOnPathFault {
 public:
  /// At the 20 Hz decision rate. `goal`: the goal being driven to (null before one is chosen);
  /// `truth`: the machine as it is; `time`: machine clock [s].
  void Update(const FaultSchedule& faults, const planning::ShovelCandidate* goal,
              const plant::MachineState& truth, double hinge_to_front_axle, double time,
              const CycleLog& log);

  /// The people the fault put in the yard now (boxes the sensors see).
  const std::vector<plant::OrientedBox>& boxes() const { return boxes_; }

 private:
  std::vector<plant::OrientedBox> boxes_;
  bool placed_ = false;
};

}  // namespace autoshovel::app
