// What a controller sends to a machine at a control tick: the same struct drives the simulated
// plant and, through a machine interface, a real one (DESIGN.md: control sees the machine only
// through sensor data and actuator commands).
#pragma once

#include <vector>

namespace autoshovel::core {

struct ActuatorCommand {
  /// Valve PWM duty per hydraulic actuator, in description order, in [-1, 1]: +1 fully opens
  /// the path that extends a cylinder (turns a motor positive). The machine applies its own
  /// valve dead zone and transport delay: this is the electrical command, not the spool.
  std::vector<double> valve;
  /// Drive command in [-1, 1]: traction motor torque fraction (electric) or throttle with the
  /// sign selecting forward/reverse gear (diesel).
  double drive = 0;
  double brake = 0;              ///< service brake in [0, 1]
  double articulation_rate = 0;  ///< commanded steering rate [rad/s], limited by the machine
};

}  // namespace autoshovel::core
