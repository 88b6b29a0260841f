// The dust warning (excavator seed §3): multiple returns raise it, the machine slows, and it
// clears with hysteresis when the dust is gone. The scan test prints its figures:
//   ./build-rangefinder/rangefinder_tests --gtest_filter='DustMonitor.*'
#include "runtime/sensors/rangefinder/dust_monitor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "runtime/sensors/rangefinder/scanning_rangefinder.h"

namespace autoshovel::sensors {
namespace {

// Pulses at one scanner's fired rate: 175 of the 600 pulses of each 20 rev/s circle fall in
// the active arc, 3500 a second, 350 in the monitor's 0.1 s window.
constexpr double kPulsePeriod = 1.0 / 3500.0;

// Feeds `pulses` pulses that all return, every `period`-th one dusty (period 0: none).
void Feed(DustMonitor& monitor, double& t, int pulses, int period) {
  for (int i = 0; i < pulses; ++i, t += kPulsePeriod) {
    monitor.Add(t, true, period > 0 && i % period == 0);
  }
}

TEST(DustMonitor, WarningRisesAndClearsWithHysteresis) {
  DustMonitor monitor;  // 0.1 s window, on at 10 %, off at 3 %
  double t = 0;
  Feed(monitor, t, 700, 0);
  EXPECT_FALSE(monitor.warning());
  EXPECT_DOUBLE_EQ(monitor.speed_scale(), 1.0);
  EXPECT_NEAR(monitor.returning_pulses(), 350, 1);
  // 6 % dust: between the thresholds, no warning from clear air.
  Feed(monitor, t, 700, 17);
  EXPECT_NEAR(monitor.dust_fraction(), 1.0 / 17, 0.004);
  EXPECT_FALSE(monitor.warning());
  EXPECT_DOUBLE_EQ(monitor.speed_scale(), 1.0);
  // 25 % dust: the warning comes on as the window's fraction passes 10 %, and the machine
  // slows to 1 − f.
  int pulses_to_warning = 0;
  while (!monitor.warning() && pulses_to_warning < 700) {
    monitor.Add(t, true, pulses_to_warning % 4 == 0);
    t += kPulsePeriod;
    ++pulses_to_warning;
  }
  EXPECT_TRUE(monitor.warning());
  EXPECT_GE(monitor.dust_fraction(), 0.10);
  EXPECT_LT(monitor.dust_fraction(), 0.11);
  // From 5.9 % to 10 % with 19 % more dust per pulse replaced: (0.10 − 0.059)·350/0.19 ≈ 75
  // pulses, 21 ms.
  EXPECT_NEAR(pulses_to_warning, 75, 10);
  Feed(monitor, t, 700, 4);
  EXPECT_NEAR(monitor.dust_fraction(), 0.25, 0.004);
  EXPECT_NEAR(monitor.speed_scale(), 0.75, 0.004);
  // Back to 6 %: still warned (above the 3 % off level), speed 1 − 0.06.
  Feed(monitor, t, 700, 17);
  EXPECT_TRUE(monitor.warning());
  EXPECT_NEAR(monitor.speed_scale(), 1 - 1.0 / 17, 0.004);
  // 2 %: clears.
  Feed(monitor, t, 700, 50);
  EXPECT_FALSE(monitor.warning());
  EXPECT_DOUBLE_EQ(monitor.speed_scale(), 1.0);
  // Back to 6 %: stays clear (below the 10 % on level).
  Feed(monitor, t, 700, 17);
  EXPECT_FALSE(monitor.warning());
  // Dense dust everywhere: the speed floor.
  Feed(monitor, t, 700, 1);
  EXPECT_TRUE(monitor.warning());
  EXPECT_DOUBLE_EQ(monitor.speed_scale(), 0.3);
  monitor.Reset();
  EXPECT_FALSE(monitor.warning());
  EXPECT_EQ(monitor.returning_pulses(), 0);
  // Time runs forward only.
  monitor.Add(1.0, true, false);
  EXPECT_THROW(monitor.Add(0.5, true, false), std::invalid_argument);
  EXPECT_THROW(monitor.Add(std::nan(""), true, false), std::invalid_argument);
}

TEST(DustMonitor, OpenSkySaysNothingAboutDust) {
  DustMonitor monitor;
  double t = 0;
  Feed(monitor, t, 700, 2);
  ASSERT_TRUE(monitor.warning());
  // Pulses with no return beyond the window: the last returning ones are too few to decide,
  // so the warning holds.
  for (int i = 0; i < 320; ++i, t += kPulsePeriod) monitor.Add(t, false, false);
  EXPECT_TRUE(monitor.warning());
  EXPECT_NEAR(monitor.returning_pulses(), 30, 1);
}

TEST(DustMonitor, BadConfigurationsAreRefused) {
  EXPECT_THROW(DustMonitor(DustMonitorConfig{0.0, 1, 0.1, 0.03, 0.3}), std::invalid_argument);
  EXPECT_THROW(DustMonitor(DustMonitorConfig{0.1, 0, 0.1, 0.03, 0.3}), std::invalid_argument);
  EXPECT_THROW(DustMonitor(DustMonitorConfig{0.1, 100, 0.1, 0.1, 0.3}), std::invalid_argument);
  EXPECT_THROW(DustMonitor(DustMonitorConfig{0.1, 100, 0.1, 0.03, 0.0}), std::invalid_argument);
}

// The left scanner looks at a truck beside the machine while a dust cloud drifts through its
// view, the full chain at 12 kHz: scan geometry, scene, waveforms, detection, dust monitor.
TEST(DustMonitor, ScanThroughADustCloudSlowsTheMachineUntilItClears) {
  const WaveformConfig waveform;
  ScanningRangefinder scanner(LeftScannerConfig(), waveform, MakeDetectorConfig(waveform),
                              DirtyWindow());
  const PanSweep pan = HoldPan(90.0 * kDegree);  // towards the truck on the left
  const Eigen::Isometry3d T_scene_cab = Eigen::Isometry3d::Identity();
  SimpleScene clear;
  clear.AddPlane({0, 0, 0}, {0, 0, 1}, 0.2);  // ground, the cab frame's origin on it
  Eigen::Isometry3d T_scene_truck = Eigen::Isometry3d::Identity();
  T_scene_truck.translation() = Eigen::Vector3d(0, 9, 1.5);
  clear.AddBox(T_scene_truck, {4.5, 1.25, 1.5}, 0.35);
  SimpleScene dusty = clear;
  DustProperties dust;
  dust.extinction = 0.25;                     // visibility ≈ 16 m
  dusty.AddDustSphere({0, 7, 2}, 3.0, dust);  // from 3 m in front of the scanner to the truck

  DustMonitor monitor;
  Rng rng(99);
  const double phase = 0.3;  // s per phase: clear, dust, clear
  double max_fraction_clear = 0, min_scale_dust = 1, onset_delay = -1, clear_delay = -1;
  int fired = 0;
  for (std::int64_t k = 0; scanner.geometry().PulseTime(k) < 3 * phase; ++k) {
    const double t = scanner.geometry().PulseTime(k);
    const bool in_dust = t >= phase && t < 2 * phase;
    const auto pulse = scanner.Fire(k, pan, T_scene_cab, in_dust ? dusty : clear, rng);
    if (!pulse) continue;
    ++fired;
    monitor.Add(t, pulse->detection);
    if (t < phase && monitor.returning_pulses() >= 100) {
      max_fraction_clear = std::max(max_fraction_clear, monitor.dust_fraction());
      EXPECT_FALSE(monitor.warning()) << "t " << t;
    }
    if (in_dust) {
      min_scale_dust = std::min(min_scale_dust, monitor.speed_scale());
      if (onset_delay < 0 && monitor.warning()) onset_delay = t - phase;
    }
    if (t >= 2 * phase && clear_delay < 0 && !monitor.warning()) clear_delay = t - 2 * phase;
  }
  std::printf(
      "[scan through dust, %d pulses fired] clear air: dust fraction max %.4f; in dust: warning "
      "after %.3f s, speed scale down to %.2f; cleared %.3f s after the dust left\n",
      fired, max_fraction_clear, onset_delay, min_scale_dust, clear_delay);
  EXPECT_LT(max_fraction_clear, 0.01);
  ASSERT_GE(onset_delay, 0.0) << "no warning in dust";
  EXPECT_LT(onset_delay, 0.1);
  EXPECT_LT(min_scale_dust, 0.8);
  ASSERT_GE(clear_delay, 0.0) << "the warning never cleared";
  // The window must first empty of dusty pulses to 3 %: most of its 0.1 s.
  EXPECT_GT(clear_delay, 0.05);
  EXPECT_LT(clear_delay, 0.11);
}

}  // namespace
}  // namespace autoshovel::sensors
