// Plant logs to try hydraulic identification on: the simulated machine (runtime/plant) driven
// by valve steps and chirps on one actuator, logged like a data logger would, with sensor
// noise, so that the procedure can be run end to end and checked against a known truth.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "identification/hydraulics/log_reader.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {

struct PlantLogOptions {
  double rate = 100;             ///< logging (and control) rate [Hz]
  double start_fraction = 0.45;  ///< joint start position within its range [-]
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

}  // namespace autoshovel::identification
