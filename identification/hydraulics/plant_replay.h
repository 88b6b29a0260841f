// Sim-to-real check of an identified valve chain: the plant of a description (with the chain's
// overlay) driven by a real log's own commands, its joint angle set against the measured one.
// `autoshovel identify hydraulics LOGS --replay OVERLAY` (identify_hydraulics_command.h).
//
// The plant starts with the driven joint at the log's first measured angle, clamped into the
// description's joint range (the logs' machine need not be the description's, nor its angle
// sensor share the description's zero), the other joints where SimulatePlantLog puts them, on
// an empty yard, and its valve command is the log's command held from row to row. Angles are
// compared as changes from each log's start: what the chain and the plant must reproduce is
// the motion, not the sensor's offset. Samples the log shows stalled (step_events.h) are left
// out of the RMS: the description's end stops are not the real machine's.
#pragma once

#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/step_events.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {

struct ReplayResult {
  std::string file;
  std::vector<double> time;       ///< [s]
  std::vector<double> measured;   ///< change from the first sample [rad]
  std::vector<double> simulated;  ///< change from the first sample [rad]
  std::vector<char> excluded;     ///< stalled or outside the overrides
  double angle_rms = 0;           ///< over the used samples [rad]
  double angle_rms_onset = 0;     ///< over 2 s after each motion onset [rad]; NaN: no onset found
  bool start_clamped = false;     ///< the measured start was outside the joint's range
  /// Over the log's first step the plant's joint and the logged angle moved opposite ways:
  /// the log's angle (or command) runs against the description's joint sense.
  bool opposite_sense = false;
};

/// Replays one log of `actuator` on the plant. Throws std::runtime_error when the plant refuses.
ReplayResult ReplayOnPlant(const model::MachineDescription& machine,
                           const generated::MachineFunctions& functions, int actuator,
                           const HydraulicLog& log, const StepEventOptions& events = {});

/// Measured and replayed angle of every log, one panel each, RMS in the titles.
void WriteReplayPlot(const std::vector<ReplayResult>& results, const std::string& path);

}  // namespace autoshovel::identification
