// The arm-angle complementary filter (runtime/control/joint_angle_filter.h).
#include "runtime/control/joint_angle_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace autoshovel::control {
namespace {

constexpr double kTick = 0.01;  // 100 Hz, the scoop cycle's control period [s]

// Exact readings of a curling bucket (0.8 rad/s peak, a 1.25 s period): the gyro rate carries the
// estimate, so it stays on the angle where a first-order low-pass with the same noise reduction
// (time constant 0.1 s) would trail it by ≈ 0.8 rad/s · 0.1 s = 0.08 rad.
TEST(JointAngleFilter, TracksAMovingJointWithoutLag) {
  JointAngleFilter filter(0.1);
  const double w = 2 * M_PI / 1.25, amplitude = 0.8 / w;
  double worst = 0;
  for (int k = 0; k <= 500; ++k) {
    const double t = k * kTick;
    // The rate is the one over the coming tick (the plant integrates it), so the prediction is
    // exact up to the rate's change within the tick.
    const double q = amplitude * std::sin(w * t), qd = amplitude * w * std::cos(w * t);
    const double estimate = filter.Update(q, qd, kTick);
    worst = std::max(worst, std::abs(estimate - q));
  }
  EXPECT_LT(worst, 0.005);  // the O(q̈·Δt²/k) residual of a sampled rate, ≪ 0.08 rad
}

// White noise σ on the angle: the estimate's spread is √(k / (2 − k))·σ (23 % at k = 0.1).
TEST(JointAngleFilter, WhiteNoiseIsReducedByTheSteadyStateRatio) {
  const double sigma = 0.5 * M_PI / 180, k = 0.1;
  JointAngleFilter filter(k);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, sigma);
  const double rate = 0.2;  // a slow boom lift [rad/s]
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (int i = 0; i < 40000; ++i) {
    const double q = 0.3 + rate * i * kTick;
    const double error = filter.Update(q + noise(rng), rate, kTick) - q;
    if (i < 100) continue;  // settled after 1 s (10 time constants)
    sum += error, sum_sq += error * error, ++n;
  }
  const double mean = sum / n, spread = std::sqrt(sum_sq / n - mean * mean);
  EXPECT_NEAR(spread / sigma, std::sqrt(k / (2 - k)), 0.02);
  EXPECT_LT(std::abs(mean), 0.05 * sigma);  // no bias on a ramp
}

// A reading that jumps (an IMU bias step) is followed within a few Δt/k.
TEST(JointAngleFilter, FollowsAnOffsetWithinItsTimeConstant) {
  JointAngleFilter filter(0.1);
  filter.Update(0.0, 0.0, kTick);
  double estimate = 0;
  for (int i = 0; i < 10; ++i) estimate = filter.Update(0.1, 0.0, kTick);  // 0.1 s = Δt/k
  EXPECT_NEAR(estimate, 0.1 * (1 - std::pow(0.9, 10)), 1e-12);
  for (int i = 0; i < 40; ++i) estimate = filter.Update(0.1, 0.0, kTick);
  EXPECT_NEAR(estimate, 0.1, 0.1 * std::pow(0.9, 50) + 1e-12);
}

// A NaN angle is not fused: the gyro carries the estimate; a NaN rate carries nothing.
TEST(JointAngleFilter, NonFiniteReadingsNeverReachTheEstimate) {
  JointAngleFilter filter(0.1);
  EXPECT_EQ(filter.Update(NAN, 1.0, kTick), 0.0);
  EXPECT_FALSE(filter.initialised());
  EXPECT_EQ(filter.Update(0.5, 1.0, kTick), 0.5);
  EXPECT_NEAR(filter.Update(NAN, 1.0, kTick), 0.51, 1e-12);
  EXPECT_NEAR(filter.Update(0.51, NAN, kTick), 0.51, 1e-12);
  EXPECT_TRUE(std::isfinite(filter.estimate()));
  JointAngleFilter pass_through(1.0);
  pass_through.Update(0.2, 0.0, kTick);
  EXPECT_EQ(pass_through.Update(0.7, 5.0, kTick), 0.7);
}

TEST(JointAngleFilter, GainOutsideZeroOneIsRefused) {
  EXPECT_THROW(JointAngleFilter(0.0), std::invalid_argument);
  EXPECT_THROW(JointAngleFilter(1.5), std::invalid_argument);
  EXPECT_THROW(JointAngleFilter(NAN), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::control
