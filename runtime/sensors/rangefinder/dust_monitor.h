// The dust warning (excavator seed §3): "the laser system can also report when multiple returns
// occur, giving a warning that dust is present ... so an autonomous machine might need to adopt
// a slower, more conservative motion strategy."
//
// Rule. Over a sliding window of the last `window` seconds of fired pulses, the dust fraction f
// is the share of the pulses that returned anything beyond the exit window whose detection
// shows dust
// evidence (PulseDetection::DustEvidence: two or more returns, or one stretched over a cloud's
// depth). Pulses into the open sky say nothing about dust and are not counted; while fewer than
// min_returning_pulses of the window returned, the state is held.
// - The warning comes on when f ≥ warn_on_fraction and goes off when f ≤ warn_off_fraction.
//   The gap between the two is the hysteresis: a cloud drifting through the scan keeps f
//   wandering around a single threshold, and the machine must not jerk between speeds.
// - While the warning is on, the recommended speed scale is max(min_speed_scale, 1 − f): the
//   machine slows in proportion to the share of unreliable ranges, so the rate at which it
//   gets dust-free ranges per metre of travel stays about what it was in clear air. It never
//   stops for dust alone (the obstacle detector stops for obstacles); without the warning it
//   is 1.
//
// Defaults and why:
// - window 0.1 s: two scan circles at 20 rev/s (350 fired pulses of each scanner at 12 kHz),
//   so the fraction averages over whole circles (dust fills only part of a circle) and the
//   warning reacts within 0.1 s, far inside the 2–3 s look-ahead of the obstacle detector
//   (§4.5). A window in time rather than in pulses keeps this whatever the active arc and
//   however many scanners feed the monitor.
// - min_returning_pulses 100: a fraction of 10 % is then ten or more dusty pulses, not one or
//   two.
// - warn_on_fraction 0.10: in clear air multiple returns come only from beam edges straddling
//   two surfaces and noise (measured well under 1 % in the tests), so 10 % is unmistakably dust.
// - warn_off_fraction 0.03: a third of the on level.
// - min_speed_scale 0.3.
#pragma once

#include <deque>

#include "runtime/sensors/rangefinder/pulse_detection.h"

namespace autoshovel::sensors {

struct DustMonitorConfig {
  double window = 0.1;  ///< [s]
  int min_returning_pulses = 100;
  double warn_on_fraction = 0.10;
  double warn_off_fraction = 0.03;
  double min_speed_scale = 0.3;
};

class DustMonitor {
 public:
  /// Throws std::invalid_argument unless window > 0, min_returning_pulses > 0,
  /// 0 ≤ warn_off_fraction < warn_on_fraction ≤ 1 and min_speed_scale ∈ (0, 1].
  explicit DustMonitor(const DustMonitorConfig& config = {});

  /// One fired pulse's detection, fired at `time` [s]. Throws std::invalid_argument for a
  /// non-finite time or one before the previous pulse's.
  void Add(double time, const PulseDetection& detection);
  /// The same from its two facts: did it return beyond the window, did it show dust.
  void Add(double time, bool returned, bool dust_evidence);
  void Reset();

  bool warning() const { return warning_; }
  /// Dust fraction over the window (0 while nothing returned).
  double dust_fraction() const;
  /// Recommended scale of the machine's speed, (0, 1].
  double speed_scale() const;
  int returning_pulses() const { return returning_; }
  const DustMonitorConfig& config() const { return config_; }

 private:
  struct Entry {
    double time;
    bool returned, dusty;
  };

  DustMonitorConfig config_;
  std::deque<Entry> window_;  // the pulses of the last config_.window seconds
  int returning_ = 0;
  int dusty_ = 0;
  bool warning_ = false;
};

}  // namespace autoshovel::sensors
