// The safety supervisor's actuator check at 20 Hz (safety_supervisor.h): a joint that does not
// answer its valve abandons the cycle; one that stalls under load is handed to the scoop cycle,
// which holds it where it stalled (not a fault).
#pragma once

#include <string>

#include "runtime/app/safety_supervisor.h"
#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/control/scoop_cycle.h"
#include "runtime/core/actuator_command.h"

namespace autoshovel::app {

/// Checks boom and bucket; returns why the cycle must be abandoned ("" when it need not be).
/// `scoop` may be null (before the hand-over).
std::string CheckJoints(SafetySupervisor& supervisor, const model::MachineDescription& machine,
                        double time, const control::Proprioception& sensed,
                        const core::ActuatorCommand& last_command, control::ScoopCycle* scoop,
                        double t0, const CycleLog& log);

}  // namespace autoshovel::app
