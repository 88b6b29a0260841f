// Where the excavator's scanning laser rangefinders point (excavator seed §2, Figs. 2–4): two
// scanners on the upper structure on either side of the boom, each a rotating mirror sweeping
// the beam around a circle in a vertical plane, the whole head panned about its vertical axis
// so that the circle sweeps the workspace in azimuth.
//
// Scanner frame. Origin at the mirror centre, on the pan axis; z is the pan axis (up when the
// scanner is mounted level), x the beam direction at pan 0 and elevation 0, y = z × x. The beam
// of a pulse fired at elevation e (mirror angle) and pan p points along
//   d = (cos e·cos p, cos e·sin p, sin e)
// so at any pan all beams lie in the vertical plane through the pan axis at azimuth p: the
// "scan plane" of Fig. 3. The cab frame is the project's machine frame (x forward, y left,
// z up); T_cab_scanner places the scanner in it.
//
// Timing. Pulse k fires at t_k = k / pulse_rate (12 kHz, §2). The mirror turns at a constant
// rate, e(t) = mirror_phase + 2π·mirror_rate·t: upwards in front, over the top, down behind and
// up again from below. Pulses whose elevation falls outside the active arc are not fired (the
// rear half of the circle looks back across the scanner's own housing, the boom or the cab).
// The pan angle is that of the pan motion (PanSweep) at t_k, so while the head pans each circle
// is drawn slightly helically: every pulse carries its own pan angle.
//
// Parameters chosen (ScannerConfig's defaults), with reasons:
// - mirror_rate 20 rev/s: 600 pulses per circle, a 0.6° in-circle step, ≈ 10 cm at 10 m,
//   finer than the 15 cm cells of the seed's truck-bed map (§4.3). Across circles the spacing
//   is pan rate / mirror rate: 1.5° at a 30°/s pan over the truck, 6° at the 120°/s maximum
//   (§2), which is used for the fast obstacle sweep ahead of the swing.
// - active arc −75°…+30°: from the ground beside the tracks up to 30° above the horizon (the
//   top of a truck's side and a high dig face from a scanner 2.6 m up); everything else in the
//   circle is either the machine itself or sky. 105° of the 360° circle are fired: 175 pulses
//   per circle.
// - pan range −120°…+120°: the dig face in front and a truck parked beside the machine on either
//   side (§4.2: usually the left), with margin for the truck's length; the rear is the
//   counterweight and the cab.
// - pan rate limit 120°/s (§2).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <numbers>

namespace autoshovel::sensors {

/// One degree [rad].
inline constexpr double kDegree = std::numbers::pi / 180.0;

struct ScannerConfig {
  /// Cab ← scanner. The default is the left scanner's (LeftScannerConfig()).
  Eigen::Isometry3d T_cab_scanner = Eigen::Isometry3d::Identity();
  double pulse_rate = 12000.0;                    ///< pulses per second [Hz] (§2)
  double mirror_rate = 20.0;                      ///< scan-circle revolutions per second [Hz]
  double mirror_phase = 0.0;                      ///< elevation at t = 0 [rad]
  double active_elevation_min = -75.0 * kDegree;  ///< [rad]
  double active_elevation_max = 30.0 * kDegree;   ///< [rad]
  double pan_min = -120.0 * kDegree;              ///< [rad]
  double pan_max = 120.0 * kDegree;               ///< [rad]
  double pan_rate_limit = 120.0 * kDegree;        ///< [rad/s] (§2)
};

/// The scanner "positioned over the operator's cab", left of the boom (§2), at the left
/// scanner's mounting point of models/excavators/excavator_25t.yaml: (0.4, 0.8, 2.6) m, level.
ScannerConfig LeftScannerConfig();
/// Its mirror image on the right of the boom: (0.4, −0.8, 2.6) m.
ScannerConfig RightScannerConfig();

/// A pan motion: hold `start_angle` until `start_time`, turn towards `end_angle` at `rate`,
/// hold `end_angle`. The pan drive is treated as a velocity servo whose acceleration phases
/// (tens of milliseconds) are short against a sweep of seconds.
struct PanSweep {
  double start_time = 0;   ///< [s]
  double start_angle = 0;  ///< [rad]
  double end_angle = 0;    ///< [rad]
  double rate = 0;         ///< speed, ≥ 0 [rad/s]; 0 only when start == end
};

/// A pan held at `angle`.
PanSweep HoldPan(double angle);

/// One pulse's beam.
struct ScanRay {
  std::int64_t index = 0;
  double time = 0;       ///< firing time [s]
  double elevation = 0;  ///< mirror angle, wrapped to (−π, π] [rad]
  double pan = 0;        ///< [rad]
  bool active = false;   ///< inside the active arc: fired
  Eigen::Vector3d origin_cab = Eigen::Vector3d::Zero();          ///< [m]
  Eigen::Vector3d direction_cab = Eigen::Vector3d::UnitX();      ///< unit
  Eigen::Vector3d direction_scanner = Eigen::Vector3d::UnitX();  ///< unit
};

class ScannerGeometry {
 public:
  /// Throws std::invalid_argument for a non-finite or non-positive rate, an empty or
  /// out-of-circle active arc, an empty pan range, or a non-rigid T_cab_scanner.
  explicit ScannerGeometry(const ScannerConfig& config);

  /// Firing time of pulse k [s].
  double PulseTime(std::int64_t k) const;
  /// The first pulse fired at or after t.
  std::int64_t FirstPulseAtOrAfter(double t) const;
  /// Mirror elevation at time t, wrapped to (−π, π] [rad].
  double ElevationAt(double t) const;
  bool InActiveArc(double elevation) const;
  /// Throws std::invalid_argument if the sweep leaves the pan range, exceeds the pan rate
  /// limit, or has a non-finite field.
  void Validate(const PanSweep& pan) const;
  /// Pan angle at time t [rad]. Validates the sweep.
  double PanAt(const PanSweep& pan, double t) const;
  /// Unit beam direction in the scanner frame.
  static Eigen::Vector3d DirectionInScanner(double elevation, double pan);
  /// The beam of pulse k under the pan motion `pan`. Validates the sweep.
  ScanRay Ray(std::int64_t k, const PanSweep& pan) const;

  /// Pulses per scan-circle revolution (fired or not).
  double pulses_per_circle() const { return config_.pulse_rate / config_.mirror_rate; }
  /// Elevation step between consecutive pulses [rad].
  double elevation_step() const;
  const ScannerConfig& config() const { return config_; }

 private:
  double PanAtUnchecked(const PanSweep& pan, double t) const;

  ScannerConfig config_;
};

}  // namespace autoshovel::sensors
