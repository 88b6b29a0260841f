#include "runtime/app/shovel_job/machine_faults.h"

#include <cstdint>

#include "runtime/plant/plant.h"

namespace autoshovel::app {

void ApplyMachineFaults(const FaultSchedule& faults, const model::MachineDescription& machine,
                        PlantMachine& machine_io, plant::Plant& plant) {
  using plant::FaultKind;
  const double now = plant.time();
  const plant::FaultSpec* jump = faults.Active(FaultKind::kLocalisationJump, now);
  machine_io.SetPoseError(jump ? jump->offset_m : Eigen::Vector2d::Zero(),
                          jump ? jump->heading_rad : 0.0);
  const plant::FaultSpec* stuck = faults.Active(FaultKind::kStuckValve, now);
  machine_io.SetStuckValve(stuck ? machine.ActuatorOfJoint(stuck->joint == "boom" ? 0 : 1) : -1);
  // Arm IMU faults: a bias growing from the fault's start, or a reading frozen there.
  const plant::FaultSpec* drift = faults.Active(FaultKind::kImuBiasDrift, now);
  const plant::FaultSpec* frozen = faults.Active(FaultKind::kImuStuck, now);
  if (frozen != nullptr) {
    machine_io.SetJointReadingFault(frozen->joint == "boom" ? 0 : 1, 0.0, true);
  } else if (drift != nullptr) {
    machine_io.SetJointReadingFault(drift->joint == "boom" ? 0 : 1,
                                    drift->rate_rad_s * (now - faults.t0() - drift->start_s),
                                    false);
  } else {
    machine_io.SetJointReadingFault(-1, 0.0, false);
  }
  const plant::FaultSpec* noise = faults.Active(FaultKind::kEncoderNoise, now);
  machine_io.SetAngleNoise(noise != nullptr ? noise->sigma_rad : 0.0,
                           0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(faults.cycle() + 1));
  if (faults.InCycle(FaultKind::kHydraulicDelayDrift)) {
    const plant::FaultSpec* slow = faults.Active(FaultKind::kHydraulicDelayDrift, now);
    for (std::size_t k = 0; k < machine.hydraulics.actuators.size(); ++k) {
      plant.SetTransportDelay(static_cast<int>(k),
                              machine.hydraulics.actuators[k].valve.transport_delay *
                                  (slow != nullptr ? slow->factor : 1.0));
    }
  }
}

}  // namespace autoshovel::app
