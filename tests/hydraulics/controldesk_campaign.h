// The excavator boom's plant step tests in the ControlDesk layout, as `autoshovel identify
// hydraulics --simulate DIR --format controldesk --machine excavator_25t --actuator
// boom_cylinders --seed 7` writes them, into a fresh temporary folder: shared by the tests that
// read them back and that fit them.
#pragma once

#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>

#include "identification/hydraulics/identify_hydraulics_command.h"

namespace autoshovel::identification::testing {

/// Writes the campaign into `dir` (emptied first); throws std::runtime_error with the command's
/// message when it fails.
inline void WriteBoomControlDeskCampaign(const std::string& dir, const std::string& models_dir) {
  std::filesystem::remove_all(dir);
  IdentifyHydraulicsOptions options;
  options.machine = "excavator_25t";
  options.models_dir = models_dir;
  options.actuator = "boom_cylinders";
  options.simulate = dir;
  options.simulate_format = "controldesk";
  options.seed = 7;
  std::ostringstream out, err;
  if (RunIdentifyHydraulics(options, out, err) != 0) {
    throw std::runtime_error("--simulate --format controldesk failed: " + err.str());
  }
}

}  // namespace autoshovel::identification::testing
