// The received power of one rangefinder pulse as a sampled waveform (excavator seed §3,
// Figs. 6–7): what the receiver of a time-of-flight scanner sees after firing into dust,
// through a possibly dirty exit window, at a target that may sit inside the dust.
//
// Model. The received power is the emitted pulse P0·s(t) convolved with the scene's range
// response along the ray (the single-scattering lidar equation):
//
//   P(t) = P0·K_w·s(t − 2r_w/c)                                            exit window
//        + P0·T_w²·∫ s(t − 2r/c)·β(r)·G(r)·exp(−2τ(r)) dr                   dust (volume)
//        + P0·T_w²·(ρ·cos θ/π)·G(r_t)·exp(−2τ(r_t))·s(t − 2r_t/c)            solid target
//
//   G(r) = A·η·O(r)/r²,  O(r) = min(1, (r/r_o)²),  τ(r) = ∫₀ʳ α(r′) dr′
//
// - Exit window (§3: "dust and dirt accumulating on the protective exit window"): dirt on the
//   window scatters the fraction K_w of the pulse straight back into the receiver at the
//   window's range r_w (a few cm), and passes T_w of the light each way. A clean, tilted
//   window sends its reflection away from the receiver: K_w = 0.
// - Dust (§3: "a dust cloud obscuring the target"): volumes with extinction α [1/m] and
//   backscatter β [1/(m·sr)]. Each slice dr of dust returns P0·β·dr·G(r) of the pulse, delayed
//   by its round trip, so the dust echo is spread over the cloud's depth; the light reaching
//   range r and coming back is attenuated twice by Beer–Lambert, exp(−2τ). The backscatter of
//   each 2.5 cm slice fluctuates (gamma-distributed, mean β, relative σ = the segment's
//   granularity): real clouds are lumpy, and the fluctuations are what a detector must not
//   mistake for targets. Single scattering only: multiply scattered light, which lengthens the
//   dust echo's tail in very thick clouds, is neglected.
// - Solid target: a Lambertian surface of reflectivity ρ filling the beam (the beam is a pencil:
//   no footprint spread over slanted surfaces), behind which nothing returns.
// - G(r): receiver aperture A, optical efficiency η, 1/r² spreading. O(r) is the overlap of
//   the transmitted beam and the receiver's field of view, which is incomplete near the
//   scanner; the quadratic ramp below r_o keeps G finite (and dust at the window harmless).
// - Receiver: Gaussian noise of variance σ_n² + k_s·P(t) (amplifier noise and the signal's
//   shot noise), then clipping at the saturation power.
// The waveform is sampled every sample_period from slightly before t = 0 (so the window's echo
// is complete) to the round trip of max_range.
#pragma once

#include <cstddef>
#include <vector>

#include "runtime/sensors/rangefinder/pulse_shape.h"
#include "runtime/sensors/rangefinder/rangefinder_scene.h"
#include "runtime/sensors/rng.h"

namespace autoshovel::sensors {

/// Laser and receiver. Defaults: a pulsed laser diode and an APD receiver of the class that
/// ranges a 10 % target to about 80 m (the scanners' max_range in
/// models/excavators/excavator_25t.yaml), digitised at 2 GS/s.
struct WaveformConfig {
  PulseShapeKind pulse_shape = PulseShapeKind::kGaussian;
  double pulse_fwhm = 4e-9;         ///< [s]: 0.6 m of range
  double peak_power = 20.0;         ///< P0 [W]
  double aperture_area = 2.0e-3;    ///< A [m²]: a 50 mm receiver lens
  double optical_efficiency = 0.7;  ///< η
  double overlap_range = 2.0;       ///< r_o [m]
  double sample_period = 0.5e-9;    ///< [s]: 7.5 cm of range per sample
  double max_range = 80.0;          ///< [m]
  double noise_sigma = 10e-9;       ///< σ_n [W]
  double shot_noise_power = 2e-10;  ///< k_s [W]
  double saturation_power = 2e-3;   ///< [W]
};

/// The protective exit window in front of the optics (§3).
struct ExitWindow {
  double range = 0.05;         ///< r_w [m]
  double backscatter = 0.0;    ///< K_w: fraction of the emitted power scattered back
  double transmittance = 1.0;  ///< T_w, one way
};

/// Throws std::invalid_argument for a negative or non-finite range, a backscatter outside
/// [0, 1] or a transmittance outside (0, 1].
void ValidateExitWindow(const ExitWindow& window);

/// A clean (tilted) window.
ExitWindow CleanWindow();
/// A window caked with dust: scatters 1.5·10⁻⁴ of the pulse back (3 mW from a 20 W pulse:
/// thousands of times a distant target's echo, and beyond the receiver's saturation) and
/// passes 80 % each way. Its echo's tail blinds the receiver to the first ~1.5 m.
ExitWindow DirtyWindow();

/// One pulse's received power.
struct Waveform {
  double start_time = 0;        ///< time of sample 0 after the pulse's peak left [s]
  double sample_period = 0;     ///< [s]
  double saturation_power = 0;  ///< samples at this level are clipped [W]
  std::vector<double> power;    ///< [W]

  double TimeAt(std::size_t n) const { return start_time + static_cast<double>(n) * sample_period; }
};

class WaveformSimulator {
 public:
  /// Throws std::invalid_argument for non-finite or non-positive parameters (noise terms may
  /// be 0), or a sample period longer than half the pulse's FWHM (the edges would not be
  /// sampled).
  explicit WaveformSimulator(const WaveformConfig& config);

  /// The noise-free received power (uniform dust, no granularity), clipped at saturation.
  /// Throws std::invalid_argument for an invalid profile or window.
  Waveform Expected(const RayProfile& profile, const ExitWindow& window) const;
  /// With dust granularity and receiver noise drawn from `rng`.
  Waveform Simulate(const RayProfile& profile, const ExitWindow& window, Rng& rng) const;

  /// G(r) = A·η·O(r)/r² [sr]: the solid angle of the receiver aperture seen from range r, × η.
  double GeometricFactor(double range) const;
  /// Peak power of a solid target's echo [W] behind a one-way optical depth τ and a window of
  /// transmittance T_w, before noise and clipping.
  double SolidPeakPower(const SolidHit& hit, double optical_depth, double transmittance) const;
  /// Samples per waveform.
  std::size_t num_samples() const { return num_samples_; }
  double start_time() const { return start_time_; }
  const PulseShape& pulse() const { return pulse_; }
  const WaveformConfig& config() const { return config_; }

 private:
  Waveform Build(const RayProfile& profile, const ExitWindow& window, Rng* rng) const;
  void AddPulse(std::vector<double>& power, double center_time, double amplitude) const;
  double PulseTable(double t) const;

  WaveformConfig config_;
  PulseShape pulse_;
  double support_ = 0;
  double table_step_ = 0;
  std::vector<double> table_;  // s(t) on [−support, support]
  double start_time_ = 0;
  std::size_t num_samples_ = 0;
};

}  // namespace autoshovel::sensors
