// The simulated return waveform (excavator seed §3, Figs. 6–7): pulse shape, 1/r², Beer–Lambert
// extinction through dust, the dust echo spread over the cloud, the dirty window, noise.
#include "runtime/sensors/rangefinder/return_waveform.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace autoshovel::sensors {
namespace {

double Energy(const Waveform& wf) {
  double sum = 0;
  for (const double p : wf.power) sum += p;
  return sum * wf.sample_period;
}

std::size_t ArgMax(const Waveform& wf) {
  return static_cast<std::size_t>(std::max_element(wf.power.begin(), wf.power.end()) -
                                  wf.power.begin());
}

RayProfile Target(double range, double reflectivity) {
  RayProfile p;
  p.solid = SolidHit{range, reflectivity, 1.0};
  return p;
}

TEST(PulseShape, WidthsAndAreaMatchTheirDefinitions) {
  for (const PulseShapeKind kind : {PulseShapeKind::kGaussian, PulseShapeKind::kSech2}) {
    const PulseShape pulse(kind, 4e-9);
    EXPECT_DOUBLE_EQ(pulse.Value(0.0), 1.0) << ToString(kind);
    EXPECT_NEAR(pulse.Value(2e-9), 0.5, 1e-12) << ToString(kind);
    EXPECT_NEAR(pulse.Value(-2e-9), 0.5, 1e-12) << ToString(kind);
    EXPECT_NEAR(pulse.HalfWidthAt(0.5), 2e-9, 1e-21) << ToString(kind);
    for (const double f : {0.9, 0.3, 1e-3}) {
      EXPECT_NEAR(pulse.Value(pulse.HalfWidthAt(f)), f, 1e-12) << ToString(kind);
    }
    EXPECT_LT(pulse.Value(pulse.Support()), 1.01e-6);
    // Trapezoidal integral against the closed form.
    double area = 0;
    const double h = 1e-12;
    for (double t = -pulse.Support(); t < pulse.Support(); t += h) area += pulse.Value(t) * h;
    EXPECT_NEAR(area / pulse.Integral(), 1.0, 1e-4) << ToString(kind);
  }
  EXPECT_THROW(PulseShape(PulseShapeKind::kGaussian, 0.0), std::invalid_argument);
  EXPECT_THROW(PulseShape(PulseShapeKind::kGaussian, 1e-9).HalfWidthAt(0.0), std::invalid_argument);
}

TEST(ReturnWaveform, TargetEchoArrivesAtTheRoundTripWithTheLidarEquationsPower) {
  const WaveformSimulator sim{WaveformConfig{}};
  for (const double range : {5.0, 20.0, 47.3}) {
    const Waveform wf = sim.Expected(Target(range, 0.4), CleanWindow());
    const std::size_t peak = ArgMax(wf);
    EXPECT_NEAR(wf.TimeAt(peak), RangeToTime(range), 0.5 * wf.sample_period + 1e-15);
    const double expected = sim.SolidPeakPower(SolidHit{range, 0.4, 1.0}, 0.0, 1.0);
    // P0·ρ/π·A·η/r² by hand.
    EXPECT_NEAR(expected, 20.0 * 0.4 / std::numbers::pi * 2e-3 * 0.7 / (range * range),
                1e-12 * expected);
    // The sampled peak is within the pulse's droop over half a sample of it.
    EXPECT_LE(wf.power[peak], expected * (1 + 1e-9));
    EXPECT_GE(wf.power[peak], expected * 0.99);
    // The energy is the peak times the pulse's integral.
    EXPECT_NEAR(Energy(wf) / (expected * sim.pulse().Integral()), 1.0, 1e-3);
  }
}

TEST(ReturnWaveform, EchoFallsAsInverseSquareAndCosine) {
  const WaveformSimulator sim{WaveformConfig{}};
  const double e10 = Energy(sim.Expected(Target(10, 0.5), CleanWindow()));
  const double e20 = Energy(sim.Expected(Target(20, 0.5), CleanWindow()));
  EXPECT_NEAR(e20 / e10, 0.25, 1e-3);
  RayProfile slanted = Target(10, 0.5);
  slanted.solid->cos_incidence = 0.5;
  EXPECT_NEAR(Energy(sim.Expected(slanted, CleanWindow())) / e10, 0.5, 1e-3);
  // Inside the overlap range the receiver sees less than 1/r² would give.
  const double e1 = Energy(sim.Expected(Target(1, 0.5), CleanWindow()));
  EXPECT_NEAR(e1 / e10, 100.0 / 4.0, 0.1);  // O(1 m) = 1/4 of full overlap
}

TEST(ReturnWaveform, DustAttenuatesTheTargetByBeerLambert) {
  const WaveformSimulator sim{WaveformConfig{}};
  const double clear = Energy(sim.Expected(Target(25, 0.3), CleanWindow()));
  for (const double alpha : {0.1, 0.3, 0.6}) {
    // Dust from 8 to 13 m: its echo has ended long before the target's at 25 m.
    RayProfile p = Target(25, 0.3);
    p.dust.push_back({8, 13, alpha, alpha / 50, 0.0});
    const Waveform wf = sim.Expected(p, CleanWindow());
    double target_energy = 0;
    for (std::size_t n = 0; n < wf.power.size(); ++n) {
      if (TimeToRange(wf.TimeAt(n)) > 20) target_energy += wf.power[n] * wf.sample_period;
    }
    EXPECT_NEAR(target_energy / clear, std::exp(-2 * alpha * 5), 1e-3 * std::exp(-2 * alpha * 5))
        << "alpha " << alpha;
  }
}

TEST(ReturnWaveform, DustEchoIsSpreadOverTheCloudsDepth) {
  const WaveformSimulator sim{WaveformConfig{}};
  const double r0 = 10, r1 = 16, alpha = 0.05, beta = alpha / 50;
  RayProfile p;
  p.dust.push_back({r0, r1, alpha, beta, 0.0});
  const Waveform wf = sim.Expected(p, CleanWindow());
  // Energy: P0·∫s·∫ β·A·η/r²·exp(−2α(r − r0)) dr, the integral by Simpson's rule here.
  const int n = 6000;
  const double h = (r1 - r0) / n;
  double integral = 0;
  for (int i = 0; i <= n; ++i) {
    const double r = r0 + i * h;
    const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    integral += w * beta * 2e-3 * 0.7 / (r * r) * std::exp(-2 * alpha * (r - r0));
  }
  integral *= h / 3;
  EXPECT_NEAR(Energy(wf) / (20.0 * sim.pulse().Integral() * integral), 1.0, 2e-3);
  // The echo covers the cloud: above 5 % of its maximum from the front to the back.
  const double max = *std::max_element(wf.power.begin(), wf.power.end());
  double first = 0, last = 0;
  bool seen = false;
  for (std::size_t i = 0; i < wf.power.size(); ++i) {
    if (wf.power[i] > 0.05 * max) {
      if (!seen) first = TimeToRange(wf.TimeAt(i));
      seen = true;
      last = TimeToRange(wf.TimeAt(i));
    }
  }
  EXPECT_NEAR(first, r0 - 0.3, 0.3);
  EXPECT_NEAR(last, r1 + 0.3, 0.3);
}

TEST(ReturnWaveform, DirtyWindowReturnsAStrongEchoAtItsRange) {
  const WaveformSimulator sim{WaveformConfig{}};
  const Waveform wf = sim.Expected(Target(30, 0.3), DirtyWindow());
  // 1.5e−4 of 20 W = 3 mW, clipped at the 2 mW saturation: a flat top centred on the window.
  std::size_t first = wf.power.size(), last = 0;
  for (std::size_t n = 0; n < wf.power.size(); ++n) {
    if (wf.power[n] >= sim.config().saturation_power) {
      first = std::min(first, n);
      last = n;
    }
  }
  ASSERT_LT(first, wf.power.size());
  EXPECT_NEAR(TimeToRange(0.5 * (wf.TimeAt(first) + wf.TimeAt(last))), 0.05, 0.04);
  // The target is seen through the window at T_w² = 0.64 of its clean power.
  const double clean = Energy(sim.Expected(Target(30, 0.3), CleanWindow()));
  double far = 0;
  for (std::size_t n = 0; n < wf.power.size(); ++n) {
    if (TimeToRange(wf.TimeAt(n)) > 25) far += wf.power[n] * wf.sample_period;
  }
  EXPECT_NEAR(far / clean, 0.64, 1e-3);
}

TEST(ReturnWaveform, NoiseHasTheReceiversStatisticsAndIsReproducible) {
  const WaveformConfig config;
  const WaveformSimulator sim(config);
  Rng rng(42);
  // Empty sky: thermal noise only.
  double sum = 0, sum2 = 0;
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    for (const double p : sim.Simulate(RayProfile{}, CleanWindow(), rng).power) {
      sum += p;
      sum2 += p * p;
      ++count;
    }
  }
  const double mean = sum / count;
  EXPECT_NEAR(mean, 0.0, 4 * config.noise_sigma / std::sqrt(count));
  EXPECT_NEAR(std::sqrt(sum2 / count - mean * mean) / config.noise_sigma, 1.0, 0.05);
  // At an echo's peak the shot noise adds k_s·P to the variance.
  const RayProfile target = Target(8, 0.5);
  const Waveform ideal = sim.Expected(target, CleanWindow());
  const std::size_t peak = ArgMax(ideal);
  double s = 0, s2 = 0;
  const int trials = 600;
  for (int k = 0; k < trials; ++k) {
    const double d = sim.Simulate(target, CleanWindow(), rng).power[peak] - ideal.power[peak];
    s += d;
    s2 += d * d;
  }
  const double var = s2 / trials - (s / trials) * (s / trials);
  const double expected =
      config.noise_sigma * config.noise_sigma + config.shot_noise_power * ideal.power[peak];
  EXPECT_NEAR(var / expected, 1.0, 0.15);
  // Same seed, same waveform; another seed, another.
  Rng a(7), b(7), c(8);
  RayProfile dusty = Target(20, 0.3);
  dusty.dust.push_back({12, 20, 0.2, 0.004, 0.5});
  const Waveform wa = sim.Simulate(dusty, DirtyWindow(), a);
  EXPECT_EQ(wa.power, sim.Simulate(dusty, DirtyWindow(), b).power);
  EXPECT_NE(wa.power, sim.Simulate(dusty, DirtyWindow(), c).power);
}

TEST(ReturnWaveform, BadParametersAreRefused) {
  auto with = [](auto change) {
    WaveformConfig config;
    change(config);
    return config;
  };
  EXPECT_THROW(WaveformSimulator(with([](WaveformConfig& c) { c.peak_power = -1; })),
               std::invalid_argument);
  EXPECT_THROW(WaveformSimulator(with([](WaveformConfig& c) { c.sample_period = 3e-9; })),
               std::invalid_argument);
  EXPECT_THROW(WaveformSimulator(with([](WaveformConfig& c) { c.noise_sigma = std::nan(""); })),
               std::invalid_argument);
  EXPECT_THROW(WaveformSimulator(with([](WaveformConfig& c) { c.optical_efficiency = 1.5; })),
               std::invalid_argument);
  const WaveformSimulator sim{WaveformConfig{}};
  EXPECT_THROW(sim.Expected(RayProfile{}, ExitWindow{0.05, 0.1, 0.0}), std::invalid_argument);
  EXPECT_THROW(sim.Expected(Target(-3, 0.2), CleanWindow()), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::sensors
