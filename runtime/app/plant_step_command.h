// `autoshovel plant step`: a valve step or chirp on one actuator of the simulated machine,
// logged as CSV — the input of hydraulic delay identification.
#pragma once

#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct PlantStepOptions {
  std::string machine;  ///< name or description path
  std::string models_dir;
  std::string actuator = "boom";
  double amplitude = 0.5;       ///< valve duty of the step, or of the chirp, in [-1, 1]
  bool chirp = false;           ///< linear sweep from chirp_f0 to chirp_f1 instead of a step
  double chirp_f0 = 0.1;        ///< [Hz]
  double chirp_f1 = 2.0;        ///< [Hz]
  double step_time = 0.5;       ///< when the step (or chirp) starts [s]
  double duration = 4.0;        ///< [s]
  double sample_rate = 100.0;   ///< control and logging rate [Hz]
  bool noise = false;           ///< add sensor noise to spool, pressure and angle
  unsigned long long seed = 1;  ///< for the noise
  std::string output;           ///< CSV path; empty: standard output
};

/// Runs the experiment; returns a process exit code (diagnostics on `err`).
int RunPlantStep(const PlantStepOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
