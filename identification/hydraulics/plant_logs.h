// Plant logs to try hydraulic identification on: the simulated machine (runtime/plant) driven
// by valve steps and chirps on one actuator, logged like a data logger would, with sensor
// noise, so that the procedure can be run end to end and checked against a known truth.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "identification/hydraulics/log_reader.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {

struct PlantLogOptions {
  double rate = 100;             ///< logging (and control) rate [Hz]
  double start_fraction = 0.45;  ///< joint start position within its range [-]
  /// If finite, the driven joint starts here instead (clamped into its range) [rad].
  double start_angle = std::numeric_limits<double>::quiet_NaN();
  bool noise = true;
  unsigned long long seed = 1;
  // A typical data logger (as `autoshovel plant step --noise`): spool LVDT 0.5 % of full
  // stroke, angle encoder 0.05°, pressure transducers 0.1 MPa.
  double spool_noise = 0.005;                          ///< [-]
  double angle_noise = 0.05 * 3.14159265358979 / 180;  ///< [rad]
  double pressure_noise = 1e5;                         ///< [Pa]
};

/// Runs the plant (on an empty yard) with `command(t)` on `actuator` for `duration` seconds
/// and returns what was logged, in SI, with `file` and `actuator` filled in.
HydraulicLog SimulatePlantLog(const model::MachineDescription& machine,
                              const generated::MachineFunctions& functions, int actuator,
                              const std::function<double(double)>& command, double duration,
                              const PlantLogOptions& options = {});

/// How a log is written.
enum class LogStyle {
  kPlantStep,   ///< `autoshovel plant step`: t,command,spool,pressure,joint_angle (SI)
  kDataLogger,  ///< three header lines, a units row, ';', ms, %, deg, bar, other column order
};

/// The LogFormat that reads a kDataLogger file.
LogFormat DataLoggerFormat();

/// Writes `log` to `path` (throws std::runtime_error when it cannot).
void WriteLog(const HydraulicLog& log, const std::string& path, LogStyle style,
              const std::string& machine_name);

/// Step at `level` from t0 to t1, zero otherwise.
std::function<double(double)> StepCommand(double level, double t0, double t1);
/// Linear chirp of amplitude `level` from f0 to f1 [Hz] between t0 and t1, zero otherwise.
std::function<double(double)> ChirpCommand(double level, double f0, double f1, double t0,
                                           double t1);

/// The identification campaign `--simulate DIR` writes for one actuator: steps at 30, 60 and
/// 100 % in both directions (plant-step style) and a 60 % chirp from 0.2 to 1.5 Hz in the
/// data-logger style with its `<name>.columns.yaml` beside it. Returns the log paths.
std::vector<std::string> WriteSimulatedCampaign(const model::MachineDescription& machine,
                                                const generated::MachineFunctions& functions,
                                                int actuator, const std::string& dir,
                                                unsigned long long seed);

/// The step tests of a real excavator as its data acquisition exports them (dSPACE ControlDesk
/// CSV at 100 Hz, /work/shared/realdata/README.md "excavator_valve_steps"): 28 header lines, then
/// rows `trace_values,` (first) or `,` (later) followed by 28 columns: time [s]; cylinder
/// pressures Arm head, Arm rod, Bkt head, Bkt rod, Boom rod, Boom head [bar]; duty Arm_in,
/// Arm_out, Bkt_in, Bkt_out, Boom_dn, Boom_up [%]; valve driver feedback, same order [counts];
/// pilot (EPPR) pressure, same order [bar]; joint angles Arm, Bkt, Boom [deg]. "in"/"up" is the
/// extending direction (cap side), "out"/"dn" the retracting one.
struct ControlDeskOptions {
  double rate = 100;                  ///< [Hz]
  double pilot_pressure_full = 35e5;  ///< pilot pressure at full command [Pa]
  double rest = 1.0;                  ///< before the step [s]
  double stall_hold = 1.0;            ///< command held on after the joint has stalled [s]
  double max_step = 10.0;             ///< longest step: a slow low-duty run is cut there [s]
  double after = 0.5;                 ///< logged after the command is off [s]
  /// Where a step that does not start at the opposite stop starts: this fraction of the
  /// stroke away from the stop it runs into.
  double start_travel = 0.4;
  double angle_noise = 0.02 * 3.14159265358979 / 180;       ///< 1σ [rad]
  double pressure_noise = 1e5;                              ///< 1σ [Pa]
  double pilot_noise = 0.2e5;                               ///< 1σ [Pa]
  std::vector<int> duties = {40, 50, 60, 70, 80, 90, 100};  ///< [%]
};

/// The valve chain the campaign's machine has (its truth), per actuator: pilot delay and lag,
/// transport delay, dead zone 0 and an opening curve per direction with a dead band near
/// 35–40 % duty and saturation above 80 % (cf. the real logs). Returned as the text of an
/// overlay of `machine` for `actuators`.
std::string ControlDeskTruthOverlay(const model::MachineDescription& machine,
                                    const std::vector<int>& actuators,
                                    const std::string& command_line);

/// The step-test campaign of `actuators` (boom and arm of an excavator): writes the truth
/// overlay `DIR/truth.overlay.yaml`, loads `machine` with it and simulates, per actuator, both
/// directions at every duty of `options` with a high- and a low-load pose (H/L: the other joints
/// placed so that gravity loads the tested joint more or less), writing
/// `<B|A>-<up|dn|in|out>-<duty>-<H|L>-S.csv`. Each file: rest, the step held until the joint
/// has stalled at its end stop for `stall_hold` (or for `max_step`), the command off. The 100 %
/// files start with the joint resting against the opposite stop. Noise is drawn from
/// `seed`. Returns the log paths (the overlay is `DIR/truth.overlay.yaml`). Throws
/// std::invalid_argument for a machine that is not a three-link excavator or an actuator that
/// drives neither its boom nor its arm.
std::vector<std::string> WriteControlDeskCampaign(const model::MachineDescription& machine,
                                                  const generated::MachineFunctions& functions,
                                                  const std::vector<int>& actuators,
                                                  const std::string& dir, unsigned long long seed,
                                                  const ControlDeskOptions& options = {});

}  // namespace autoshovel::identification
