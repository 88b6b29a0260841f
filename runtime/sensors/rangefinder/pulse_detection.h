// Range from a return waveform (excavator seed §3, Figs. 6–8): the three ways a time-of-flight
// receiver can turn the received light into a range, and the multiple-return report.
//
// The waveform is first smoothed (Gaussian, smoothing_sigma) against noise, then cut into
// returns: stretches above the detection threshold; a return ends only after min_gap below it,
// so noise on a slowly decaying dust echo does not split it into many.
//
// Edge timing. An edge is timed where it crosses a level L = max(f·A, T) set by its peak A and
// the threshold T, and corrected by the known half-width of a single surface's smoothed echo
// at that level: t0 = t_cross ± w(L/A). w is calibrated from the pulse shape, the sample period
// and the smoothing. f = 0 is a leading-edge discriminator at the fixed threshold with
// amplitude-walk correction; f = 0.5 a constant-fraction discriminator, which times the edge
// where it is steepest, so noise moves it least.
// - The leading edge (first and last pulse) is timed at the threshold (leading_fraction 0), as
//   the seed's last-pulse unit must be to behave as §3 reports: it fires on the first light of
//   a return, so a target merged with the dust in front of it is reported at the cloud's front
//   (Fig. 8). A constant fraction (0.5) of the return's first peak ranges clear-air targets
//   better, but where the dust in front is under ~2 m deep it has no peak of its own and the
//   fraction lands on the target's rise: a better device than the seed's, not the one it
//   describes.
// - The trailing edge is timed at half its peak (trailing_fraction 0.5).
//
// The three ranges:
// - First pulse (a conventional rangefinder): the leading edge of the first return, timed on its
//   first peak's height. It sees the dirty exit window at ~0 m, or the front of a dust cloud
//   instead of the target (§3).
// - Last pulse (§3, Fig. 6): the leading edge of the last return. Reflections off the window
//   and dust in front of the target come earlier and are rejected; a return in the window zone
//   (closer than window_zone_range: the window's own echo) is never a target, so a pulse that
//   returns only from the window reports nothing. When the target is inside the cloud, dust and
//   target merge into one return (Fig. 7) and the last pulse reports its start, the front of
//   the cloud (Fig. 8).
// - Trailing edge (§3, Figs. 7–8): the target is the last thing the beam meets and nothing
//   behind it returns light, so the last return ends where the target's echo ends however much
//   dust precedes it. The detector climbs back from the end of the last return to its last peak,
//   times the falling edge at trailing_fraction of that peak and subtracts w. Two tests keep it
//   from calling dust a target:
//   * prominence: the waveform must rise into the peak (within edge_window_fwhm echo widths
//     before the peak it dips to at most `prominence` of the peak, and the peak stands at least
//     the threshold above the dip). A lump in a dust echo has as much dust before it as under
//     it; a noise blip on a dust tail hardly rises above the tail;
//   * fall steepness: the peak's 80 %→20 % fall may take at most (1 + max_fall_stretch) × a
//     single echo's (plus 3σ of its timing noise). Behind a surface the light stops at once;
//     a dense cloud's echo is the pulse smeared by the exponential decay into the cloud and
//     falls more slowly.
//   The price (§3: it "forgoes some range accuracy") is a bias of a few cm towards the scanner
//   when the dust just in front of the target is bright compared with the target, and no range
//   at all when that dust outshines the target's echo.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "runtime/sensors/rangefinder/return_waveform.h"

namespace autoshovel::sensors {

struct DetectorConfig {
  double threshold = 0;            ///< on the smoothed waveform [W], > 0
  double smoothing_sigma = 1e-9;   ///< [s]
  double min_gap = 2e-9;           ///< below threshold this long ends a return [s]
  double window_zone_range = 0.5;  ///< leading edges nearer than this are the window's [m]
  double edge_window_fwhm = 1.5;   ///< peak search and prominence span, in echo FWHMs
  double leading_fraction = 0.0;   ///< timing level on the rising edge, [0, 1)
  double trailing_fraction = 0.5;  ///< timing level on the falling edge, [0, 1)
  double prominence = 0.7;         ///< see above, (0, 1)
  double max_fall_stretch = 0.10;  ///< see above, ≥ 0
  /// A return longer than a single echo of its height by more than this many smoothed-echo
  /// FWHMs is extended: range-spread scatterers (dust) rather than one surface.
  double extended_margin_fwhm = 1.0;
};

/// A detector for waveforms of `waveform`: threshold = threshold_snr × the smoothed receiver
/// noise σ (6σ: about one false return per million pulses). Throws std::invalid_argument for
/// a non-positive SNR or smoothing, or a noise-free receiver (no threshold can be derived).
DetectorConfig MakeDetectorConfig(const WaveformConfig& waveform, double threshold_snr = 6.0,
                                  double smoothing_sigma = 1e-9);

/// One return: a stretch of the smoothed waveform above the threshold.
struct EchoReturn {
  double rise_time = 0;           ///< upward threshold crossing [s]
  double fall_time = 0;           ///< last downward threshold crossing [s]
  double peak_time = 0;           ///< of its highest point [s]
  double peak_power = 0;          ///< smoothed [W]
  double leading_edge_range = 0;  ///< [m]
  bool window = false;            ///< in the window zone
  bool extended = false;          ///< longer than one echo: dust
  bool saturated = false;         ///< the receiver clipped inside it
};

struct PulseDetection {
  std::vector<EchoReturn> returns;            ///< in time order, window's included
  std::optional<double> first_pulse_range;    ///< [m]
  std::optional<double> last_pulse_range;     ///< [m]; never the window's
  std::optional<double> trailing_edge_range;  ///< [m]; none when no target stands out
  int target_returns = 0;                     ///< returns beyond the window zone
  bool window_return = false;                 ///< the exit window returned light
  bool multiple_returns = false;              ///< ≥ 2 returns beyond the window zone
  bool extended_return = false;               ///< some return beyond the window zone is extended
  bool trailing_edge_saturated = false;

  /// What the dust monitor counts (§3: "report when multiple returns occur, giving a warning
  /// that dust is present"): several returns, or one stretched over the depth of a cloud.
  bool DustEvidence() const { return multiple_returns || extended_return; }
};

class PulseDetector {
 public:
  /// Throws std::invalid_argument for an invalid waveform configuration or detector
  /// parameters out of range.
  PulseDetector(const WaveformConfig& waveform, const DetectorConfig& config);

  /// Throws std::invalid_argument for a waveform of another sample period, an empty one, or
  /// non-finite samples.
  PulseDetection Detect(const Waveform& waveform) const;

  /// The waveform after smoothing [W].
  std::vector<double> Smooth(const std::vector<double>& power) const;
  /// Half-width of the smoothed echo at `fraction` of its peak [s], fraction ∈ (0, 1].
  double EchoHalfWidth(double fraction) const;
  /// Standard deviation of the smoothed waveform's noise at signal level `level` [W]: the
  /// receiver's noise model (WaveformConfig) through the smoothing.
  double NoiseSigma(double level) const;
  /// FWHM of the smoothed echo [s].
  double echo_fwhm() const { return echo_fwhm_; }
  const DetectorConfig& config() const { return config_; }

 private:
  struct Peak {
    std::size_t index = 0;
    double time = 0, power = 0;
  };
  // From sample `from` towards `to` (either direction), follow the waveform uphill to the first
  // peak: stop where it has fallen more than kClimbSigmas noise σ below the highest sample so
  // far, or at `to`.
  std::size_t Climb(const std::vector<double>& y, std::size_t from, std::size_t to) const;
  // The sub-sample peak at sample i (parabola through i and its neighbours).
  Peak Refine(const std::vector<double>& y, std::size_t i, double start_time) const;
  // Time at which y, going from the peak in direction `step` (±1), first drops below `level`.
  std::optional<double> Crossing(const std::vector<double>& y, std::size_t peak, int step,
                                 double level, double start_time) const;
  // One return's crossings, peaks, leading edge and flags; [begin, end] are its samples.
  EchoReturn Measure(const std::vector<double>& y, const Waveform& waveform, std::size_t begin,
                     std::size_t end) const;
  std::optional<double> TrailingEdge(const std::vector<double>& y, std::size_t begin,
                                     std::size_t end, double start_time) const;
  double EchoHalfWidthSlope(double fraction) const;

  DetectorConfig config_;
  double sample_period_;
  double noise_variance_;       // σ_n² of the raw samples [W²]
  double shot_noise_power_;     // k_s [W]
  double noise_gain_ = 1;       // sqrt(Σw²) of the smoothing
  std::vector<double> kernel_;  // smoothing weights, centred, sum 1
  // Half-width of the smoothed echo, tabulated against u = sqrt(−2 ln f) (exactly linear in u
  // for a Gaussian echo, smooth for a sech²).
  std::vector<double> width_table_;
  double u_step_ = 0;
  double echo_fwhm_ = 0;
  std::size_t edge_window_samples_ = 0;
  std::size_t leading_span_samples_ = 0;
  std::size_t gap_samples_ = 0;
};

}  // namespace autoshovel::sensors
