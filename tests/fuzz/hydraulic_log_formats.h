// The two ways the hydraulic log fuzz target reads every input, shared with the regression test
// so that a kept input is read exactly as when it was found.
#pragma once

#include <vector>

#include "identification/hydraulics/log_reader.h"

namespace autoshovel::fuzz {

/// The default column names of `autoshovel plant step` (SI units), and a column map by position
/// in logger units (ms, percent, deg, bar): both ways of finding columns, every unit conversion.
inline std::vector<identification::LogFormat> HydraulicLogFormats() {
  using namespace identification;
  LogFormat by_position = ParseColumnsSpec("time=1,command=2,spool=3,pressure_a=4,joint_angle=5");
  by_position.time_units = TimeUnits::kMilliseconds;
  by_position.command_units = by_position.spool_units = CommandUnits::kPercent;
  by_position.angle_units = AngleUnits::kDegrees;
  by_position.pressure_units = PressureUnits::kBar;
  return {LogFormat{}, by_position};
}

}  // namespace autoshovel::fuzz
