// The emitted laser pulse of the scanning rangefinders (excavator seed §2–3): its shape in time,
// with a unit peak, and the time-of-flight conversions every rangefinder file shares.
//
// Two shapes are offered:
// - Gaussian, s(t) = exp(−t²/2σ²), FWHM = 2σ·sqrt(2 ln 2): a bandwidth-limited receiver's
//   response to a short pulse;
// - sech², s(t) = sech²(t/τ), FWHM = 2τ·acosh(√2) ≈ 1.7627τ: the usual description of pulsed
//   laser diodes and Q-switched lasers, with exponential tails (4·e^{−2|t|/τ}) heavier than the
//   Gaussian's.
// Both are symmetric, so a pulse's rise and fall are mirror images: a detector that knows the
// shape can turn a threshold crossing on either edge into the pulse centre (pulse_detection.h).
#pragma once

namespace autoshovel::sensors {

/// Speed of light [m/s]. The simulation and the detectors use the same constant, so the
/// refractive index of air (range scale 1.0003, 2 cm at 80 m) is a shared calibration constant
/// and does not appear as an error.
inline constexpr double kSpeedOfLight = 299792458.0;

/// Round-trip time of flight to `range` [s].
inline constexpr double RangeToTime(double range) { return 2.0 * range / kSpeedOfLight; }
/// Range of a round-trip time of flight [m].
inline constexpr double TimeToRange(double time) { return 0.5 * kSpeedOfLight * time; }

enum class PulseShapeKind { kGaussian, kSech2 };

/// "gaussian", "sech2".
const char* ToString(PulseShapeKind kind);

/// One emitted pulse, peak 1 at t = 0.
class PulseShape {
 public:
  /// Throws std::invalid_argument unless `fwhm` is finite and positive.
  PulseShape(PulseShapeKind kind, double fwhm);

  /// s(t), peak 1 at t = 0.
  double Value(double t) const;
  /// ∫ s(t) dt [s]: the pulse energy is peak power × this.
  double Integral() const;
  /// Half-width beyond which s(t) < 1e-6 [s]; the simulation truncates the pulse there.
  double Support() const;
  /// The t ≥ 0 where s(t) = fraction, fraction ∈ (0, 1] [s]. Throws std::invalid_argument
  /// otherwise.
  double HalfWidthAt(double fraction) const;

  PulseShapeKind kind() const { return kind_; }
  double fwhm() const { return fwhm_; }
  /// σ of the Gaussian or τ of the sech² [s].
  double width_parameter() const { return width_; }

 private:
  PulseShapeKind kind_;
  double fwhm_;
  double width_;
};

}  // namespace autoshovel::sensors
