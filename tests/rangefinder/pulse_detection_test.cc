// First-pulse, last-pulse and trailing-edge detection (excavator seed §3, Figs. 6–8) on
// simulated waveforms: clear air, a dirty exit window, dust in front of the target, the target
// inside the dust, dust too thick to see through. The statistical tests print their figures
// (docs/rangefinder.md quotes them):
//   ./build-rangefinder/rangefinder_tests --gtest_filter='PulseDetectionTest.*'
#include "runtime/sensors/rangefinder/pulse_detection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace autoshovel::sensors {
namespace {

// Range of one waveform sample: 7.5 cm at 2 GS/s.
double SampleRange(const WaveformConfig& config) { return TimeToRange(config.sample_period); }

double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

class PulseDetectionTest : public ::testing::Test {
 protected:
  WaveformConfig config_;
  WaveformSimulator sim_{config_};
  PulseDetector detector_{config_, MakeDetectorConfig(config_)};
  Rng rng_{2024};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};

  double Uniform(double lo, double hi) { return lo + (hi - lo) * uniform_(rng_); }
  PulseDetection Fire(const RayProfile& p, const ExitWindow& w = CleanWindow()) {
    return detector_.Detect(sim_.Simulate(p, w, rng_));
  }
};

RayProfile Target(double range, double reflectivity, double cos_incidence = 1.0) {
  RayProfile p;
  p.solid = SolidHit{range, reflectivity, cos_incidence};
  return p;
}

TEST_F(PulseDetectionTest, ClearAirTargetIsRangedWellInsideASample) {
  std::vector<double> last_errors, trailing_errors, strong_trailing_errors;
  const int trials = 300;
  for (int i = 0; i < trials; ++i) {
    const double range = Uniform(3, 78), rho = Uniform(0.1, 0.9), cos_i = Uniform(0.5, 1.0);
    const RayProfile p = Target(range, rho, cos_i);
    const PulseDetection d = Fire(p);
    ASSERT_TRUE(d.first_pulse_range && d.last_pulse_range && d.trailing_edge_range)
        << "range " << range << " rho " << rho;
    EXPECT_EQ(d.target_returns, 1);
    EXPECT_FALSE(d.window_return);
    EXPECT_FALSE(d.DustEvidence()) << "range " << range;
    EXPECT_DOUBLE_EQ(*d.first_pulse_range, *d.last_pulse_range);
    last_errors.push_back(std::abs(*d.last_pulse_range - range));
    trailing_errors.push_back(std::abs(*d.trailing_edge_range - range));
    const double snr = sim_.SolidPeakPower(*p.solid, 0, 1) / detector_.NoiseSigma(0);
    if (snr > 1000) strong_trailing_errors.push_back(trailing_errors.back());
  }
  const double sample = SampleRange(config_);
  std::printf(
      "[clear air, %d targets 3-78 m, rho 0.1-0.9] last pulse |err| median %.4f m, 95 %% %.4f m, "
      "max %.4f m; trailing edge median %.4f m, max %.4f m, max at SNR>1000 %.4f m (sample = "
      "%.4f m)\n",
      trials, Quantile(last_errors, 0.5), Quantile(last_errors, 0.95), Quantile(last_errors, 1.0),
      Quantile(trailing_errors, 0.5), Quantile(trailing_errors, 1.0),
      Quantile(strong_trailing_errors, 1.0), sample);
  // Against the sample period. The last pulse, a leading-edge discriminator at the fixed
  // threshold, is limited by the noise where the echo's slow foot crosses the threshold,
  // whatever the echo's strength (the error is skewed early: a noise bump on the foot fires
  // it): median within a quarter sample, 95 % within 0.6, all within 1.5. The trailing edge,
  // timed at half its peak: all within half a sample, the median within a twentieth, echoes
  // with a peak SNR over 1000 within a tenth.
  EXPECT_LT(Quantile(last_errors, 0.5), 0.25 * sample);
  EXPECT_LT(Quantile(last_errors, 0.95), 0.6 * sample);
  EXPECT_LT(Quantile(last_errors, 1.0), 1.5 * sample);
  EXPECT_LT(Quantile(trailing_errors, 1.0), 0.5 * sample);
  EXPECT_LT(Quantile(trailing_errors, 0.5), 0.05 * sample);
  EXPECT_LT(Quantile(strong_trailing_errors, 1.0), 0.1 * sample);
}

TEST_F(PulseDetectionTest, Sech2PulseIsRangedAsWell) {
  WaveformConfig config;
  config.pulse_shape = PulseShapeKind::kSech2;
  const WaveformSimulator sim(config);
  const PulseDetector detector(config, MakeDetectorConfig(config));
  std::vector<double> last_errors, trailing_errors;
  for (int i = 0; i < 200; ++i) {
    const double range = Uniform(3, 60);
    const PulseDetection d = detector.Detect(sim.Simulate(Target(range, 0.3), CleanWindow(), rng_));
    ASSERT_TRUE(d.last_pulse_range && d.trailing_edge_range);
    last_errors.push_back(std::abs(*d.last_pulse_range - range));
    trailing_errors.push_back(std::abs(*d.trailing_edge_range - range));
  }
  std::printf(
      "[sech2 pulse, 200 targets 3-60 m, rho 0.3] last pulse |err| median %.4f m, 95 %% %.4f m, "
      "max %.4f m; trailing edge median %.4f m, max %.4f m\n",
      Quantile(last_errors, 0.5), Quantile(last_errors, 0.95), Quantile(last_errors, 1.0),
      Quantile(trailing_errors, 0.5), Quantile(trailing_errors, 1.0));
  // The sech²'s exponential foot rises more slowly than a Gaussian's, so the threshold
  // crossing of the last pulse is noisier; the trailing edge, timed at half height, is not.
  const double sample = SampleRange(config);
  EXPECT_LT(Quantile(last_errors, 0.5), 0.4 * sample);
  EXPECT_LT(Quantile(last_errors, 1.0), 2.5 * sample);
  EXPECT_LT(Quantile(trailing_errors, 1.0), 0.3 * sample);
}

// §3, Fig. 6: a first-pulse unit sees the dirty window; the last pulse sees the target.
TEST_F(PulseDetectionTest, LastPulseRejectsTheDirtyWindowsReturn) {
  for (int i = 0; i < 100; ++i) {
    // Beyond the ~1.5 m the window's saturated echo blinds.
    const double range = Uniform(3, 70);
    const PulseDetection d = Fire(Target(range, Uniform(0.1, 0.9)), DirtyWindow());
    ASSERT_TRUE(d.first_pulse_range && d.last_pulse_range && d.trailing_edge_range);
    EXPECT_TRUE(d.window_return);
    EXPECT_NEAR(*d.first_pulse_range, 0.0, 0.3) << "the first pulse is the window";
    EXPECT_TRUE(d.returns.front().saturated);
    EXPECT_NEAR(*d.last_pulse_range, range, 0.12);
    EXPECT_NEAR(*d.trailing_edge_range, range, 0.03);
    EXPECT_EQ(d.target_returns, 1);
    EXPECT_FALSE(d.DustEvidence()) << "the window is not dust";
  }
  // Nothing but the window: the last pulse reports nothing rather than 0 m.
  const PulseDetection sky = Fire(RayProfile{}, DirtyWindow());
  ASSERT_TRUE(sky.first_pulse_range);
  EXPECT_NEAR(*sky.first_pulse_range, 0.0, 0.3);
  EXPECT_FALSE(sky.last_pulse_range);
  EXPECT_FALSE(sky.trailing_edge_range);
  EXPECT_EQ(sky.target_returns, 0);
}

// §3, Fig. 6: a dust cloud between scanner and target. The first pulse reports the cloud, the
// last pulse the target, and the two returns are a dust warning.
TEST_F(PulseDetectionTest, DustCloudInFrontOfTheTargetIsRejectedByLastPulse) {
  int separated = 0;
  const int trials = 100;
  for (int i = 0; i < trials; ++i) {
    const double front = Uniform(5, 15), depth = Uniform(2, 5), gap = Uniform(2, 10);
    const double range = front + depth + gap, alpha = Uniform(0.05, 0.3);
    RayProfile p = Target(range, Uniform(0.1, 0.6));
    p.dust.push_back({front, front + depth, alpha, alpha / 50, 0.5});
    const PulseDetection d = Fire(p, i % 2 ? DirtyWindow() : CleanWindow());
    ASSERT_TRUE(d.last_pulse_range && d.trailing_edge_range);
    EXPECT_NEAR(*d.last_pulse_range, range, 0.12);
    EXPECT_NEAR(*d.trailing_edge_range, range, 0.03);
    EXPECT_TRUE(d.DustEvidence());
    if (d.multiple_returns) ++separated;
    // The first return beyond the window is the cloud's front.
    const auto cloud = std::find_if(d.returns.begin(), d.returns.end(),
                                    [](const EchoReturn& e) { return !e.window; });
    ASSERT_NE(cloud, d.returns.end());
    EXPECT_NEAR(cloud->leading_edge_range, front, 0.6);
    if (i % 2 == 0) {
      EXPECT_NEAR(*d.first_pulse_range, front, 0.6);
    }
  }
  EXPECT_EQ(separated, trials);
}

// §3, Figs. 7–8: the target inside the cloud. Dust and target merge into one return: the last
// pulse reports the cloud's front; the trailing edge finds the target.
TEST_F(PulseDetectionTest, TrailingEdgeFindsTheTargetInsideTheDustCloud) {
  const int trials = 200;
  int trailing_within_10cm = 0, trailing_reported = 0, last_at_cloud = 0, last_off_target = 0;
  std::vector<double> trailing_errors, last_minus_front;
  for (int i = 0; i < trials; ++i) {
    // A truck side (ρ 0.15–0.5) 8–30 m away shrouded in a heavy cloud (α 0.15–0.5 /m,
    // visibility 8–26 m) that reaches 1.5–3.5 m in front of it: one-way optical depth 0.2–1.75,
    // the target's echo 3–67 % of its clear-air power. Lumpy dust, receiver noise, a clean
    // window.
    const double range = Uniform(8, 30), rho = Uniform(0.15, 0.5);
    const double depth = Uniform(1.5, 3.5), alpha = Uniform(0.15, 0.5);
    const double front = range - depth;
    RayProfile p = Target(range, rho);
    p.dust.push_back({front, range, alpha, alpha / 50, 0.5});
    const PulseDetection d = Fire(p);
    ASSERT_TRUE(d.last_pulse_range);
    EXPECT_EQ(d.target_returns, 1) << "dust and target merge";
    EXPECT_TRUE(d.extended_return);
    last_minus_front.push_back(*d.last_pulse_range - front);
    if (std::abs(*d.last_pulse_range - front) < 0.75) ++last_at_cloud;
    if (std::abs(*d.last_pulse_range - range) > 1.0) ++last_off_target;
    if (d.trailing_edge_range) {
      ++trailing_reported;
      trailing_errors.push_back(*d.trailing_edge_range - range);
      if (std::abs(trailing_errors.back()) < 0.10) ++trailing_within_10cm;
    }
  }
  std::printf(
      "[target inside dust, %d trials] trailing edge: reported %d, within 10 cm %d (%.1f %%), "
      "error min %.3f median %.3f max %.3f m; last pulse: within 0.75 m of the cloud front %d, "
      "more than 1 m off the target %d, (last - front) median %.2f max %.2f m\n",
      trials, trailing_reported, trailing_within_10cm, 100.0 * trailing_within_10cm / trials,
      Quantile(trailing_errors, 0.0), Quantile(trailing_errors, 0.5),
      Quantile(trailing_errors, 1.0), last_at_cloud, last_off_target,
      Quantile(last_minus_front, 0.5), Quantile(last_minus_front, 1.0));
  EXPECT_GE(trailing_within_10cm, trials * 95 / 100);
  std::vector<double> abs_errors;
  for (const double e : trailing_errors) abs_errors.push_back(std::abs(e));
  EXPECT_LT(Quantile(abs_errors, 0.95), 0.05);
  EXPECT_GE(last_at_cloud, trials * 90 / 100);
  EXPECT_GE(last_off_target, trials * 95 / 100);
}

// A harder population: darker targets (ρ 0.05–0.6), 1–6 m of dust of one-way optical depth up
// to 1.5 in front of them, grazing incidence down to cos 0.5, out to 40 m. Where the trailing
// edge cannot tell the target from the dust it reports nothing; what it reports is right.
TEST_F(PulseDetectionTest, TrailingEdgeInHeavierDustMissesRatherThanLies) {
  const int trials = 400;
  int reported = 0, within_10cm = 0;
  for (int i = 0; i < trials; ++i) {
    const double range = Uniform(7, 40), rho = Uniform(0.05, 0.6), cos_i = Uniform(0.5, 1.0);
    const double depth = Uniform(1, 6), tau = Uniform(0.2, 1.5);
    RayProfile p = Target(range, rho, cos_i);
    p.dust.push_back({range - depth, range, tau / depth, tau / depth / 50, 0.5});
    const PulseDetection d = Fire(p);
    if (!d.trailing_edge_range) continue;
    ++reported;
    if (std::abs(*d.trailing_edge_range - range) < 0.10) ++within_10cm;
  }
  std::printf(
      "[target in heavier dust, %d trials] trailing edge reported %d (%.1f %%), within "
      "10 cm %d (%.1f %% of reported)\n",
      trials, reported, 100.0 * reported / trials, within_10cm, 100.0 * within_10cm / reported);
  EXPECT_GE(reported, trials * 90 / 100);
  EXPECT_GE(within_10cm, reported * 99 / 100);
}

// §3: "both dust penetrating techniques are physically limited by very heavy dust levels". The
// target's echo is extinguished below the noise; the trailing edge must not call the dust a
// target. Heavy dust (visibility 2–5 m) and light dust with nothing behind it.
TEST_F(PulseDetectionTest, NoTargetIsInventedWhereDustHidesIt) {
  const int trials = 200;
  int heavy_false = 0, light_false = 0;
  for (int i = 0; i < trials; ++i) {
    const double range = Uniform(15, 35), rho = Uniform(0.15, 1.0);
    const double alpha = Uniform(0.8, 2.0), tau = Uniform(6, 9);
    RayProfile p = Target(range, rho);
    p.dust.push_back({range - tau / alpha, range, alpha, alpha / 50, 0.5});
    // The premise: the target's own echo is below the noise floor.
    ASSERT_LT(sim_.SolidPeakPower(*p.solid, tau, 1.0), detector_.NoiseSigma(0));
    const PulseDetection d = Fire(p);
    if (d.trailing_edge_range) {
      ++heavy_false;
      ADD_FAILURE() << "heavy dust α " << alpha << ": trailing edge " << *d.trailing_edge_range
                    << " m, target at " << range << " m";
    }
    // Light dust, open sky behind it: the echo is the cloud only.
    const double a2 = Uniform(0.1, 0.5), front = Uniform(4, 25);
    RayProfile sky;
    sky.dust.push_back({front, front + Uniform(2, 10), a2, a2 / 50, 0.5});
    const PulseDetection s = Fire(sky);
    if (s.trailing_edge_range) {
      ++light_false;
      ADD_FAILURE() << "light dust α " << a2 << ": trailing edge " << *s.trailing_edge_range;
    }
    EXPECT_TRUE(s.target_returns == 0 || s.DustEvidence());
  }
  std::printf(
      "[dust hides the target, %d trials each] false trailing-edge targets: heavy dust %d, "
      "light dust over open sky %d\n",
      trials, heavy_false, light_false);
}

// Where the method's limits lie: the share of heavy-dust pulses (target extinguished) in which
// the trailing edge mistakes the cloud front for a surface, against the extinction. A dust
// front with a visibility under a metre is as sharp as a surface at this pulse width.
TEST_F(PulseDetectionTest, DenseDustFrontLimit) {
  std::printf(
      "[dense dust front, target extinguished, 200 pulses each] alpha (1/m): "
      "trailing edge reports the front\n");
  std::vector<double> rates;
  for (const double alpha : {1.0, 2.0, 3.0, 5.0, 10.0}) {
    int reported = 0;
    for (int i = 0; i < 200; ++i) {
      RayProfile p = Target(20, 0.5);
      p.dust.push_back({20 - 8 / alpha, 20, alpha, alpha / 50, 0.5});
      if (Fire(p).trailing_edge_range) ++reported;
    }
    rates.push_back(reported / 200.0);
    std::printf("  alpha %5.1f: %5.1f %%\n", alpha, 100.0 * rates.back());
  }
  EXPECT_EQ(rates[0], 0.0);
  EXPECT_EQ(rates[1], 0.0);
  EXPECT_GT(rates[4], 0.5) << "a dust wall is a surface to any pulse of this width";
}

// The threshold sits where MakeDetectorConfig says it does: at k σ of the smoothed noise,
// noise alone crosses it upwards at Rice's rate, (1/2π)·sqrt(−ρ″(0))·exp(−k²/2) per unit time,
// ρ the smoothed noise's autocorrelation (Gaussian of σ √2·smoothing_sigma). Checked at 3.5 σ,
// where crossings are frequent enough to count; at the default 6 σ the same formula gives one
// false return in 10⁶ pulses.
TEST_F(PulseDetectionTest, NoiseCrossesTheThresholdAtRicesRate) {
  const double k = 3.5;
  const PulseDetector detector(config_, MakeDetectorConfig(config_, k));
  const int pulses = 5000;
  long crossings = 0;
  for (int i = 0; i < pulses; ++i) {
    crossings += static_cast<long>(
        detector.Detect(sim_.Simulate(RayProfile{}, CleanWindow(), rng_)).returns.size());
  }
  const double record = static_cast<double>(sim_.num_samples()) * config_.sample_period;
  const double rate = 1.0 / (2 * std::numbers::pi) /
                      (std::numbers::sqrt2 * detector.config().smoothing_sigma) *
                      std::exp(-0.5 * k * k);
  const double expected = rate * record * pulses;
  std::printf("[noise only, %d pulses, threshold %.1f sigma] %ld returns, Rice predicts %.0f\n",
              pulses, k, crossings, expected);
  EXPECT_NEAR(static_cast<double>(crossings) / expected, 1.0, 0.15);
}

TEST_F(PulseDetectionTest, BadInputIsRefused) {
  DetectorConfig config = MakeDetectorConfig(config_);
  config.threshold = 0;
  EXPECT_THROW(PulseDetector(config_, config), std::invalid_argument);
  config = MakeDetectorConfig(config_);
  config.trailing_fraction = 1.0;
  EXPECT_THROW(PulseDetector(config_, config), std::invalid_argument);
  config = MakeDetectorConfig(config_);
  config.prominence = std::nan("");
  EXPECT_THROW(PulseDetector(config_, config), std::invalid_argument);
  WaveformConfig noiseless;
  noiseless.noise_sigma = 0;
  EXPECT_THROW(MakeDetectorConfig(noiseless), std::invalid_argument);
  EXPECT_THROW(MakeDetectorConfig(config_, -1.0), std::invalid_argument);

  Waveform wf = sim_.Expected(Target(10, 0.5), CleanWindow());
  wf.power[100] = std::nan("");
  EXPECT_THROW(detector_.Detect(wf), std::invalid_argument);
  wf = sim_.Expected(Target(10, 0.5), CleanWindow());
  wf.sample_period *= 2;
  EXPECT_THROW(detector_.Detect(wf), std::invalid_argument);
  EXPECT_THROW(detector_.Detect(Waveform{}), std::invalid_argument);
  EXPECT_THROW(detector_.EchoHalfWidth(0.0), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::sensors
