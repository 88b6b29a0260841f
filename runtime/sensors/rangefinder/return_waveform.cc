#include "runtime/sensors/rangefinder/return_waveform.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

namespace autoshovel::sensors {
namespace {

// Dust is integrated in slices of at most this depth [m]: a tenth of the default pulse's σ in
// range (0.25 m), so the sum is the integral to well under a percent.
constexpr double kMaxDustSlice = 0.025;
// Table resolution: samples of s(t) per waveform sample.
constexpr int kTableOversampling = 64;
// Beyond this two-way optical depth nothing further along the ray is visible (e^−50 ≈ 2e−22).
constexpr double kOpaqueDepth = 50.0;

void RequirePositive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0) {
    throw std::invalid_argument(std::string("WaveformConfig: ") + name +
                                " must be finite and positive, got " + std::to_string(value));
  }
}

void RequireNonNegative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0) {
    throw std::invalid_argument(std::string("WaveformConfig: ") + name +
                                " must be finite and ≥ 0, got " + std::to_string(value));
  }
}

}  // namespace

void ValidateExitWindow(const ExitWindow& window) {
  if (!std::isfinite(window.range) || window.range < 0) {
    throw std::invalid_argument("ExitWindow: range must be finite and ≥ 0, got " +
                                std::to_string(window.range));
  }
  if (!std::isfinite(window.backscatter) || window.backscatter < 0 || window.backscatter > 1) {
    throw std::invalid_argument("ExitWindow: backscatter must be in [0, 1], got " +
                                std::to_string(window.backscatter));
  }
  if (!std::isfinite(window.transmittance) || window.transmittance <= 0 ||
      window.transmittance > 1) {
    throw std::invalid_argument("ExitWindow: transmittance must be in (0, 1], got " +
                                std::to_string(window.transmittance));
  }
}

ExitWindow CleanWindow() { return ExitWindow{}; }

ExitWindow DirtyWindow() { return ExitWindow{0.05, 1.5e-4, 0.8}; }

WaveformSimulator::WaveformSimulator(const WaveformConfig& config)
    : config_(config), pulse_(config.pulse_shape, config.pulse_fwhm) {
  RequirePositive(config.peak_power, "peak_power");
  RequirePositive(config.aperture_area, "aperture_area");
  RequirePositive(config.optical_efficiency, "optical_efficiency");
  RequirePositive(config.overlap_range, "overlap_range");
  RequirePositive(config.sample_period, "sample_period");
  RequirePositive(config.max_range, "max_range");
  RequirePositive(config.saturation_power, "saturation_power");
  RequireNonNegative(config.noise_sigma, "noise_sigma");
  RequireNonNegative(config.shot_noise_power, "shot_noise_power");
  if (config.optical_efficiency > 1) {
    throw std::invalid_argument("WaveformConfig: optical_efficiency must be ≤ 1, got " +
                                std::to_string(config.optical_efficiency));
  }
  if (config.sample_period > 0.5 * config.pulse_fwhm) {
    throw std::invalid_argument(
        "WaveformConfig: sample_period must be at most half the pulse FWHM (two samples per "
        "pulse width), got " +
        std::to_string(config.sample_period) + " s for a " + std::to_string(config.pulse_fwhm) +
        " s pulse");
  }
  support_ = pulse_.Support();
  table_step_ = config.sample_period / kTableOversampling;
  const auto table_size = static_cast<std::size_t>(std::ceil(2.0 * support_ / table_step_)) + 2;
  table_.resize(table_size);
  for (std::size_t i = 0; i < table_size; ++i) {
    table_[i] = pulse_.Value(-support_ + static_cast<double>(i) * table_step_);
  }
  // Start a few ns before the window's echo can begin, end when max_range's echo has ended.
  start_time_ = -(support_ + 4e-9);
  const double end_time = RangeToTime(config.max_range) + support_;
  num_samples_ =
      static_cast<std::size_t>(std::floor((end_time - start_time_) / config.sample_period)) + 1;
}

double WaveformSimulator::GeometricFactor(double range) const {
  const double r_o = config_.overlap_range;
  // O(r)/r² = (r/r_o)²/r² = 1/r_o² inside the overlap range.
  const double inverse_r2 = range < r_o ? 1.0 / (r_o * r_o) : 1.0 / (range * range);
  return config_.aperture_area * config_.optical_efficiency * inverse_r2;
}

double WaveformSimulator::SolidPeakPower(const SolidHit& hit, double optical_depth,
                                         double transmittance) const {
  return config_.peak_power * transmittance * transmittance * hit.reflectivity * hit.cos_incidence /
         std::numbers::pi * GeometricFactor(hit.range) * std::exp(-2.0 * optical_depth);
}

double WaveformSimulator::PulseTable(double t) const {
  const double u = (t + support_) / table_step_;
  if (u <= 0) return 0.0;
  const auto i = static_cast<std::size_t>(u);
  if (i + 1 >= table_.size()) return 0.0;
  const double f = u - static_cast<double>(i);
  return table_[i] + f * (table_[i + 1] - table_[i]);
}

void WaveformSimulator::AddPulse(std::vector<double>& power, double center_time,
                                 double amplitude) const {
  const double dt = config_.sample_period;
  const double lo = std::ceil((center_time - support_ - start_time_) / dt);
  const double hi = std::floor((center_time + support_ - start_time_) / dt);
  if (hi < 0 || lo >= static_cast<double>(power.size())) return;
  const auto n0 = static_cast<std::size_t>(std::max(lo, 0.0));
  const auto n1 = std::min(static_cast<std::size_t>(hi), power.size() - 1);
  for (std::size_t n = n0; n <= n1; ++n) {
    power[n] += amplitude * PulseTable(start_time_ + static_cast<double>(n) * dt - center_time);
  }
}

Waveform WaveformSimulator::Expected(const RayProfile& profile, const ExitWindow& window) const {
  return Build(profile, window, nullptr);
}

Waveform WaveformSimulator::Simulate(const RayProfile& profile, const ExitWindow& window,
                                     Rng& rng) const {
  return Build(profile, window, &rng);
}

Waveform WaveformSimulator::Build(const RayProfile& profile, const ExitWindow& window,
                                  Rng* rng) const {
  ValidateRayProfile(profile);
  ValidateExitWindow(window);
  Waveform wf;
  wf.start_time = start_time_;
  wf.sample_period = config_.sample_period;
  wf.saturation_power = config_.saturation_power;
  wf.power.assign(num_samples_, 0.0);

  const double p0 = config_.peak_power;
  const double t_w2 = window.transmittance * window.transmittance;
  if (window.backscatter > 0) {
    AddPulse(wf.power, RangeToTime(window.range), p0 * window.backscatter);
  }

  // Everything beyond the first solid surface (or the end of the record) is invisible.
  const double record_end = config_.max_range + TimeToRange(support_);
  const double end = profile.solid ? std::min(profile.solid->range, record_end) : record_end;

  // Dust: march through the intervals between segment boundaries, where α and β are constant.
  std::vector<double> bounds;
  for (const DustSegment& d : profile.dust) {
    if (d.range_begin >= end) continue;
    bounds.push_back(d.range_begin);
    bounds.push_back(std::min(d.range_end, end));
  }
  std::sort(bounds.begin(), bounds.end());
  bounds.erase(std::unique(bounds.begin(), bounds.end()), bounds.end());
  double depth = 0;  // one-way optical depth τ at the current interval's start
  for (std::size_t i = 0; i + 1 < bounds.size() && 2.0 * depth < kOpaqueDepth; ++i) {
    const double r0 = bounds[i], r1 = bounds[i + 1];
    const double mid = 0.5 * (r0 + r1);
    double alpha = 0;
    std::vector<const DustSegment*> covering;
    for (const DustSegment& d : profile.dust) {
      if (d.range_begin <= mid && mid < d.range_end) {
        alpha += d.extinction;
        covering.push_back(&d);
      }
    }
    if (covering.empty()) continue;
    const double length = r1 - r0;
    const auto slices = static_cast<int>(std::ceil(length / kMaxDustSlice));
    const double dr = length / slices;
    for (int j = 0; j < slices; ++j) {
      const double offset = (j + 0.5) * dr;
      const double r = r0 + offset;
      double beta = 0;
      for (const DustSegment* d : covering) {
        double factor = 1.0;
        if (rng != nullptr && d->granularity > 0) {
          // Gamma with shape 1/g² and scale g²: mean 1, relative σ = g.
          const double g2 = d->granularity * d->granularity;
          std::gamma_distribution<double> lumps(1.0 / g2, g2);
          factor = lumps(*rng);
        }
        beta += d->backscatter * factor;
      }
      const double amplitude =
          p0 * t_w2 * beta * dr * GeometricFactor(r) * std::exp(-2.0 * (depth + alpha * offset));
      AddPulse(wf.power, RangeToTime(r), amplitude);
    }
    depth += alpha * length;
  }

  if (profile.solid && profile.solid->range <= record_end && 2.0 * depth < kOpaqueDepth) {
    AddPulse(wf.power, RangeToTime(profile.solid->range),
             SolidPeakPower(*profile.solid, depth, window.transmittance));
  }

  if (rng != nullptr && (config_.noise_sigma > 0 || config_.shot_noise_power > 0)) {
    std::normal_distribution<double> normal(0.0, 1.0);
    const double var0 = config_.noise_sigma * config_.noise_sigma;
    for (double& p : wf.power) {
      p += std::sqrt(var0 + config_.shot_noise_power * std::max(p, 0.0)) * normal(*rng);
    }
  }
  for (double& p : wf.power) p = std::min(p, config_.saturation_power);
  return wf;
}

}  // namespace autoshovel::sensors
