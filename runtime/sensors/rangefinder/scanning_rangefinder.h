// One of the excavator's scanning laser rangefinders end to end (excavator seed §2–3): the
// scan geometry picks the beam of each pulse, the scene says what lies along it, the waveform
// simulation produces the received power and the detector the ranges. The dust monitor
// (dust_monitor.h) is fed by the caller, typically with every fired pulse of both scanners.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "runtime/sensors/rangefinder/pulse_detection.h"
#include "runtime/sensors/rangefinder/rangefinder_scene.h"
#include "runtime/sensors/rangefinder/return_waveform.h"
#include "runtime/sensors/rangefinder/scanner_geometry.h"
#include "runtime/sensors/rng.h"

namespace autoshovel::sensors {

/// One fired pulse.
struct ScanPulse {
  ScanRay ray;
  PulseDetection detection;
  /// The detected ranges as points in the cab frame [m].
  std::optional<Eigen::Vector3d> p_cab_first, p_cab_last, p_cab_trailing;
};

class ScanningRangefinder {
 public:
  /// Throws std::invalid_argument as the parts' constructors do.
  ScanningRangefinder(const ScannerConfig& scanner, const WaveformConfig& waveform,
                      const DetectorConfig& detector, const ExitWindow& window = CleanWindow());

  /// Fires pulse k under the pan motion `pan`, with the cab at T_scene_cab in the scene. No
  /// pulse (and no random draw) outside the active arc.
  std::optional<ScanPulse> Fire(std::int64_t k, const PanSweep& pan,
                                const Eigen::Isometry3d& T_scene_cab, const RangefinderScene& scene,
                                Rng& rng) const;

  /// The window gets dirty or is cleaned. Throws std::invalid_argument for an invalid window.
  void set_window(const ExitWindow& window);
  const ExitWindow& window() const { return window_; }
  const ScannerGeometry& geometry() const { return geometry_; }
  const WaveformSimulator& waveform() const { return waveform_; }
  const PulseDetector& detector() const { return detector_; }

 private:
  ScannerGeometry geometry_;
  WaveformSimulator waveform_;
  PulseDetector detector_;
  ExitWindow window_;
};

}  // namespace autoshovel::sensors
