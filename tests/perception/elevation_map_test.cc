// The elevation map against the simulator's ground truth (wheel-loader seed §4.1).
#include "runtime/perception/elevation_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/plant/machine_state.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/scenario.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::perception {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

TEST(GridMap, IndexAndPositionRoundTripAndMoveKeepsTheWorld) {
  GridMap map(0.3, Eigen::Vector2d(6.0, 3.0), Eigen::Vector2d(10.0, -5.0));
  EXPECT_EQ(map.size().x(), 20);
  EXPECT_EQ(map.size().y(), 10);
  map.Add("h", 0.0f);
  for (GridMapIterator it(map); !it.done(); ++it) {
    Index back;
    ASSERT_TRUE(map.IndexOf(map.PositionOf(*it), back));
    EXPECT_TRUE((back == *it).all());
    map.at("h", *it) = static_cast<float>(map.PositionOf(*it).x() * 100 + map.PositionOf(*it).y());
  }
  Index outside;
  EXPECT_FALSE(map.IndexOf(Eigen::Vector2d(13.1, -5.0), outside));
  EXPECT_THROW(map["missing"], std::out_of_range);
  const Index shift = map.Move(Eigen::Vector2d(10.95, -5.6));  // 3 cells east, 2 south
  EXPECT_EQ(shift.x(), 3);
  EXPECT_EQ(shift.y(), -2);
  int kept = 0;
  for (GridMapIterator it(map); !it.done(); ++it) {
    const float v = map.at("h", *it);
    if (v == 0.0f) continue;  // entered the map
    const Eigen::Vector2d p = map.PositionOf(*it);
    EXPECT_NEAR(v, p.x() * 100 + p.y(), 1e-3);  // the same world cell holds the same value
    ++kept;
  }
  EXPECT_EQ(kept, (20 - 3) * (10 - 2));
}

// Eq. (8) applied twice to one cell with single returns: the closed form.
TEST(ElevationMap, KalmanUpdateIsEquationEight) {
  ElevationMapConfig config;
  config.resolution = 1.0;
  config.length = Eigen::Vector2d(10, 10);
  config.change_gate = 1e9;  // pure Eq. (8)
  config.process_noise = 0;
  config.clearing_stride = 0;
  ElevationMap map(config);
  auto frame = [](double x, double z, double stamp) {
    sensors::PointCloud cloud;
    cloud.stamp = stamp;
    sensors::LidarPoint p;
    p.p_sensor = Eigen::Vector3f(static_cast<float>(x), 0.0f, static_cast<float>(z));
    cloud.points.push_back(p);
    return cloud;
  };
  const Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  ASSERT_TRUE(map.Update(frame(2.5, 1.0, 0.0), T, 0.0).applied);
  const double d1 = 2.5 * 2.5 + 1.0, s1 = 0.05 * d1;  // σp² = α_d d²
  const double d2 = 2.5 * 2.5 + 1.4 * 1.4, s2 = 0.05 * d2;
  ASSERT_TRUE(map.Update(frame(2.5, 1.4, 0.1), T, 0.1).applied);
  const double h = (s2 * 1.0 + s1 * 1.4) / (s1 + s2);
  const double v = s1 * s2 / (s1 + s2);
  Index i;
  ASSERT_TRUE(map.map().IndexOf(Eigen::Vector2d(2.5, 0.0), i));
  EXPECT_NEAR(map.map().at("elevation", i), h, 1e-5);
  EXPECT_NEAR(map.map().at("variance", i), v, 1e-5);
}

TEST(ElevationMap, BadFramesLeaveTheMapUnchangedAndNanIsCounted) {
  ElevationMap map;
  sensors::PointCloud cloud;
  cloud.stamp = 5.0;
  EXPECT_EQ(map.Update(cloud, Eigen::Isometry3d::Identity(), 5.0).refused, "empty frame");
  sensors::LidarPoint good, bad;
  good.p_sensor = Eigen::Vector3f(5, 0, -1);
  bad.p_sensor = Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0, 0);
  cloud.points = {good, bad, good};
  bad.p_sensor.z() = std::numeric_limits<float>::infinity();
  cloud.points.push_back(bad);
  const MapUpdateStats old_pose = map.Update(cloud, Eigen::Isometry3d::Identity(), 4.0);
  EXPECT_FALSE(old_pose.applied);
  EXPECT_NE(old_pose.refused.find("pose is"), std::string::npos);
  EXPECT_TRUE(std::isnan(map.HeightAt(Eigen::Vector2d(5, 0))));
  const MapUpdateStats ok = map.Update(cloud, Eigen::Isometry3d::Identity(), 5.0);
  EXPECT_TRUE(ok.applied);
  EXPECT_EQ(ok.non_finite, 2);
  EXPECT_EQ(ok.fused, 2);
  EXPECT_NEAR(map.HeightAt(Eigen::Vector2d(5, 0)), -1.0, 1e-6);
}

// The loader in the cone yard, its forward LiDAR mapping the pile over several frames.
struct YardFixture {
  plant::Scenario scenario;
  model::MachineDescription machine;
  std::unique_ptr<plant::Plant> plant;
  std::unique_ptr<sensors::RaycastScene> scene;
  sensors::Rng rng{7};

  explicit YardFixture(const std::string& name, double start_offset = 4.0) {
    scenario = plant::LoadScenario(plant::ResolveScenario(name, kModels));
    machine =
        model::LoadMachineDescription(model::ResolveMachineDescription(scenario.machine, kModels));
    plant::MachineState start;
    start.hinge_xy = Eigen::Vector2d(scenario.start.x + start_offset, scenario.start.y);
    start.heading = scenario.start.heading;
    start.q = plant::BucketOnFloor(machine);
    plant = std::make_unique<plant::Plant>(machine, *generated::FindMachine(machine.name),
                                           scenario.world, start);
    scene = std::make_unique<sensors::RaycastScene>(scenario.world, plant->OwnBodies());
  }
  const model::Lidar& lidar() const { return machine.sensors.lidars.at(1); }
  Eigen::Isometry3d T_world_lidar() const {
    return sensors::SensorInWorld(plant->state(), lidar().pose);
  }
  sensors::PointCloud Frame(double stamp) {
    scene->Update();
    return sensors::SimulateLidarFrame(lidar(), *scene, T_world_lidar(), stamp, rng);
  }
  MachineFootprint Footprint() const {
    const plant::MachineState& s = plant->state();
    return LoaderFootprint(machine, s.hinge_xy, s.heading, s.articulation,
                           (plant->TipInWorld().head<2>() - s.hinge_xy).norm());
  }
  /// RMS of map minus truth over observed cells whose centre lies within `radius` of `center`.
  double Rms(const ElevationMap& map, const Eigen::Vector2d& center, double radius,
             int* count) const {
    double sum = 0;
    *count = 0;
    const GridMap& g = map.map();
    for (GridMapIterator it(g); !it.done(); ++it) {
      const Eigen::Vector2d p = g.PositionOf(*it);
      if ((p - center).norm() > radius || g.at("observed", *it) == 0) continue;
      const double e = g.at("elevation", *it) - scenario.world.terrain.HeightAt(p.x(), p.y());
      sum += e * e;
      ++*count;
    }
    return *count ? std::sqrt(sum / *count) : 0.0;
  }
};

TEST(ElevationMap, MapsTheConeWithinFiveCentimetres) {
  YardFixture yard("cone_pile");
  ElevationMap map(ElevationMapConfig{}, yard.plant->state().hinge_xy);
  const MachineFootprint footprint = yard.Footprint();
  long on_machine = 0;
  for (int k = 0; k < 5; ++k) {
    const MapUpdateStats s =
        map.Update(yard.Frame(0.1 * k), yard.T_world_lidar(), 0.1 * k, &footprint);
    ASSERT_TRUE(s.applied) << s.refused;
    on_machine += s.on_machine;
  }
  EXPECT_GT(on_machine, 100);  // the sensor sees its own bucket and boom, and drops them
  const plant::Pile& pile = yard.scenario.piles.front();
  int count = 0;
  const double rms = yard.Rms(map, pile.center, pile.height / pile.slope + 1.0, &count);
  EXPECT_GT(count, 200);
  EXPECT_LT(rms, 0.05);
  // Nothing of the machine got into the map.
  const GridMap& g = map.map();
  for (GridMapIterator it(g); !it.done(); ++it) {
    const Eigen::Vector2d p = g.PositionOf(*it);
    if (footprint.Contains(Eigen::Vector3d(p.x(), p.y(), 0.0))) {
      EXPECT_TRUE(g.at("observed", *it) == 0 || g.at("elevation", *it) < 0.3);
    }
  }
}

// A bucket takes 0.6 m off the pile's flank: the dug cells follow within three frames.
TEST(ElevationMap, DugCellsDropToTheNewSurfaceWithinThreeFrames) {
  YardFixture yard("cone_pile");
  ElevationMap map(ElevationMapConfig{}, yard.plant->state().hinge_xy);
  for (int k = 0; k < 30; ++k) {  // a long history: the Kalman filter is very sure
    map.Update(yard.Frame(0.1 * k), yard.T_world_lidar(), 0.1 * k);
  }
  plant::Terrain& terrain = yard.scenario.world.terrain;
  const plant::Pile& pile = yard.scenario.piles.front();
  const Eigen::Vector2d dig = pile.center - Eigen::Vector2d(2.0, 0.0);
  for (int iy = 0; iy < terrain.ny(); ++iy) {
    for (int ix = 0; ix < terrain.nx(); ++ix) {
      if ((terrain.CellCenter(ix, iy) - dig).norm() < 1.0 && terrain.depth(ix, iy) > 0) {
        terrain.SetHeight(ix, iy, terrain.height(ix, iy) - 0.6);
      }
    }
  }
  for (int k = 30; k < 33; ++k) map.Update(yard.Frame(0.1 * k), yard.T_world_lidar(), 0.1 * k);
  int count = 0;
  const double rms = yard.Rms(map, dig, 0.8, &count);
  EXPECT_GT(count, 10);
  EXPECT_LT(rms, 0.05);
}

// A person stands in front of the loader and walks away: the rays that now pass where the
// person was clear those cells.
TEST(ElevationMap, RaysClearAnObstacleThatLeft) {
  YardFixture yard("cone_pile");
  plant::OrientedBox person;
  person.name = "person";
  // Beside the bucket's shadow, so that the ground behind the person is in view once it left.
  person.center = Eigen::Vector3d(yard.plant->state().hinge_xy.x() + 7.0,
                                  yard.plant->state().hinge_xy.y() + 2.5, 0.9);
  person.half_extents = Eigen::Vector3d(0.25, 0.25, 0.9);
  person.semantic_class = core::SemanticClass::kPerson;
  yard.scenario.world.obstacles.push_back(person);
  ElevationMapConfig config;
  config.clearing_stride = 1;
  ElevationMap map(config, yard.plant->state().hinge_xy);
  for (int k = 0; k < 3; ++k) map.Update(yard.Frame(0.1 * k), yard.T_world_lidar(), 0.1 * k);
  const float with_person = map.HeightAt(person.center.head<2>());
  EXPECT_GT(with_person, 1.0);
  yard.scenario.world.obstacles.pop_back();
  long cleared = 0;
  for (int k = 3; k < 8; ++k) {
    cleared += map.Update(yard.Frame(0.1 * k), yard.T_world_lidar(), 0.1 * k).cells_cleared;
  }
  EXPECT_GT(cleared, 0);
  // Back to the surface the person stood on (the pile's toe).
  const float after = map.HeightAt(person.center.head<2>());
  const double surface = yard.scenario.world.terrain.HeightAt(person.center.x(), person.center.y());
  EXPECT_TRUE(std::isnan(after) || std::abs(after - surface) < 0.15) << after << " vs " << surface;
}

TEST(ElevationMap, HolesAreFilledFromTheNearestObservedCellAndFlagged) {
  ElevationMapConfig config;
  config.resolution = 1.0;
  config.length = Eigen::Vector2d(10, 10);
  config.max_fill_distance = 2.5;
  ElevationMap map(config);
  sensors::PointCloud cloud;
  cloud.stamp = 0;
  for (const auto& [x, z] : {std::pair{-2.5, 1.0}, std::pair{2.5, 3.0}}) {
    sensors::LidarPoint p;
    p.p_sensor = Eigen::Vector3f(static_cast<float>(x), 0.5f, static_cast<float>(z));
    cloud.points.push_back(p);
  }
  ASSERT_TRUE(map.Update(cloud, Eigen::Isometry3d::Identity(), 0.0).applied);
  const long filled = map.FillHoles();
  EXPECT_GT(filled, 0);
  const GridMap& g = map.map();
  for (GridMapIterator it(g); !it.done(); ++it) {
    const Eigen::Vector2d p = g.PositionOf(*it);
    const double to_a = (p - Eigen::Vector2d(-2.5, 0.5)).norm();
    const double to_b = (p - Eigen::Vector2d(2.5, 0.5)).norm();
    if (std::min(to_a, to_b) < 1e-9) {
      EXPECT_EQ(g.at("filled", *it), 0.0f);
      continue;
    }
    if (std::min(to_a, to_b) > 2.5 + 1e-9) {
      EXPECT_TRUE(std::isnan(g.at("elevation", *it)));
      continue;
    }
    EXPECT_EQ(g.at("filled", *it), 1.0f);
    if (std::abs(to_a - to_b) > 1e-6) {
      EXPECT_EQ(g.at("elevation", *it), to_a < to_b ? 1.0f : 3.0f);  // Eq. (9)
    }
  }
}

}  // namespace
}  // namespace autoshovel::perception
