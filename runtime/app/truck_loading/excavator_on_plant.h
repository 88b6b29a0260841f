// The simulated 25 t excavator as the excavator control layer sees it: joint positions and
// rates measured, desired joint positions (or a stop) sent through the joint servos
// (control/excavator/joint_servo.h) to the plant's valves. DESIGN.md: only app/ and tests wire
// the plant to control.
#pragma once

#include <string>

#include "runtime/control/excavator/excavator_joints.h"
#include "runtime/control/excavator/joint_servo.h"
#include "runtime/plant/plant.h"

namespace autoshovel::app {

class ExcavatorOnPlant {
 public:
  /// `servo` must be built for the plant's machine. Throws std::invalid_argument when the
  /// plant's machine does not have the four excavator joints.
  ExcavatorOnPlant(plant::Plant& plant, control::ExcavatorJointServo& servo);

  /// Proprioception: the plant's true joint positions and rates (encoders without noise).
  control::ExcavatorState Sense() const;
  /// Sends `command` through the servos; the valves stay as they are until the next call.
  /// Returns false (and counts it) when the plant refused the duties.
  bool Command(const control::ExcavatorCommand& command);
  void Advance(double dt) { plant_.Advance(dt); }
  double time() const { return plant_.time(); }

  plant::Plant& plant() { return plant_; }
  const plant::Plant& plant() const { return plant_; }
  long refused_commands() const { return refused_; }

 private:
  plant::Plant& plant_;
  control::ExcavatorJointServo& servo_;
  core::ActuatorCommand command_;
  long refused_ = 0;
};

}  // namespace autoshovel::app
