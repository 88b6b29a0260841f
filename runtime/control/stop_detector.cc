// Seed §6.2: confidence += (0.1 − v)·100 per cycle while v ≤ 0.15 m/s, reset above, stop at 100.
#include "runtime/control/stop_detector.h"

#include <algorithm>
#include <cmath>

namespace autoshovel::control {

bool StopDetector::Update(double speed) {
  if (!std::isfinite(speed)) {
    confidence_ = 0;
    return false;
  }
  const double v = std::abs(speed);
  if (v > kResetSpeed) {
    confidence_ = 0;
  } else {
    confidence_ = std::max(0.0, confidence_ + (kReferenceSpeed - v) * kGainPerMetrePerSecond);
  }
  return stopped();
}

}  // namespace autoshovel::control
