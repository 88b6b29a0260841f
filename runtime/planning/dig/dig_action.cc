#include "runtime/planning/dig/dig_action.h"

#include <cmath>

namespace autoshovel::planning {

bool IsFinite(const DigAction& action) {
  return std::isfinite(action.swing) && std::isfinite(action.radius) &&
         std::isfinite(action.entry_height) && std::isfinite(action.depth) &&
         std::isfinite(action.drag_length);
}

bool IsUsable(const DigPrediction& prediction, std::string& why) {
  if (!prediction.executed) {
    why = prediction.why.empty() ? "not executed" : "not executed: " + prediction.why;
    return false;
  }
  if (!std::isfinite(prediction.volume) || !std::isfinite(prediction.energy) ||
      !std::isfinite(prediction.duration)) {
    why = "non-finite prediction (volume " + std::to_string(prediction.volume) + ", energy " +
          std::to_string(prediction.energy) + ", duration " + std::to_string(prediction.duration) +
          ")";
    return false;
  }
  if (prediction.volume < 0 || prediction.energy < 0 || prediction.duration < 0) {
    why = "negative prediction (volume " + std::to_string(prediction.volume) + " m^3, energy " +
          std::to_string(prediction.energy) + " J, duration " +
          std::to_string(prediction.duration) + " s)";
    return false;
  }
  for (const Eigen::Vector3d& p : prediction.tip_path) {
    if (!p.allFinite()) {
      why = "non-finite point in the predicted tip path";
      return false;
    }
  }
  return true;
}

}  // namespace autoshovel::planning
