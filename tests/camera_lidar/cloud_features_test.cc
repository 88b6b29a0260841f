// The segment classes of the camera–LiDAR score (cloud_features.h) on a synthetic scene: a floor
// with Gaussian height noise and a box standing on it. What matters for an unbiased F_S is that
// the floor stays ground as a whole, neither of its noise tails leaking into the box's class.
#include "identification/camera_lidar/cloud_features.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace autoshovel::identification {
namespace {

struct Scene {
  std::vector<Eigen::Vector3f> points;
  std::vector<char> on_floor;
};

// Floor z = 0 on [0, 8] × [−4, 4] every 4 cm with N(0, σ) heights; a 1 m box on [4, 5] × [−0.5,
// 0.5] (its top and its four sides, 4 cm apart), the floor under it left out.
Scene FloorAndBox(double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Scene s;
  const double step = 0.04;
  auto add = [&](double x, double y, double z, bool floor) {
    s.points.emplace_back(static_cast<float>(x), static_cast<float>(y),
                          static_cast<float>(z + noise(rng)));
    s.on_floor.push_back(floor ? 1 : 0);
  };
  for (double x = 0; x < 8; x += step) {
    for (double y = -4; y < 4; y += step) {
      if (x > 4 && x < 5 && std::abs(y) < 0.5) continue;
      add(x, y, 0, true);
    }
  }
  for (double a = 4; a <= 5; a += step) {
    for (double b = -0.5; b <= 0.5; b += step) add(a, b, 1.0, false);
    for (double z = step; z < 1.0; z += step) {
      add(a, -0.5, z, false);
      add(a, 0.5, z, false);
    }
  }
  for (double b = -0.5; b <= 0.5; b += step) {
    for (double z = step; z < 1.0; z += step) {
      add(4, b, z, false);
      add(5, b, z, false);
    }
  }
  return s;
}

// Floor points more than 12 cm (three grid steps, beyond the reach of the smoothing's
// neighbours) from the box's footprint.
struct Counts {
  int floor = 0, floor_ground = 0, floor_in_object = 0;
};

Counts ClassifyFloorAwayFromTheBox(const Scene& s, const CloudFeatures& f) {
  Counts c;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (!s.on_floor[i]) continue;
    const double dx = std::max({4.0 - s.points[i].x(), s.points[i].x() - 5.0, 0.0});
    const double dy = std::max(std::abs(s.points[i].y()) - 0.5, 0.0);
    if (std::hypot(dx, dy) < 0.12) continue;
    ++c.floor;
    if (f.segment[i] == 0) ++c.floor_ground;
    if (f.segment[i] > 0) ++c.floor_in_object;
  }
  return c;
}

TEST(CloudFeatures, NoisyFloorStaysGroundWithTheNoiseAdaptiveSmoothing) {
  const double sigma = 0.01;
  const Scene s = FloorAndBox(sigma, 7);
  const CloudFeatures f = ComputeCloudFeatures(s.points, Eigen::Vector3d::UnitZ());
  // The robust σ of the floor (MAD) within 10 %, and k the smallest with 5σ/√k ≤ 1.5 cm.
  EXPECT_NEAR(f.ground_noise, sigma, 0.1 * sigma);
  const double ratio = 5 * f.ground_noise / 0.015;
  EXPECT_EQ(f.ground_smoothing_neighbours, static_cast<int>(std::ceil(ratio * ratio)));
  const Counts c = ClassifyFloorAwayFromTheBox(s, f);
  // Unsmoothed, a ±1.5 cm band keeps only 87 % of an N(0, 1 cm) floor and gives 6.7 % of it to
  // the object classes (the upper tail: clusters of its own or the box's); averaged over k ≈ 12
  // neighbours a floor point leaves the band with probability ≈ 1e-6: all of it is ground.
  EXPECT_EQ(c.floor_ground, c.floor);
  EXPECT_EQ(c.floor_in_object, 0);

  CloudFeatureOptions unsmoothed;
  unsmoothed.max_ground_smoothing_neighbours = 1;
  const Counts raw = ClassifyFloorAwayFromTheBox(
      s, ComputeCloudFeatures(s.points, Eigen::Vector3d::UnitZ(), unsmoothed));
  EXPECT_LT(raw.floor_ground, 0.9 * raw.floor);
  EXPECT_GT(raw.floor_in_object, 0.05 * raw.floor);
}

TEST(CloudFeatures, CleanFloorIsNotSmoothedAndTheBoxKeepsItsFoot) {
  const Scene s = FloorAndBox(0.0, 7);
  const CloudFeatures f = ComputeCloudFeatures(s.points, Eigen::Vector3d::UnitZ());
  EXPECT_LT(f.ground_noise, 1e-3);
  EXPECT_EQ(f.ground_smoothing_neighbours, 1);
  const Counts c = ClassifyFloorAwayFromTheBox(s, f);
  EXPECT_EQ(c.floor_ground, c.floor);
  // The box's lowest row (4 cm up) is object, none of it ground.
  int foot = 0, foot_object = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (s.on_floor[i] || s.points[i].z() > 0.05f) continue;
    ++foot;
    if (f.segment[i] > 0) ++foot_object;
  }
  EXPECT_GT(foot, 0);
  EXPECT_EQ(foot_object, foot);
}

}  // namespace
}  // namespace autoshovel::identification
