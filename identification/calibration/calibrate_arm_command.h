// `autoshovel calibrate arm DATA.csv --machine M`: the arm calibration of wheel-loader seed §3.1
// from a measurement file (arm_calibration_csv.h), printed as a table and written as an overlay
// of the machine description. `--simulate FILE` writes such a file from the machine's own model
// with the seed's §7.1 noise, to try the procedure before measuring.
//
// The command lives in identification/ (the `autoshovel` executable registers it): runtime
// libraries never depend on identification, the executable that composes everything does.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace autoshovel::identification {

struct CalibrateArmOptions {
  std::string data;  ///< measurement CSV
  std::string machine;
  std::string models_dir;
  std::vector<double> initial;  ///< [l_1 … l_n (m), α_1 … α_n (deg)]; empty: nominal
  std::string overlay;          ///< where to write the overlay; empty: <data>.overlay.yaml
  std::string png;              ///< residual chart; empty: <overlay>.png
  std::string simulate;         ///< write a simulated measurement file here instead
  unsigned long long seed = 1;  ///< of the simulated noise
};

int RunCalibrateArm(const CalibrateArmOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::identification
