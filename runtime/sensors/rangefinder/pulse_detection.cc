#include "runtime/sensors/rangefinder/pulse_detection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace autoshovel::sensors {
namespace {

// The width table covers fractions down to exp(−u_max²/2) ≈ 1e−9, below any threshold/peak
// ratio the receiver can produce (saturation / threshold ≈ 1e5).
constexpr double kMaxU = 6.5;
constexpr int kWidthTableSize = 1301;
// The fall-steepness test (DetectorConfig::max_fall_stretch) times the fall from 80 % to 20 %
// of the peak, the low level kept 1.2 × the threshold clear of it, and is skipped for echoes
// too weak to leave a 30 % span (their fall is mostly noise).
constexpr double kFallHigh = 0.8;
constexpr double kFallLow = 0.2;
constexpr double kFallLowMargin = 1.2;
constexpr double kMinFallSpan = 0.3;
constexpr double kFallNoiseSigmas = 3.0;
// A climb to a peak ends where the waveform has fallen this many noise σ below the best so far.
constexpr double kClimbSigmas = 3.0;
// A return's first peak is sought this many echo FWHMs after its rise: the strongest
// unsaturated echo (peak/threshold ≈ 10⁵) peaks 2.0 FWHMs after its threshold crossing.
constexpr double kLeadingSpanFwhm = 2.5;

std::vector<double> GaussianKernel(double sigma, double dt) {
  const auto half = static_cast<int>(std::ceil(4.0 * sigma / dt));
  std::vector<double> w(2 * half + 1);
  double sum = 0;
  for (int k = -half; k <= half; ++k) {
    const double x = k * dt / sigma;
    w[k + half] = std::exp(-0.5 * x * x);
    sum += w[k + half];
  }
  for (double& v : w) v /= sum;
  return w;
}

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

bool InOpenUnit(double x) { return x > 0 && x < 1; }

}  // namespace

DetectorConfig MakeDetectorConfig(const WaveformConfig& waveform, double threshold_snr,
                                  double smoothing_sigma) {
  Require(std::isfinite(threshold_snr) && threshold_snr > 0,
          "MakeDetectorConfig: threshold_snr must be finite and > 0, got " +
              std::to_string(threshold_snr));
  Require(std::isfinite(smoothing_sigma) && smoothing_sigma > 0,
          "MakeDetectorConfig: smoothing_sigma must be finite and > 0, got " +
              std::to_string(smoothing_sigma));
  Require(std::isfinite(waveform.sample_period) && waveform.sample_period > 0,
          "MakeDetectorConfig: the waveform's sample_period must be finite and > 0");
  Require(std::isfinite(waveform.noise_sigma) && waveform.noise_sigma > 0,
          "MakeDetectorConfig: a threshold needs receiver noise (noise_sigma > 0)");
  double sum_w2 = 0;
  for (const double w : GaussianKernel(smoothing_sigma, waveform.sample_period)) sum_w2 += w * w;
  DetectorConfig config;
  config.smoothing_sigma = smoothing_sigma;
  config.threshold = threshold_snr * waveform.noise_sigma * std::sqrt(sum_w2);
  return config;
}

PulseDetector::PulseDetector(const WaveformConfig& waveform, const DetectorConfig& config)
    : config_(config),
      sample_period_(waveform.sample_period),
      noise_variance_(waveform.noise_sigma * waveform.noise_sigma),
      shot_noise_power_(waveform.shot_noise_power) {
  const PulseShape pulse(waveform.pulse_shape, waveform.pulse_fwhm);
  Require(std::isfinite(sample_period_) && sample_period_ > 0 &&
              sample_period_ <= 0.5 * waveform.pulse_fwhm,
          "PulseDetector: the sample period must be finite, > 0 and ≤ half the pulse FWHM");
  Require(
      std::isfinite(config.threshold) && config.threshold > 0,
      "DetectorConfig: threshold must be finite and > 0, got " + std::to_string(config.threshold));
  Require(std::isfinite(config.smoothing_sigma) && config.smoothing_sigma > 0,
          "DetectorConfig: smoothing_sigma must be finite and > 0");
  Require(std::isfinite(config.min_gap) && config.min_gap >= 0,
          "DetectorConfig: min_gap must be finite and ≥ 0");
  Require(std::isfinite(config.window_zone_range),
          "DetectorConfig: window_zone_range must be finite");
  Require(std::isfinite(config.edge_window_fwhm) && config.edge_window_fwhm > 0,
          "DetectorConfig: edge_window_fwhm must be finite and > 0");
  Require(config.leading_fraction >= 0 && config.leading_fraction < 1,
          "DetectorConfig: leading_fraction must be in [0, 1), got " +
              std::to_string(config.leading_fraction));
  Require(config.trailing_fraction >= 0 && config.trailing_fraction < 1,
          "DetectorConfig: trailing_fraction must be in [0, 1), got " +
              std::to_string(config.trailing_fraction));
  Require(InOpenUnit(config.prominence),
          "DetectorConfig: prominence must be in (0, 1), got " + std::to_string(config.prominence));
  Require(std::isfinite(config.max_fall_stretch) && config.max_fall_stretch >= 0,
          "DetectorConfig: max_fall_stretch must be finite and ≥ 0");
  Require(std::isfinite(config.extended_margin_fwhm) && config.extended_margin_fwhm >= 0,
          "DetectorConfig: extended_margin_fwhm must be finite and ≥ 0");

  kernel_ = GaussianKernel(config.smoothing_sigma, sample_period_);
  double sum_w2 = 0;
  for (const double w : kernel_) sum_w2 += w * w;
  noise_gain_ = std::sqrt(sum_w2);
  const int half = static_cast<int>(kernel_.size() / 2);
  // The smoothed echo of a pulse centred at 0, as a continuous function: the samples of the
  // smoothed waveform are exactly its values, whatever the pulse's sub-sample position.
  auto echo = [&](double x) {
    double q = 0;
    for (int k = -half; k <= half; ++k)
      q += kernel_[k + half] * pulse.Value(x - k * sample_period_);
    return q;
  };
  const double q0 = echo(0.0);
  const double x_max = pulse.Support() + half * sample_period_;
  u_step_ = kMaxU / (kWidthTableSize - 1);
  width_table_.resize(kWidthTableSize);
  width_table_[0] = 0;
  for (int i = 1; i < kWidthTableSize; ++i) {
    const double u = i * u_step_;
    const double target = q0 * std::exp(-0.5 * u * u);
    // The smoothed echo decreases monotonically for x > 0 (both pulse and kernel are
    // symmetric and unimodal): bisection.
    double lo = width_table_[i - 1], hi = x_max;
    if (echo(hi) >= target) {
      width_table_[i] = hi;
      continue;
    }
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (echo(mid) > target ? lo : hi) = mid;
    }
    width_table_[i] = 0.5 * (lo + hi);
  }
  echo_fwhm_ = 2.0 * EchoHalfWidth(0.5);
  edge_window_samples_ =
      static_cast<std::size_t>(std::ceil(config.edge_window_fwhm * echo_fwhm_ / sample_period_));
  leading_span_samples_ =
      static_cast<std::size_t>(std::ceil(kLeadingSpanFwhm * echo_fwhm_ / sample_period_));
  gap_samples_ = static_cast<std::size_t>(std::ceil(config.min_gap / sample_period_));
}

double PulseDetector::EchoHalfWidth(double fraction) const {
  if (!(fraction > 0 && fraction <= 1)) {
    throw std::invalid_argument("PulseDetector::EchoHalfWidth: fraction must be in (0, 1], got " +
                                std::to_string(fraction));
  }
  const double u = std::sqrt(-2.0 * std::log(fraction)) / u_step_;
  const auto i = static_cast<std::size_t>(u);
  if (i + 1 >= width_table_.size()) return width_table_.back();
  const double f = u - static_cast<double>(i);
  return width_table_[i] + f * (width_table_[i + 1] - width_table_[i]);
}

std::vector<double> PulseDetector::Smooth(const std::vector<double>& power) const {
  const auto n = static_cast<std::ptrdiff_t>(power.size());
  const auto half = static_cast<std::ptrdiff_t>(kernel_.size() / 2);
  std::vector<double> y(power.size(), 0.0);
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    double acc = 0;
    // Zero beyond the record's ends: the record starts before the earliest echo and ends after
    // the latest, so only noise is missing there (repeating the edge samples instead would
    // raise the noise at the edges and with it the false alarms).
    const std::ptrdiff_t k_lo = std::max(-half, i - (n - 1)), k_hi = std::min(half, i);
    for (std::ptrdiff_t k = k_lo; k <= k_hi; ++k) {
      acc += kernel_[static_cast<std::size_t>(k + half)] * power[static_cast<std::size_t>(i - k)];
    }
    y[static_cast<std::size_t>(i)] = acc;
  }
  return y;
}

std::size_t PulseDetector::Climb(const std::vector<double>& y, std::size_t from,
                                 std::size_t to) const {
  std::size_t best = from;
  std::size_t i = from;
  while (i != to) {
    i = to > from ? i + 1 : i - 1;
    if (y[i] > y[best]) {
      best = i;
    } else if (y[i] < y[best] - kClimbSigmas * NoiseSigma(y[best])) {
      break;
    }
  }
  return best;
}

PulseDetector::Peak PulseDetector::Refine(const std::vector<double>& y, std::size_t i,
                                          double start_time) const {
  Peak peak;
  peak.index = i;
  peak.power = y[i];
  peak.time = start_time + static_cast<double>(i) * sample_period_;
  if (i > 0 && i + 1 < y.size()) {
    const double a = y[i - 1], b = y[i], c = y[i + 1];
    const double curvature = a - 2.0 * b + c;
    if (curvature < 0) {
      const double delta = std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
      peak.power = b - 0.25 * (a - c) * delta;
      peak.time += delta * sample_period_;
    }
  }
  return peak;
}

std::optional<double> PulseDetector::Crossing(const std::vector<double>& y, std::size_t peak,
                                              int step, double level, double start_time) const {
  std::size_t m = peak;
  std::size_t prev = peak;
  while (y[m] >= level) {
    if ((step < 0 && m == 0) || (step > 0 && m + 1 >= y.size())) return std::nullopt;
    prev = m;
    m = step > 0 ? m + 1 : m - 1;
  }
  if (m == peak) return std::nullopt;  // the "peak" is below the level
  const double t_prev = start_time + static_cast<double>(prev) * sample_period_;
  return t_prev + step * sample_period_ * (y[prev] - level) / (y[prev] - y[m]);
}

double PulseDetector::NoiseSigma(double level) const {
  return noise_gain_ * std::sqrt(noise_variance_ + shot_noise_power_ * std::max(level, 0.0));
}

double PulseDetector::EchoHalfWidthSlope(double fraction) const {
  // |dw/df| by a central difference inside (0, 1).
  const double h = 1e-3;
  const double lo = std::max(fraction - h, 1e-9), hi = std::min(fraction + h, 1.0);
  return (EchoHalfWidth(lo) - EchoHalfWidth(hi)) / (hi - lo);
}

std::optional<double> PulseDetector::TrailingEdge(const std::vector<double>& y, std::size_t begin,
                                                  std::size_t end, double start_time) const {
  // Back from the return's end, up its falling edge, to its last peak.
  const std::size_t top = Climb(y, end, begin);
  // The waveform must rise into that peak: within edge_window_fwhm echo widths before it, it
  // dips to at most `prominence` of the peak, and the peak stands at least the threshold above
  // the dip (the target's echo is itself detectable above the dust in front of it). A noise
  // blip on a dust tail hardly rises above the tail; a lump in a dust echo has as much dust
  // before it as under it.
  const std::size_t span_begin = top > edge_window_samples_ ? top - edge_window_samples_ : 0;
  if (top == span_begin) return std::nullopt;
  const Peak peak = Refine(y, top, start_time);
  const double dip = *std::min_element(y.begin() + static_cast<std::ptrdiff_t>(span_begin),
                                       y.begin() + static_cast<std::ptrdiff_t>(top));
  if (dip > config_.prominence * peak.power || peak.power - dip < config_.threshold) {
    return std::nullopt;
  }
  const double level = std::max(config_.trailing_fraction * peak.power, config_.threshold);
  const std::optional<double> t_cross = Crossing(y, top, +1, level, start_time);
  if (!t_cross) return std::nullopt;

  // Steepness of the fall, judged where the echo is strong enough for its shape to show. The
  // allowance adds kFallNoiseSigmas standard deviations of the two crossings' timing noise
  // (receiver noise over the edge's slope), so weak targets are not rejected for noise.
  const double f_hi = kFallHigh;
  const double f_lo = std::max(kFallLow, kFallLowMargin * config_.threshold / peak.power);
  if (f_hi - f_lo >= kMinFallSpan) {
    const std::optional<double> t_hi = Crossing(y, top, +1, f_hi * peak.power, start_time);
    const std::optional<double> t_lo = Crossing(y, top, +1, f_lo * peak.power, start_time);
    if (!t_hi || !t_lo) return std::nullopt;
    const double single = EchoHalfWidth(f_lo) - EchoHalfWidth(f_hi);
    const double jitter_hi = NoiseSigma(f_hi * peak.power) * EchoHalfWidthSlope(f_hi) / peak.power;
    const double jitter_lo = NoiseSigma(f_lo * peak.power) * EchoHalfWidthSlope(f_lo) / peak.power;
    const double allowed = (1.0 + config_.max_fall_stretch) * single +
                           kFallNoiseSigmas * std::hypot(jitter_hi, jitter_lo);
    if (*t_lo - *t_hi > allowed) return std::nullopt;
  }
  return TimeToRange(*t_cross - EchoHalfWidth(level / peak.power));
}

EchoReturn PulseDetector::Measure(const std::vector<double>& y, const Waveform& waveform,
                                  std::size_t begin, std::size_t end) const {
  const double threshold = config_.threshold;
  const double t0 = waveform.start_time;
  const double dt = sample_period_;
  const std::size_t n = y.size();
  EchoReturn echo;
  echo.rise_time = begin == 0 ? t0
                              : t0 + (static_cast<double>(begin) - 1.0) * dt +
                                    dt * (threshold - y[begin - 1]) / (y[begin] - y[begin - 1]);
  echo.fall_time = end + 1 >= n ? t0 + static_cast<double>(end) * dt
                                : t0 + static_cast<double>(end) * dt +
                                      dt * (y[end] - threshold) / (y[end] - y[end + 1]);
  const auto highest = [&](std::size_t from, std::size_t to) {
    std::size_t best = from;
    for (std::size_t k = from; k <= to; ++k) {
      if (y[k] > y[best]) best = k;
    }
    return best;
  };
  const Peak peak = Refine(y, highest(begin, end), t0);
  echo.peak_time = peak.time;
  echo.peak_power = peak.power;

  // The leading edge is timed on the return's first peak: the highest point within the leading
  // span after the rise, the echo itself or the front of a dust cloud.
  const Peak first = Refine(y, highest(begin, std::min(end, begin + leading_span_samples_)), t0);
  double level = std::max(config_.leading_fraction * first.power, threshold);
  double t_lead = echo.rise_time;
  if (const std::optional<double> t = Crossing(y, first.index, -1, level, t0)) {
    t_lead = *t;
  } else {
    level = threshold;
  }
  echo.leading_edge_range = TimeToRange(t_lead + EchoHalfWidth(level / first.power));
  echo.window = echo.leading_edge_range < config_.window_zone_range;

  // A single surface's echo of this height is above the threshold for 2·w(T/A).
  const double single_echo = 2.0 * EchoHalfWidth(threshold / peak.power);
  echo.extended =
      echo.fall_time - echo.rise_time > single_echo + config_.extended_margin_fwhm * echo_fwhm_;

  // Clipped raw samples anywhere under the smoothing kernel's reach.
  const std::size_t half = kernel_.size() / 2;
  const std::size_t raw_begin = begin > half ? begin - half : 0;
  const std::size_t raw_end = std::min(end + half, n - 1);
  for (std::size_t k = raw_begin; k <= raw_end; ++k) {
    if (waveform.power[k] >= waveform.saturation_power) echo.saturated = true;
  }
  return echo;
}

PulseDetection PulseDetector::Detect(const Waveform& waveform) const {
  if (waveform.power.empty()) {
    throw std::invalid_argument("PulseDetector::Detect: empty waveform");
  }
  if (std::abs(waveform.sample_period - sample_period_) > 1e-9 * sample_period_) {
    throw std::invalid_argument(
        "PulseDetector::Detect: waveform sampled every " + std::to_string(waveform.sample_period) +
        " s, the detector was calibrated for " + std::to_string(sample_period_) + " s");
  }
  if (!std::isfinite(waveform.start_time) || !(waveform.saturation_power > 0) ||
      !std::all_of(waveform.power.begin(), waveform.power.end(),
                   [](double p) { return std::isfinite(p); })) {
    throw std::invalid_argument(
        "PulseDetector::Detect: non-finite start time, saturation power or sample");
  }
  const std::vector<double> y = Smooth(waveform.power);
  const std::size_t n = y.size();

  // Returns: stretches above the threshold, bridging gaps of up to min_gap.
  PulseDetection out;
  std::optional<std::pair<std::size_t, std::size_t>> last_target;  // [begin, end] samples
  std::size_t i = 0;
  while (i < n) {
    if (y[i] <= config_.threshold) {
      ++i;
      continue;
    }
    const std::size_t begin = i;
    std::size_t end = i;
    std::size_t j = i + 1;
    while (j < n && (y[j] > config_.threshold || j - end <= gap_samples_)) {
      if (y[j] > config_.threshold) end = j;
      ++j;
    }
    i = j;
    out.returns.push_back(Measure(y, waveform, begin, end));
    if (!out.returns.back().window) last_target = std::make_pair(begin, end);
  }

  for (const EchoReturn& echo : out.returns) {
    if (echo.window) {
      out.window_return = true;
      continue;
    }
    ++out.target_returns;
    out.extended_return = out.extended_return || echo.extended;
  }
  out.multiple_returns = out.target_returns >= 2;
  if (!out.returns.empty()) out.first_pulse_range = out.returns.front().leading_edge_range;
  // The window's echo comes first; a last return in the window zone means nothing else
  // returned.
  if (!out.returns.empty() && !out.returns.back().window) {
    out.last_pulse_range = out.returns.back().leading_edge_range;
    out.trailing_edge_range =
        TrailingEdge(y, last_target->first, last_target->second, waveform.start_time);
    out.trailing_edge_saturated = out.returns.back().saturated;
  }
  return out;
}

}  // namespace autoshovel::sensors
