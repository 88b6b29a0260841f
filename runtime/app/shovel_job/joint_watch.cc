#include "runtime/app/shovel_job/joint_watch.h"

namespace autoshovel::app {

std::string CheckJoints(SafetySupervisor& supervisor, const model::MachineDescription& machine,
                        double time, const control::Proprioception& sensed,
                        const core::ActuatorCommand& last_command, control::ScoopCycle* scoop,
                        double t0, const CycleLog& log) {
  for (int j = 0; j < 2; ++j) {
    const char* name = j == 0 ? "boom" : "bucket";
    const JointCheck check = supervisor.CheckJoint(
        j, name, time, ReadJoint(machine, j, sensed, last_command), RangeOf(machine, j));
    if (check.state == JointState::kDoesNotAnswer) return check.message;
    if (check.state == JointState::kStallsUnderLoad && check.first_report) {
      log.Say(check.message + " at t = " + Fixed(time - t0, 2) + " s" +
              (scoop != nullptr ? std::string(" (scoop ") + scoop->phase_name() + "): the " + name +
                                      " is held where it stalled"
                                : std::string()));
      if (scoop != nullptr) scoop->JointStalledUnderLoad(j, check.message);
    }
  }
  return "";
}

}  // namespace autoshovel::app
