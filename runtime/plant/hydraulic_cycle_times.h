// Spec-sheet hydraulic cycle times of a wheel loader, measured on the plant (SAE J732 / ISO
// 14397-1 list them): full valve command, stopwatch from the command to the joint within
// `end_tolerance` of its end.
//   raise  boom from "ground" (bucket racked back, boom at the lowest angle that keeps the whole
//          bucket above the ground line) to its upper joint limit, tilt valve centred;
//   dump   bucket from racked back to its dumped joint limit, boom at the top, boom valve
//          centred;
// ("racked back" and "dumped": the joint limits, or as far as a frame-mounted tilt cylinder
// reaches at that boom angle: its stroke window slides with the boom.)
//   lower  boom from the top back to the raise's start angle, bucket as dumped.
// The bucket is empty in all three: the plant's payload is the material the bucket captures,
// and the yard floor lies far below so that nothing is touched. With the plant's pressure-
// compensated (load-sensing) valves a spool's flow does not depend on the load as long as the
// pump's pressure suffices, which the describe command checks for the rated load
// (model::SpecSheet::boom_pressure_for_rated_load). Each time includes the valve's transport
// delay and spool lag, as a stopwatch started at the operator's lever would.
#pragma once

#include <vector>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"

namespace autoshovel::plant {

struct CycleTimeOptions {
  double tick = 0.01;                             ///< command and sampling period [s]
  double time_limit = 30.0;                       ///< per motion: not reached after this [s]
  double end_tolerance = 0.5 * 3.14159265 / 180;  ///< of the joint limit [rad]
};

struct HydraulicCycleTimes {
  double raise = 0;  ///< [s]; negative: not reached within the time limit
  double dump = 0;   ///< [s]
  double lower = 0;  ///< [s]
  double total() const { return raise + dump + lower; }
  std::vector<double> start_pose;  ///< the raise's start ("ground") [rad]
  double boom_end = 0;             ///< boom angle reached at the top [rad]
  /// Largest angle by which the bucket went past its dumped joint limit, from the dump's end
  /// through the lowering [rad]. The plant stops a joint only at its cylinder's ends; a limit
  /// that no cylinder end holds is passed (the valve closes a transport delay after the
  /// stopwatch), which `describe` reports: a description whose tilt cylinder leaves stroke past
  /// the dumped limit at the top lets the bucket swing through.
  double bucket_past_dump_limit = 0;
};

/// The boom angle of the raise's start: bucket racked back fully, the lowest boom angle at which
/// no point of the bucket profile is below the ground line (z = 0), within the joint range [rad].
double GroundBoomAngle(const model::MachineDescription& machine);

/// Runs the three motions on the plant. `functions` must be the machine's generated code.
/// Throws std::invalid_argument for a machine that is not a wheel loader.
HydraulicCycleTimes SimulateHydraulicCycleTimes(const model::MachineDescription& machine,
                                                const generated::MachineFunctions& functions,
                                                const CycleTimeOptions& options = {});

}  // namespace autoshovel::plant
