// The simulated machine in a scenario yard, observed by its own simulated sensors: the wiring
// every later closed-loop test relies on.
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/plant/plant.h"
#include "runtime/plant/scenario.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/sensor_pose.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

TEST(YardSimulation, LoaderDigsTheScenarioPileAndItsLidarSeesTheChange) {
  Scenario scenario = LoadScenario(ResolveScenario("cone_pile", testing::ModelsDir()));
  const model::MachineDescription machine = testing::LoadMachine(scenario.machine);
  World& world = scenario.world;
  MachineState start = testing::LoaderAt(machine, 0.0);
  start.hinge_xy = Eigen::Vector2d(scenario.start.x, scenario.start.y);
  start.heading = scenario.start.heading;
  Plant plant(machine, testing::Functions(machine.name), world, start);
  const double volume0 = world.terrain.MaterialVolume();

  sensors::RaycastScene scene(world, plant.OwnBodies());
  const model::Lidar& lidar = machine.sensors.lidars.at(1);  // the forward non-repetitive one
  sensors::Rng rng(scenario.seed);
  auto frame = [&] {
    scene.SetExtraBoxes(plant.OwnBodies());
    scene.Update();
    return sensors::SimulateLidarFrame(
        lidar, scene, sensors::SensorInWorld(plant.state(), lidar.pose), plant.time(), rng);
  };
  // Before: the sensor sees its own bucket (boxes of class kOwnLoader) and the pile.
  const Eigen::Isometry3d T_world_lidar = sensors::SensorInWorld(plant.state(), lidar.pose);
  const Eigen::Vector3d to_tip = (plant.TipInWorld() - T_world_lidar.translation()).normalized();
  const sensors::RayHit bucket_hit = scene.Cast(T_world_lidar.translation(), to_tip, 50.0);
  ASSERT_TRUE(bucket_hit.hit);
  EXPECT_EQ(bucket_hit.semantic_class, core::SemanticClass::kOwnLoader);
  const sensors::PointCloud before = frame();
  EXPECT_GT(before.points.size(), 10000u);

  // Drive into the pile with the bucket on the floor, then lift and back off.
  core::ActuatorCommand command;
  command.valve = {0.0, 0.0};
  command.drive = 0.6;
  while (plant.time() < 14.0) {
    if (plant.resistance().in_contact && plant.state().speed < 0.1 && plant.time() > 2) {
      command.drive = -0.3;
      command.valve = {0.6, plant.state().q[1] < 0.9 ? 0.8 : 0.0};
    }
    ASSERT_TRUE(plant.SetCommand(command));
    plant.Advance(0.01);
  }
  EXPECT_GT(plant.bucket().payload_volume(), 0.5);
  EXPECT_NEAR(world.terrain.MaterialVolume() + plant.bucket().payload_volume(), volume0,
              1e-6 * volume0);
  // The dug face is lower than the cone was: a ray cast straight down where the bucket cut
  // meets the new surface, not the analytic cone.
  const Pile& pile = scenario.piles.front();
  const double toe = pile.center.x() - pile.height / pile.slope;
  const Eigen::Vector3d probe(toe + 0.6, pile.center.y(), 10.0);
  const double cone_height = pile.height - pile.slope * (pile.center.x() - probe.x());
  scene.Update();
  const sensors::RayHit down = scene.Cast(probe, -Eigen::Vector3d::UnitZ(), 50.0);
  ASSERT_TRUE(down.hit);
  EXPECT_LT(down.point.z(), cone_height - 0.1);
  EXPECT_NEAR(down.point.z(), world.terrain.HeightAt(probe.x(), probe.y()), 1e-6);
}

}  // namespace
}  // namespace autoshovel::plant
