// Step 2 of §4.1: segments of neighbouring scanlines grouped into planar regions.
#include "runtime/perception/truck/planar_regions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "truck_scan_simulation.h"

namespace autoshovel::perception {
namespace {

using truck_sim::Rng;
using truck_sim::ScannerSpec;
using truck_sim::SimScene;

ScannerSpec Scanner() {
  ScannerSpec scanner;
  scanner.p_world_sensor = Eigen::Vector3d(0, 0, 4.8);
  return scanner;
}

// Angle between two unit vectors [deg].
double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180 / std::numbers::pi;
}

// The region whose normal is closest to `normal` among those within 5°, or nullptr.
const PlanarRegion* FindByNormal(const std::vector<PlanarRegion>& regions,
                                 const Eigen::Vector3d& normal, const Eigen::Vector3d& near) {
  const PlanarRegion* best = nullptr;
  for (const PlanarRegion& r : regions) {
    if (AngleDeg(r.normal, normal) > 5) continue;
    if (best == nullptr || (r.centroid - near).norm() < (best->centroid - near).norm()) best = &r;
  }
  return best;
}

TEST(PlanarRegions, FindsTheGroundAndTheVisibleFacesOfABox) {
  SimScene scene;
  // A 6 m × 2.5 m × 2.5 m block 7 m to the left, turned by 20°.
  const double yaw = 20 * std::numbers::pi / 180;
  scene.AddBox({0.5, 7.5, 0}, yaw, {6, 2.5, 2.5});
  Rng rng(1);
  const std::vector<LineSegment> segments =
      SegmentScanlines(truck_sim::SimulateScan(scene, Scanner(), rng));
  const std::vector<PlanarRegion> regions = GroupPlanarRegions(segments);
  ASSERT_GE(regions.size(), 3u);

  const GroundEstimate ground = EstimateGround(regions);
  ASSERT_TRUE(ground.found);
  EXPECT_EQ(ground.region, 0);  // the largest region
  EXPECT_NEAR(ground.HeightAbove(Eigen::Vector3d(3, 4, 0)), 0.0, 0.01);
  EXPECT_NEAR(ground.HeightAbove(Eigen::Vector3d(3, 4, 1.5)), 1.5, 0.01);

  // The side facing the excavator (normal −y turned by yaw) and the top.
  const Eigen::Vector3d side_normal(std::sin(yaw), -std::cos(yaw), 0);
  const PlanarRegion* side = FindByNormal(regions, side_normal, {0.5, 6.3, 1.25});
  ASSERT_NE(side, nullptr);
  EXPECT_LT(AngleDeg(side->normal, side_normal), 1.0);
  EXPECT_NEAR(side->top_z, 2.5, 0.06);
  EXPECT_NEAR(side->USize(), 6.0, 0.3);
  const PlanarRegion* top = FindByNormal(regions, Eigen::Vector3d::UnitZ(), {0.5, 7.5, 2.5});
  ASSERT_NE(top, nullptr);
  EXPECT_NEAR(top->centroid.z(), 2.5, 0.02);
}

TEST(PlanarRegions, EveryRegionHonoursItsToleranceAndFacesTheSensor) {
  // A dirt pile (curved) beside two walls: whatever is grown stays planar within the tolerance.
  SimScene scene;
  scene.cones.push_back({{-2, 8}, 2.5, 3.5});
  scene.AddBox({4, 8, 0}, 0.4, {5, 0.3, 3});
  scene.AddBox({1, 13, 0}, -0.2, {8, 0.3, 4});
  Rng rng(2);
  const std::vector<Scanline> scan = truck_sim::SimulateScan(scene, Scanner(), rng);
  const std::vector<LineSegment> segments = SegmentScanlines(scan);
  const PlanarRegionParams params;
  const std::vector<PlanarRegion> regions = GroupPlanarRegions(segments, params);
  ASSERT_FALSE(regions.empty());
  int pile_regions = 0;
  for (const PlanarRegion& r : regions) {
    EXPECT_LE(r.rms_residual, params.max_plane_rms + 1e-12);
    EXPECT_GE(static_cast<int>(r.segments.size()), params.min_segments);
    EXPECT_GE(r.num_points, params.min_points);
    EXPECT_GT(r.normal.dot(r.p_world_sensor_mean - r.centroid), 0);
    for (int s : r.segments) {
      EXPECT_LE(std::abs(r.normal.dot(segments[s].p_world_start - r.centroid)),
                params.plane_tolerance + 0.03);
    }
    // Pile regions: tilted like the pile's flanks (30°–38°), each a strip of the cone.
    const double tilt = std::acos(std::abs(r.normal.z())) * 180 / std::numbers::pi;
    if (tilt > 20 && tilt < 70) ++pile_regions;
  }
  EXPECT_GT(pile_regions, 1);  // the cone is not taken for one plane
}

TEST(PlanarRegions, KeepsCoplanarFacesApartAcrossAGap) {
  // Two walls in one plane, 1 m apart: scanlines through the gap see the ground far behind.
  SimScene scene;
  scene.AddBox({-2.5, 7, 0}, 0.0, {4, 0.2, 2.5});
  scene.AddBox({2.5, 7, 0}, 0.0, {4, 0.2, 2.5});
  Rng rng(4);
  const std::vector<PlanarRegion> regions =
      GroupPlanarRegions(SegmentScanlines(truck_sim::SimulateScan(scene, Scanner(), rng)));
  int walls = 0;
  for (const PlanarRegion& r : regions) {
    if (AngleDeg(r.normal, -Eigen::Vector3d::UnitY()) < 3 && r.USize() > 2) {
      ++walls;
      EXPECT_LT(r.USize(), 4.3);
    }
  }
  EXPECT_EQ(walls, 2);
}

TEST(PlanarRegions, RejectsInvalidParametersAndSegments) {
  PlanarRegionParams params;
  params.max_link_angle_deg = 95;
  EXPECT_THROW(GroupPlanarRegions({}, params), std::invalid_argument);
  params = {};
  params.min_segments = 1;
  EXPECT_THROW(GroupPlanarRegions({}, params), std::invalid_argument);
  std::vector<LineSegment> segments(1);  // scanline index left at -1
  EXPECT_THROW(GroupPlanarRegions(segments), std::invalid_argument);
  EXPECT_THROW(EstimateGround({}, 0.0), std::invalid_argument);
  EXPECT_TRUE(GroupPlanarRegions({}).empty());
  EXPECT_FALSE(EstimateGround({}).found);
  EXPECT_TRUE(std::isnan(EstimateGround({}).HeightAbove(Eigen::Vector3d::Zero())));
}

}  // namespace
}  // namespace autoshovel::perception
