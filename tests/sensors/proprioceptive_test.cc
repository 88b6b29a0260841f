// IMUs (wheel-loader seed Eq. 1), articulation encoder, localisation: exact when noise-free,
// the configured noise statistics otherwise, the bias random walk, determinism.
#include "runtime/sensors/proprioceptive.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "tests/sensors/sensor_test_support.h"

namespace autoshovel::sensors {
namespace {

using testing::Xcmg;

constexpr double kDeg = std::numbers::pi / 180;

model::MachineDescription NoiseFree(bool keep_bias) {
  model::MachineDescription d = Xcmg();
  for (auto& imu : d.sensors.imus) {
    imu.angle_noise = 0;
    if (!keep_bias) imu.bias = 0;
  }
  return d;
}

plant::MachineState RandomState(const model::MachineDescription& d, std::mt19937_64& rng) {
  plant::MachineState s;
  s.pitch = std::uniform_real_distribution<double>(-0.2, 0.2)(rng);
  s.articulation = std::uniform_real_distribution<double>(-0.6, 0.6)(rng);
  s.heading = std::uniform_real_distribution<double>(-3, 3)(rng);
  s.hinge_xy = Eigen::Vector2d(std::uniform_real_distribution<double>(-50, 50)(rng),
                               std::uniform_real_distribution<double>(-50, 50)(rng));
  for (const auto& link : d.links) {
    s.q.push_back(std::uniform_real_distribution<double>(link.joint_min, link.joint_max)(rng));
  }
  return s;
}

TEST(Imu, NoiseFreeReadingsAreEquationOne) {
  const model::MachineDescription d = NoiseFree(false);
  ASSERT_EQ(d.sensors.imus.size(), 3u);
  ASSERT_EQ(d.links.size(), 2u);
  // The offsets must take part, or the test would not see them dropped.
  model::MachineDescription with_offsets = d;
  with_offsets.links[0].imu_offset = 3.0 * kDeg;
  with_offsets.links[1].imu_offset = -7.5 * kDeg;
  ProprioceptiveSensors sensors(with_offsets);
  std::mt19937_64 states(1);
  Rng rng(2);
  for (int i = 0; i < 1000; ++i) {
    const plant::MachineState s = RandomState(with_offsets, states);
    const auto imus = sensors.ReadImus(s, rng);
    ASSERT_EQ(imus.size(), 3u);
    const double theta_cab = imus[0].pitch, theta_1 = imus[1].pitch, theta_2 = imus[2].pitch;
    EXPECT_EQ(imus[0].name, "cab_imu");
    EXPECT_EQ(theta_cab, s.pitch);
    // φ_1 = q_1, φ_2 = q_1 + q_2; Eq. 1: φ_k = θ_k − θ_cab + α_k.
    EXPECT_NEAR(theta_1 - theta_cab + 3.0 * kDeg, s.q[0], 1e-14);
    EXPECT_NEAR(theta_2 - theta_cab - 7.5 * kDeg, s.q[0] + s.q[1], 1e-14);
    EXPECT_EQ(imus[1].roll, 0.0);
  }
}

TEST(Imu, BiasIsAddedToEveryReading) {
  const model::MachineDescription d = NoiseFree(true);
  ProprioceptiveSensors sensors(d);
  std::mt19937_64 states(3);
  Rng rng(4);
  for (int i = 0; i < 100; ++i) {
    const plant::MachineState s = RandomState(d, states);
    const auto imus = sensors.ReadImus(s, rng);
    for (std::size_t k = 0; k < imus.size(); ++k) {
      EXPECT_NEAR(imus[k].pitch - TrueImuPitch(d, d.sensors.imus[k], s), d.sensors.imus[k].bias,
                  1e-14);
    }
  }
  EXPECT_NEAR(d.sensors.imus[1].bias, -0.1 * kDeg, 1e-15);  // boom_imu bias_deg: -0.1
}

TEST(Imu, NoiseHasTheConfiguredSigma) {
  const model::MachineDescription& d = Xcmg();
  ProprioceptiveSensors sensors(d);
  std::mt19937_64 states(5);
  Rng rng(6);
  constexpr int kN = 20000;
  std::vector<double> sum(3), sum2(3);
  for (int i = 0; i < kN; ++i) {
    plant::MachineState s = RandomState(d, states);
    s.time = 0.01 * i;
    const auto imus = sensors.ReadImus(s, rng);
    for (int k = 0; k < 3; ++k) {
      const double e = imus[k].pitch - TrueImuPitch(d, d.sensors.imus[k], s);
      sum[k] += e;
      sum2[k] += e * e;
    }
  }
  for (int k = 0; k < 3; ++k) {
    const auto& imu = d.sensors.imus[k];
    const double mean = sum[k] / kN, sd = std::sqrt(sum2[k] / kN - mean * mean);
    EXPECT_NEAR(mean, imu.bias, 4 * imu.angle_noise / std::sqrt(kN)) << imu.name;
    EXPECT_NEAR(sd / imu.angle_noise, 1.0, 0.03) << imu.name;  // brief: 15 %; n gives ±0.5 %
  }
  EXPECT_NEAR(d.sensors.imus[2].angle_noise, 0.08 * kDeg, 1e-15);
}

TEST(Imu, BiasRandomWalkGrowsWithTheSquareRootOfTime) {
  // σ_b = 0.01 rad/√s for 100 steps of 0.04 s (4 s): bias change σ = 0.02 rad, over 4000 runs.
  ProprioceptiveOptions options;
  options.imu_bias_random_walk = 0.01;
  const model::MachineDescription d = NoiseFree(true);
  Rng rng(7);
  plant::MachineState s;
  s.q = {0.1, 0.2};
  double sum2 = 0;
  constexpr int kRuns = 4000;
  for (int run = 0; run < kRuns; ++run) {
    ProprioceptiveSensors sensors(d, options);
    for (int i = 0; i <= 100; ++i) {
      s.time = 0.04 * i;
      sensors.ReadImus(s, rng);
    }
    const double change = sensors.imu_biases()[1] - d.sensors.imus[1].bias;
    sum2 += change * change;
  }
  EXPECT_NEAR(std::sqrt(sum2 / kRuns), 0.02, 0.02 * 0.05);
  // Default: no drift.
  ProprioceptiveSensors fixed(d);
  s.time = 100;
  fixed.ReadImus(s, rng);
  s.time = 200;
  fixed.ReadImus(s, rng);
  EXPECT_EQ(fixed.imu_biases()[2], d.sensors.imus[2].bias);
}

TEST(Encoder, ArticulationNoise) {
  ProprioceptiveSensors sensors(Xcmg());
  Rng rng(8);
  plant::MachineState s;
  s.articulation = 0.3;
  s.time = 2.5;
  constexpr int kN = 20000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < kN; ++i) {
    const ArticulationSample a = sensors.ReadArticulation(s, rng);
    ASSERT_EQ(a.stamp, 2.5);
    sum += a.angle - 0.3;
    sum2 += (a.angle - 0.3) * (a.angle - 0.3);
  }
  const double sd = std::sqrt(sum2 / kN - (sum / kN) * (sum / kN));
  EXPECT_NEAR(sum / kN, 0.0, 4 * 0.1 * kDeg / std::sqrt(kN));
  EXPECT_NEAR(sd / (0.1 * kDeg), 1.0, 0.03);
}

TEST(Localisation, CabPoseAndNoise) {
  ProprioceptiveSensors sensors(Xcmg());
  Rng rng(9);
  plant::MachineState s;
  s.hinge_xy = Eigen::Vector2d(12.0, -4.0);
  s.heading = 0.8;
  s.articulation = 0.25;  // the rear frame (cab) is turned −γ from the front frame
  s.pitch = 0.05;
  // The cab's x axis is Rz(ψ)·Ry(−θ)·Rz(−γ)·x: pitch about the front frame's y axis shortens
  // its x component by cos θ, so its heading is ψ + atan2(−sin γ, cos γ cos θ) (ψ − γ − 3e-4).
  const double yaw = 0.8 + std::atan2(-std::sin(0.25), std::cos(0.25) * std::cos(0.05));
  EXPECT_NEAR(yaw, 0.8 - 0.25, 4e-4);
  constexpr int kN = 20000;
  double sx = 0, sy = 0, syaw = 0, sx2 = 0, sy2 = 0, syaw2 = 0;
  for (int i = 0; i < kN; ++i) {
    const PoseSample p = sensors.ReadPose(s, rng);
    const double ex = p.x - 12.0, ey = p.y + 4.0, eyaw = p.yaw - yaw;
    sx += ex, sy += ey, syaw += eyaw;
    sx2 += ex * ex, sy2 += ey * ey, syaw2 += eyaw * eyaw;
  }
  auto sd = [](double s1, double s2) { return std::sqrt(s2 / kN - (s1 / kN) * (s1 / kN)); };
  EXPECT_NEAR(syaw / kN, 0.0, 4 * 0.2 * kDeg / std::sqrt(kN));
  EXPECT_NEAR(sx / kN, 0.0, 4 * 0.02 / std::sqrt(kN));
  EXPECT_NEAR(sy / kN, 0.0, 4 * 0.02 / std::sqrt(kN));
  EXPECT_NEAR(sd(sx, sx2) / 0.02, 1.0, 0.03);
  EXPECT_NEAR(sd(sy, sy2) / 0.02, 1.0, 0.03);
  EXPECT_NEAR(sd(syaw, syaw2) / (0.2 * kDeg), 1.0, 0.03);
}

TEST(Proprioceptive, SameSeedSameReadings) {
  auto run = [](std::uint64_t seed) {
    ProprioceptiveOptions options;
    options.imu_bias_random_walk = 1e-3;
    ProprioceptiveSensors sensors(Xcmg(), options);
    Rng rng(seed);
    std::mt19937_64 states(10);
    std::vector<double> out;
    for (int i = 0; i < 50; ++i) {
      plant::MachineState s = RandomState(Xcmg(), states);
      s.time = 0.1 * i;
      for (const auto& imu : sensors.ReadImus(s, rng)) out.push_back(imu.pitch);
      out.push_back(sensors.ReadArticulation(s, rng).angle);
      out.push_back(sensors.ReadPose(s, rng).yaw);
    }
    return out;
  };
  EXPECT_TRUE(run(11) == run(11));
  EXPECT_FALSE(run(11) == run(12));
}

}  // namespace
}  // namespace autoshovel::sensors
