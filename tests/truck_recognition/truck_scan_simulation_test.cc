// The test scan simulator itself: the recognition tests are only as good as the scans they feed.
#include "truck_scan_simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace autoshovel::perception::truck_sim {
namespace {

TEST(TruckScanSimulation, RayHitsTheNearestSurface) {
  SimScene scene;
  scene.AddBox({10, 0, 0}, 0.0, {2, 2, 2});  // faces at x = 9 and 11
  const Eigen::Vector3d origin(0, 0, 1);
  EXPECT_NEAR(CastRay(scene, origin, Eigen::Vector3d::UnitX(), 40), 9.0, 1e-9);
  // Down at 45° onto the ground from 1 m up: √2.
  const Eigen::Vector3d down = Eigen::Vector3d(1, 0, -1).normalized();
  EXPECT_NEAR(CastRay(scene, origin, down, 40), std::sqrt(2.0), 1e-9);
  // Beyond the maximum range or into the sky: no return.
  EXPECT_FALSE(std::isfinite(CastRay(scene, origin, Eigen::Vector3d::UnitX(), 5)));
  EXPECT_FALSE(std::isfinite(CastRay(scene, origin, Eigen::Vector3d::UnitZ(), 40)));
}

TEST(TruckScanSimulation, RayHitsAConeOnItsFlank) {
  SimScene scene;
  scene.cones.push_back({{10, 0}, 2.0, 2.0});  // 45° flanks: surface at x = 8 + z
  const Eigen::Vector3d origin(0, 0, 1);
  EXPECT_NEAR(CastRay(scene, origin, Eigen::Vector3d::UnitX(), 40), 9.0, 1e-9);
  // Just over the apex: the ground beyond, 37.5 m out.
  const Eigen::Vector3d over(1, 0, -0.08);
  EXPECT_NEAR(CastRay(scene, Eigen::Vector3d(0, 0, 3), over.normalized(), 40), 37.5 * over.norm(),
              1e-9);
}

TEST(TruckScanSimulation, NoiseAndDropoutsHaveTheRequestedStatistics) {
  SimScene scene;
  scene.AddBox({8, 0, 0}, 0.0, {1, 40, 20});  // a tall wall at x = 7.5 fills the view
  ScannerSpec scanner;
  scanner.p_world_sensor = Eigen::Vector3d(0, 0, 4);
  scanner.pan_start_deg = -10;
  scanner.pan_end_deg = 10;
  scanner.elevation_min_deg = -20;
  scanner.elevation_max_deg = 20;
  scanner.range_noise_sigma = 0.03;
  scanner.dropout_probability = 0.05;
  scanner.pan_during_sweep = false;
  Rng rng(3);
  const std::vector<Scanline> scan = SimulateScan(scene, scanner, rng);
  double sum_sq = 0;
  int valid = 0;
  int total = 0;
  for (const Scanline& line : scan) {
    for (const ScanPoint& p : line.points) {
      ++total;
      if (!p.valid) continue;
      ++valid;
      const double error = p.p_world.x() - 7.5;  // noise along the beam, projected on x
      const Eigen::Vector3d beam = (p.p_world - scanner.p_world_sensor).normalized();
      sum_sq += std::pow(error / beam.x(), 2);
    }
  }
  ASSERT_GT(total, 3000);
  EXPECT_NEAR(1.0 - static_cast<double>(valid) / total, 0.05, 0.01);
  EXPECT_NEAR(std::sqrt(sum_sq / valid), 0.03, 0.002);
}

TEST(TruckScanSimulation, TruckTruthDescribesTheBedOpening) {
  SimScene scene;
  const TruckSpec spec = Tipper20t();
  const double yaw = 0.3;
  const TruckTruth truth = AddTruck(spec, {1.0, 7.0}, yaw, &scene);
  EXPECT_NEAR(truth.rim_height, spec.floor_height + spec.wall_height, 1e-12);
  EXPECT_NEAR(truth.T_world_bed.translation().z(), truth.rim_height, 1e-12);
  EXPECT_NEAR((truth.p_world_corners[0] - truth.p_world_corners[3]).norm(), spec.inner_length,
              1e-9);
  EXPECT_NEAR((truth.p_world_corners[0] - truth.p_world_corners[1]).norm(), spec.inner_width, 1e-9);
  // A beam straight down through the middle of the bed lands on the floor.
  const Eigen::Vector3d above = truth.T_world_bed * Eigen::Vector3d(0, 0, 2);
  EXPECT_NEAR(CastRay(scene, above, -Eigen::Vector3d::UnitZ(), 40), 2.0 + spec.wall_height, 1e-9);
  // The front corner is ahead of the rear one along the heading.
  const Eigen::Vector2d heading(std::cos(yaw), std::sin(yaw));
  EXPECT_GT(heading.dot((truth.p_world_corners[0] - truth.p_world_corners[3]).head<2>()), 0);
}

}  // namespace
}  // namespace autoshovel::perception::truck_sim
