#include "runtime/sensors/rangefinder/dust_monitor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::sensors {

DustMonitor::DustMonitor(const DustMonitorConfig& config) : config_(config) {
  if (!std::isfinite(config.window) || config.window <= 0) {
    throw std::invalid_argument("DustMonitorConfig: window must be finite and > 0, got " +
                                std::to_string(config.window));
  }
  if (config.min_returning_pulses <= 0) {
    throw std::invalid_argument("DustMonitorConfig: min_returning_pulses must be > 0, got " +
                                std::to_string(config.min_returning_pulses));
  }
  if (!(config.warn_off_fraction >= 0 && config.warn_off_fraction < config.warn_on_fraction &&
        config.warn_on_fraction <= 1)) {
    throw std::invalid_argument(
        "DustMonitorConfig: need 0 ≤ warn_off_fraction < warn_on_fraction ≤ 1, got " +
        std::to_string(config.warn_off_fraction) + " and " +
        std::to_string(config.warn_on_fraction));
  }
  if (!(config.min_speed_scale > 0 && config.min_speed_scale <= 1)) {
    throw std::invalid_argument("DustMonitorConfig: min_speed_scale must be in (0, 1], got " +
                                std::to_string(config.min_speed_scale));
  }
}

void DustMonitor::Reset() {
  window_.clear();
  returning_ = dusty_ = 0;
  warning_ = false;
}

void DustMonitor::Add(double time, const PulseDetection& detection) {
  Add(time, detection.target_returns > 0, detection.DustEvidence());
}

void DustMonitor::Add(double time, bool returned, bool dust_evidence) {
  if (!std::isfinite(time) || (!window_.empty() && time < window_.back().time)) {
    throw std::invalid_argument("DustMonitor::Add: pulse times must be finite and in order, got " +
                                std::to_string(time));
  }
  // Evidence without a return beyond the window cannot happen; it counts as no return.
  const Entry entry{time, returned, returned && dust_evidence};
  window_.push_back(entry);
  returning_ += entry.returned ? 1 : 0;
  dusty_ += entry.dusty ? 1 : 0;
  while (window_.front().time <= time - config_.window) {
    returning_ -= window_.front().returned ? 1 : 0;
    dusty_ -= window_.front().dusty ? 1 : 0;
    window_.pop_front();
  }

  if (returning_ < config_.min_returning_pulses) return;  // too little seen: hold
  const double f = dust_fraction();
  if (!warning_ && f >= config_.warn_on_fraction) warning_ = true;
  if (warning_ && f <= config_.warn_off_fraction) warning_ = false;
}

double DustMonitor::dust_fraction() const {
  return returning_ > 0 ? static_cast<double>(dusty_) / returning_ : 0.0;
}

double DustMonitor::speed_scale() const {
  if (!warning_) return 1.0;
  return std::clamp(1.0 - dust_fraction(), config_.min_speed_scale, 1.0);
}

}  // namespace autoshovel::sensors
