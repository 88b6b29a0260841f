// The map from delivered frames alone (perception/sensor_fusion.h): no plant, no simulator.
#include "runtime/perception/sensor_fusion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "runtime/model/description.h"

namespace autoshovel::perception {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

// A LiDAR 2 m above the origin looking along +x: a floor (z = 0) from x = 3 to 9 m and a block
// 1.5 m high over x ∈ [6.0, 7.0], y ∈ [−0.5, 0.5], sampled every 5 cm.
LidarFrame FloorAndBlock(const std::string& lidar, double stamp) {
  LidarFrame frame;
  frame.lidar = lidar;
  frame.T_world_lidar = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 2.0));
  frame.stamp = stamp;
  frame.cloud.stamp = stamp;
  frame.cloud.sensor = lidar;
  for (double x = 3.0; x <= 9.0 + 1e-9; x += 0.05) {
    for (double y = -2.0; y <= 2.0 + 1e-9; y += 0.05) {
      const bool block = x >= 6.0 && x <= 7.0 && std::abs(y) <= 0.5;
      sensors::LidarPoint p;
      p.p_sensor = Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y),
                                   static_cast<float>((block ? 1.5 : 0.0) - 2.0));
      p.intensity = 0.3f;
      frame.cloud.points.push_back(p);
    }
  }
  return frame;
}

TEST(SensorFusion, FramesGiveTheHeightsTheyMeasureAndDropTheMachinesOwnReturns) {
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription("xcmg_968ev", kModels));
  const std::string lidar = machine.sensors.lidars.front().name;
  ElevationMapConfig config;
  config.length = Eigen::Vector2d(30.0, 30.0);
  ElevationMap map(config);
  SemanticMap semantic(map);
  SensorFrames frames;
  frames.lidar.push_back(FloorAndBlock(lidar, 0.0));
  // The machine's outline reaches 4 m ahead of the origin: the floor returns there are its own.
  frames.footprint.hinge_xy = Eigen::Vector2d::Zero();
  frames.footprint.front_length = 4.0;
  frames.footprint.rear_length = 3.0;
  frames.footprint.half_width = 1.5;
  const FusionStats stats = FuseSensorFrames(machine, frames, {}, map, semantic);
  EXPECT_GT(stats.returns_on_machine, 0);
  EXPECT_GT(stats.returns_fused, 0);
  EXPECT_EQ(stats.returns_fused + stats.returns_on_machine,
            static_cast<long>(frames.lidar.front().cloud.points.size()));
  EXPECT_NEAR(map.HeightAt({5.0, 0.0}), 0.0, 0.05);
  EXPECT_NEAR(map.HeightAt({6.5, 0.0}), 1.5, 0.05);
  EXPECT_NEAR(map.HeightAt({8.5, 1.5}), 0.0, 0.05);
  // No camera frame: no class evidence, but holes are filled and the ground plane is fitted.
  EXPECT_TRUE(stats.semantics.empty());
  EXPECT_TRUE(stats.ground_plane_found);
  EXPECT_NEAR(semantic.ground_plane().z(), 0.0, 0.05);
}

TEST(SensorFusion, AFrameOfALidarTheMachineLacksIsRefusedByName) {
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription("xcmg_968ev", kModels));
  ElevationMap map;
  SemanticMap semantic(map);
  SensorFrames frames;
  frames.lidar.push_back(FloorAndBlock("no_such_lidar", 0.0));
  try {
    FuseSensorFrames(machine, frames, {}, map, semantic);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no LiDAR 'no_such_lidar'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace autoshovel::perception
