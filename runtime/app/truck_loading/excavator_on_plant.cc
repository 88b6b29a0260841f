#include "runtime/app/truck_loading/excavator_on_plant.h"

#include <stdexcept>

namespace autoshovel::app {

ExcavatorOnPlant::ExcavatorOnPlant(plant::Plant& plant, control::ExcavatorJointServo& servo)
    : plant_(plant), servo_(servo) {
  if (plant.state().q.size() != static_cast<std::size_t>(control::kNumExcavatorJoints)) {
    throw std::invalid_argument("ExcavatorOnPlant: " + plant.machine().name +
                                " does not have boom, stick, bucket and swing joints");
  }
  command_.valve.assign(plant.machine().hydraulics.actuators.size(), 0.0);
}

control::ExcavatorState ExcavatorOnPlant::Sense() const {
  control::ExcavatorState s;
  const plant::MachineState& m = plant_.state();
  for (int j = 0; j < control::kNumExcavatorJoints; ++j) {
    s.q[j] = m.q[j];
    s.qd[j] = m.qd[j];
  }
  return s;
}

bool ExcavatorOnPlant::Command(const control::ExcavatorCommand& command) {
  command_.valve = servo_.Update(command, Sense());
  command_.drive = 0;
  command_.brake = 1;  // the undercarriage stands (the plant does not move excavators anyway)
  if (!plant_.SetCommand(command_)) {
    ++refused_;
    return false;
  }
  return true;
}

}  // namespace autoshovel::app
