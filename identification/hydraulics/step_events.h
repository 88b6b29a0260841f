// What a valve step log shows, read from the log itself: the command steps, the rest before
// each, the joint's motion onset, and the stalls (the joint held by an end stop while the
// command is on). The fit of the valve chain (valve_chain_fit.h) uses the samples between
// stalls and never those the data shows to be stalled; it keeps the rest before a step,
// also a rest against a stop, because the delay is seen only against it.
//
// A stall, from the data: the command is on, the joint's driving pressure (the higher of the
// two chamber pressures) is within `stall_pressure_band` of the highest seen in that file (or
// of the relief given as an override), and the joint is within `stall_angle_band` of the
// furthest angle it reached in the command's direction. The stall then extends back over the
// samples before it in which the joint was already at that angle (the pressure rises to
// relief only after the joint has stopped), and on past the command's end while the joint
// stays there and the valve closes. Without pressure channels the pressure
// condition is dropped and a stall must last `min_stall_duration`. Joint ranges and a time
// window can be given as overrides: samples outside them are left out too.
//
// Why the end of travel and not the rate alone: at the stop, the angle sensors of real
// machines jitter by tenths of a degree under relief pressure (the structure flexes), which a
// rate threshold reads as motion, while a low-duty step moves the joint at well under 1 °/s,
// which a rate threshold reads as rest.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "identification/hydraulics/log_reader.h"

namespace autoshovel::identification {

struct StepEventOptions {
  double command_on = 0.02;               ///< |u| above which the command is on [-]
  double stall_pressure_band = 0.10;      ///< of the stall pressure [-]
  double min_stall_pressure_band = 15e5;  ///< at least [Pa]
  double stall_angle_band = 0.035;        ///< of the furthest angle reached [rad] (2°)
  double rest_rate = 0.0035;              ///< below: at rest (no pressure channels) [rad/s]
  /// A stall extends back over the samples within this of its first angle: the joint had
  /// already stopped there while the pressure rose [rad] (0.1°).
  double stall_rest_band = 0.1 * 3.141592653589793 / 180;
  double min_stall_duration = 0.3;  ///< [s]
  /// A stall that lasts to the command's end goes on this long after it while the joint stays
  /// at the stop: the valve closes over its delays and lags, and a model free of the stop
  /// would move the joint on [s].
  double post_stall_settle = 1.0;
  double onset_angle = 0.3 * 3.141592653589793 / 180;  ///< motion onset threshold [rad]
  double relief = 0;  ///< override: stall pressure [Pa]; 0: the highest seen in each file
  double joint_min = -std::numeric_limits<double>::infinity();     ///< override [rad]
  double joint_max = std::numeric_limits<double>::infinity();      ///< override [rad]
  double window_begin = -std::numeric_limits<double>::infinity();  ///< override [s]
  double window_end = std::numeric_limits<double>::infinity();     ///< override [s]
  std::size_t min_segment = 10;  ///< shorter runs of usable samples are left out
  /// +1 when a positive command (extending the cylinder, the plant's convention) raises the
  /// joint angle, −1 when it lowers it (from the description's kinematics).
  int joint_sense = 1;
  /// Steps shorter than this are not judged by the sign check [s].
  double sign_check_duration = 1.0;
};

/// One command step: the command holds one sign from `on` to `off` (exclusive).
struct CommandStep {
  std::size_t on = 0;
  std::size_t off = 0;
  double level = 0;  ///< the largest |u| in the step, signed [-1, 1]
  /// First sample at which the joint has moved `onset_angle` from its angle at `on` in the
  /// command's direction; npos if it never does.
  std::size_t onset = static_cast<std::size_t>(-1);
};

struct LogEvents {
  std::vector<double> rate;    ///< joint rate, central difference over ±50 ms [rad/s]
  std::vector<char> stalled;   ///< 1: the joint is held by a stop with the command on
  std::vector<char> excluded;  ///< 1: stalled or outside the overrides (window, range)
  std::vector<CommandStep> steps;
  std::vector<std::pair<std::size_t, std::size_t>> segments;  ///< [begin, end) of used samples
  bool has_pressure = false;
  double stall_pressure = 0;  ///< pressure taken as relief in this file [Pa] (0: none)
  double relief_seen = 0;     ///< median driving pressure over the stalled samples [Pa] (0: none)
  std::size_t stalled_samples = 0;
};

/// Reads the events of one log. Never throws on a valid log; a log with no step gives no steps.
LogEvents DetectStepEvents(const HydraulicLog& log, const StepEventOptions& options = {});

/// The joint's motion against each step's command: a step of at least `sign_check_duration`
/// over which the joint's net change (beyond 4× the onset threshold) has the other sign.
/// Empty: every such step agrees.
struct SignMismatch {
  std::size_t step = 0;
  double level = 0;         ///< signed command [-1, 1]
  double angle_change = 0;  ///< over the step [rad]
};
std::vector<SignMismatch> FindSignMismatches(const HydraulicLog& log, const LogEvents& events,
                                             const StepEventOptions& options = {});

}  // namespace autoshovel::identification
