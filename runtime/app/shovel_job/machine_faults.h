// Faults of the simulated machine's own sensors and actuators (plant/fault_spec.h), applied at
// the control rate before the machine is sensed: a localisation jump, a stuck valve, an arm IMU's
// growing bias or frozen reading, encoder noise, hydraulic delays that drift. Simulation side.
#pragma once

#include "runtime/app/plant_machine.h"
#include "runtime/app/shovel_job/fault_schedule.h"

namespace autoshovel::app {

void ApplyMachineFaults(const FaultSchedule& faults, const model::MachineDescription& machine,
                        PlantMachine& machine_io, plant::Plant& plant);

}  // namespace autoshovel::app
