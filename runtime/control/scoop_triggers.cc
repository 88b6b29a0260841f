// Scoop triggers (seed §6.2, Table 5): V1 + V2 ≥ V_t, V1 ≥ V_t, boom pressure ≥ threshold.
#include "runtime/control/scoop_triggers.h"

#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

namespace {
double Positive(double value, const char* what) {
  if (!std::isfinite(value) || value <= 0) {
    throw std::invalid_argument(std::string(what) + " must be finite and > 0, got " +
                                std::to_string(value));
  }
  return value;
}
}  // namespace

PredictedVolumeTrigger::PredictedVolumeTrigger(double target_volume)
    : target_volume_(Positive(target_volume, "predicted-volume trigger: target volume")) {}

bool PredictedVolumeTrigger::Fire(const TriggerInputs& in) {
  // NaN compares false; a non-positive κ never fires.
  return in.v1 > 0 && in.intake_factor > 0 && in.intake_factor * (in.v1 + in.v2) >= target_volume_;
}

PerceptionTrigger::PerceptionTrigger(double target_volume)
    : target_volume_(Positive(target_volume, "perception trigger: target volume")) {}

bool PerceptionTrigger::Fire(const TriggerInputs& in) { return in.v1 >= target_volume_; }

BoomPressureTrigger::BoomPressureTrigger(double threshold, int hold_cycles)
    : threshold_(Positive(threshold, "boom-pressure trigger: threshold")),
      hold_cycles_(hold_cycles) {
  if (hold_cycles < 1) {
    throw std::invalid_argument("boom-pressure trigger: hold_cycles must be >= 1, got " +
                                std::to_string(hold_cycles));
  }
}

bool BoomPressureTrigger::Fire(const TriggerInputs& in) {
  count_ = in.boom_pressure >= threshold_ ? count_ + 1 : 0;
  return count_ >= hold_cycles_;
}

}  // namespace autoshovel::control
