// The truck in the world (excavator seed §4.1, §4.3): boxes of another machine, the bed floor
// as raised terrain floor with no material on it, the wall ring, the truth frames, and the
// world as the rangefinders' scene.
#include "runtime/app/truck_scan/truck_placement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "runtime/app/truck_scan/truck_scanner.h"
#include "runtime/app/truck_scan/world_rangefinder_scene.h"
#include "runtime/sensors/raycast.h"
#include "truck_scan_test_support.h"

namespace autoshovel::app {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Placed {
  plant::World world;
  TruckPlacement truck;
};

Placed PlaceOnRoad(TruckClass truck_class, const Eigen::Vector2d& p_bed, double yaw,
                   const TruckPlacementOptions& options = {}) {
  Placed p{testing::MakeBenchYard({}, testing::Excavator25t()), {}};
  p.truck = PlaceTruck(TruckBodyOf(truck_class), {p_bed, yaw, -2.0}, &p.world, options);
  return p;
}

TEST(TruckPlacement, RaisesTheFloorUnderTheBedWithoutMaterial) {
  for (const TruckClass c :
       {TruckClass::kTipper15t, TruckClass::kTipper20t, TruckClass::kHauler38t}) {
    plant::World world = testing::MakeBenchYard({}, testing::Excavator25t());
    const double volume_before = world.terrain.MaterialVolume();
    const TruckBody body = TruckBodyOf(c);
    const TruckPlacement t = PlaceTruck(body, {{0.4, 5.9}, 17 * kDeg, -2.0}, &world);
    SCOPED_TRACE(body.name);
    const plant::Terrain& terrain = world.terrain;
    // Placing a truck moves no material: the bookkeeping of later dumps starts from here.
    EXPECT_NEAR(terrain.MaterialVolume(), volume_before, 1e-12);
    EXPECT_EQ(t.MaterialInBed(terrain), 0.0);
    EXPECT_NEAR(t.floor_z, -2.0 + body.floor_height, 1e-12);
    EXPECT_NEAR(t.rim_z, -2.0 + body.rim_height(), 1e-12);
    // Every cell whose centre lies in the opening carries the bed floor, and only those.
    const double cell_area = terrain.cell_area();
    EXPECT_NEAR(t.floor_cells.size() * cell_area, body.inner_length * body.inner_width,
                2 * (body.inner_length + body.inner_width) * terrain.resolution());
    for (const int i : t.floor_cells) {
      const Eigen::Vector2d c_xy = terrain.CellCenter(i % terrain.nx(), i / terrain.nx());
      EXPECT_TRUE(t.InsideBed(c_xy.x(), c_xy.y()));
      EXPECT_EQ(terrain.floors()[i], t.floor_z);
      EXPECT_EQ(terrain.heights()[i], t.floor_z);
    }
    for (const int i : t.wall_cells) {
      const Eigen::Vector2d c_xy = terrain.CellCenter(i % terrain.nx(), i / terrain.nx());
      EXPECT_FALSE(t.InsideBed(c_xy.x(), c_xy.y()));
      EXPECT_EQ(terrain.floors()[i], t.rim_z);
    }
    EXPECT_FALSE(t.wall_cells.empty());
    // The road next to the truck is untouched.
    const Eigen::Vector3d p_road = t.T_world_bed * Eigen::Vector3d(0, body.inner_width, 0);
    EXPECT_NEAR(terrain.HeightAt(p_road.x(), p_road.y()), -2.0, 1e-12);
    // Soil dumped on the floor is terrain material in the bed.
    const int i = t.floor_cells[t.floor_cells.size() / 2];
    world.terrain.SetHeight(i % terrain.nx(), i / terrain.nx(), t.floor_z + 0.5);
    EXPECT_NEAR(t.MaterialInBed(world.terrain), 0.5 * cell_area, 1e-12);
  }
}

TEST(TruckPlacement, FramesCornersAndBoxes) {
  const Placed p = PlaceOnRoad(TruckClass::kTipper20t, {0.5, 5.6}, 180 * kDeg);
  const TruckPlacement& t = p.truck;
  // Bed frame: centre of the opening on the rim, x towards the cab.
  EXPECT_TRUE(t.T_world_bed.translation().isApprox(Eigen::Vector3d(0.5, 5.6, 0.7), 1e-12));
  EXPECT_TRUE(t.T_world_bed.linear().col(0).isApprox(Eigen::Vector3d(-1, 0, 0), 1e-12));
  // Corner frame: rear-right corner, the opening is [0, L] × [0, W].
  const Eigen::Vector3d p_rear_right = t.T_world_bed_corner().translation();
  EXPECT_TRUE(p_rear_right.isApprox(t.p_world_corners[2], 1e-12));
  EXPECT_TRUE((t.T_world_bed_corner() * Eigen::Vector3d(5.8, 2.35, 0))
                  .isApprox(t.p_world_corners[0], 1e-12));
  EXPECT_TRUE(t.InsideBed(0.5, 5.6));
  EXPECT_FALSE(t.InsideBed(0.5, 5.6 + 1.2));
  EXPECT_FALSE(t.InsideBed(0.5 - 3.0, 5.6));
  // Boxes: appended to the world, another machine (not a new class), named after the truck.
  EXPECT_EQ(p.world.obstacles.size(), t.boxes.size());
  EXPECT_EQ(t.boxes.size(), 13u);  // floor, 2 sides, headboard, tailgate, cab, chassis, 6 wheels
  for (const plant::OrientedBox& box : t.boxes) {
    EXPECT_EQ(box.semantic_class, core::SemanticClass::kOtherLoader);
    EXPECT_EQ(box.name.rfind("truck_", 0), 0u) << box.name;
    // Nothing of the truck below the road.
    EXPECT_GE(box.center.z() - box.half_extents.z(), -2.0 - 1e-12) << box.name;
  }
  // The hauler has no tailgate and no wall ring at its open rear.
  const Placed h = PlaceOnRoad(TruckClass::kHauler38t, {0.5, 6.0}, 0.0);
  EXPECT_EQ(h.truck.boxes.size(), 12u);
  for (const int i : h.truck.wall_cells) {
    const Eigen::Vector2d c =
        h.world.terrain.CellCenter(i % h.world.terrain.nx(), i / h.world.terrain.nx());
    EXPECT_GE((h.truck.T_world_bed.inverse() * Eigen::Vector3d(c.x(), c.y(), 0)).x(), -3.1);
  }
}

TEST(TruckPlacement, RefusesImpossiblePlacements) {
  plant::World world = testing::MakeBenchYard({}, testing::Excavator25t());
  const TruckBody body = TruckBodyOf(TruckClass::kTipper20t);
  // Into the bench: the terrain's floor there lies above the truck's bed floor.
  EXPECT_THROW(PlaceTruck(body, {{0, 2.0}, 0, -2.0}, &world), std::invalid_argument);
  // Off the grid.
  EXPECT_THROW(PlaceTruck(body, {{15.0, 8.0}, 0, -2.0}, &world), std::invalid_argument);
  // On a heap.
  int ix = 0, iy = 0;
  ASSERT_TRUE(world.terrain.CellOf(-5.0, 8.0, ix, iy));
  world.terrain.SetHeight(ix, iy, -1.5);
  EXPECT_THROW(PlaceTruck(body, {{-5.0, 8.0}, 0, -2.0}, &world), std::invalid_argument);
  TruckBody bad = body;
  bad.inner_width = -1;
  EXPECT_THROW(PlaceTruck(bad, {{0, 8.0}, 0, -2.0}, &world), std::invalid_argument);
  EXPECT_THROW(PlaceTruck(body, {{0, 8.0}, std::nan(""), -2.0}, &world), std::invalid_argument);
  EXPECT_THROW(PlaceTruck(body, {{0, 8.0}, 0, -2.0}, nullptr), std::invalid_argument);
  EXPECT_TRUE(world.obstacles.empty());  // nothing half placed
}

TEST(WorldRangefinderScene, SeesTerrainBoxesAndDust) {
  Placed p = PlaceOnRoad(TruckClass::kTipper20t, {0.0, 5.6}, 0.0);
  const sensors::RaycastScene raycast(p.world);
  WorldRangefinderScene scene(raycast);
  // Straight down onto the bench: range, the bare floor's reflectivity, normal incidence.
  sensors::RayProfile down = scene.Trace({-3, 0, 2.6}, {0, 0, -1}, 80);
  ASSERT_TRUE(down.solid);
  EXPECT_NEAR(down.solid->range, 2.6, 1e-9);
  EXPECT_NEAR(down.solid->reflectivity, p.world.ground_reflectivity, 1e-12);
  EXPECT_NEAR(down.solid->cos_incidence, 1.0, 1e-9);
  EXPECT_TRUE(down.dust.empty());
  // Down at 45° onto the side of the truck's cab (y = 5.6 − 2.3/2 = 4.45 m), 0.5 m up.
  const Eigen::Vector3d d = Eigen::Vector3d(0, 1, -1).normalized();
  const sensors::RayProfile side = scene.Trace({4.0, 0, 0.5 + 4.45}, d, 80);
  ASSERT_TRUE(side.solid);
  EXPECT_NEAR(side.solid->range, std::sqrt(2.0) * 4.45, 1e-9);
  EXPECT_NEAR(side.solid->reflectivity, 0.35, 1e-12);
  EXPECT_NEAR(side.solid->cos_incidence, std::sqrt(0.5), 1e-9);
  // A dust cloud straddling the bench surface: cut where the beam meets the ground.
  sensors::DustProperties dust;
  scene.AddDustSphere({-3, 0, 0.5}, 1.0, dust);
  down = scene.Trace({-3, 0, 2.6}, {0, 0, -1}, 80);
  ASSERT_EQ(down.dust.size(), 1u);
  EXPECT_NEAR(down.dust[0].range_begin, 1.1, 1e-9);
  EXPECT_NEAR(down.dust[0].range_end, 2.6, 1e-9);
  EXPECT_NEAR(down.dust[0].extinction, dust.extinction, 1e-12);
  sensors::ValidateRayProfile(down);
  scene.ClearDust();
  EXPECT_TRUE(scene.Trace({-3, 0, 2.6}, {0, 0, -1}, 80).dust.empty());
  // Into the sky: nothing.
  EXPECT_FALSE(scene.Trace({0, 0, 2.6}, {0, 0, 1}, 80).solid);
}

TEST(TruckScanner, ScannerMountsComeFromTheDescription) {
  const sensors::ScannerConfig left =
      ScannerConfigFromDescription(testing::Excavator25t(), "left_scanner");
  const sensors::ScannerConfig right =
      ScannerConfigFromDescription(testing::Excavator25t(), "right_scanner");
  // rpy (90°, 0, 0): the mirror spins about the cab's y axis, the head is level.
  EXPECT_TRUE(left.T_cab_scanner.linear().isIdentity(1e-12));
  EXPECT_TRUE(left.T_cab_scanner.translation().isApprox(Eigen::Vector3d(0.4, 0.8, 2.6), 1e-12));
  EXPECT_TRUE(right.T_cab_scanner.translation().isApprox(Eigen::Vector3d(0.4, -0.8, 2.6), 1e-12));
  // The library's own left-scanner mount agrees.
  EXPECT_TRUE(left.T_cab_scanner.isApprox(sensors::LeftScannerConfig().T_cab_scanner, 1e-12));
  EXPECT_THROW(ScannerConfigFromDescription(testing::Excavator25t(), "front_lidar"),
               std::invalid_argument);
}

TEST(TruckScanner, MotionsRespectThePanRangeAndRate) {
  const sensors::ScannerConfig sc = sensors::LeftScannerConfig();
  const TruckScanMotion pan = PanAcross(sc, 0.0, 0.0, 120 * kDeg, 0.8 * kDeg);
  EXPECT_NEAR(pan.pan.rate, 16 * kDeg, 1e-12);
  EXPECT_NEAR(pan.end_time, 7.5 + 0.05, 1e-9);
  EXPECT_THROW(PanAcross(sc, 0.0, 0.0, 150 * kDeg, 0.8 * kDeg), std::invalid_argument);
  EXPECT_THROW(PanAcross(sc, 0.0, 0.0, 90 * kDeg, 7 * kDeg), std::invalid_argument);  // 140°/s
  // Swinging back from the truck at 42°/s while the scan plane crosses the bed from 135° to
  // 45°: the pan turns from 45° to 45° — it holds.
  const TruckScanMotion back =
      SwingWithCounterPan(sc, 90 * kDeg, 0.0, 42 * kDeg, 135 * kDeg, 45 * kDeg, 1.0);
  EXPECT_NEAR(back.end_time - back.start_time, 90.0 / 42.0, 1e-9);
  EXPECT_NEAR(back.pan.rate, 0.0, 1e-12);
  // Holding the scan plane 60° to the right of the base while swinging 90° to the left needs
  // a pan of −150°, outside the ±120° range.
  EXPECT_THROW(SwingWithCounterPan(sc, 0.0, 90 * kDeg, 42 * kDeg, -60 * kDeg, -60 * kDeg),
               std::invalid_argument);
  const std::vector<TruckScanMotion> first = FirstPassScan(sc, 0.0, 90 * kDeg, 42 * kDeg);
  ASSERT_EQ(first.size(), 2u);
  EXPECT_EQ(first[1].start_time, first[0].end_time);
  EXPECT_NEAR(first[1].pan.start_angle, 120 * kDeg, 1e-12);
  EXPECT_NEAR(first[1].pan.end_angle, 65 * kDeg, 1e-12);
  // A working-speed swing would space the scanlines more than 1° apart: refused.
  EXPECT_THROW(FirstPassScan(sc, 0.0, 90 * kDeg, 80 * kDeg), std::invalid_argument);
  // Mirrored for a truck on the right.
  const std::vector<TruckScanMotion> right = FirstPassScan(sc, 0.0, -90 * kDeg, 42 * kDeg);
  EXPECT_NEAR(right[0].pan.end_angle, -120 * kDeg, 1e-12);
}

TEST(TruckScanner, StandingLevelFilterKeepsWalls) {
  // One scanline down the bench, over the crest, across a wall standing from −2 to +0.7 m.
  perception::Scanline line;
  line.p_world_sensor = {0, 0.8, 2.6};
  for (int i = 0; i < 30; ++i) line.points.push_back({{0, 1.5 + 0.05 * i, 0.001}, true});
  for (int i = 0; i < 55; ++i) line.points.push_back({{0, 4.3, -1.5 + 0.04 * i}, true});
  for (int i = 0; i < 34; ++i) line.points.push_back({{0, 4.3 + 0.05 * i, 0.7}, true});
  line.points.push_back({});  // a miss keeps its place
  const std::vector<perception::Scanline> out =
      WithoutStandingLevel({line}, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out[0].points.size(), line.points.size());
  int bench = 0, wall_kept = 0, top_kept = 0;
  for (std::size_t i = 0; i < line.points.size(); ++i) {
    const Eigen::Vector3d& p = line.points[i].p_world;
    if (!line.points[i].valid) continue;
    if (p.y() < 3.0) bench += out[0].points[i].valid ? 0 : 1;
    if (p.y() == 4.3 && p.z() < 0.7) wall_kept += out[0].points[i].valid ? 1 : 0;
    if (p.z() == 0.7) top_kept += out[0].points[i].valid ? 1 : 0;
  }
  EXPECT_EQ(bench, 30);      // every bench return withheld
  EXPECT_EQ(wall_kept, 55);  // the wall crossing z = 0 keeps all of its returns
  EXPECT_EQ(top_kept, 34);   // level, but 0.7 m above the standing level
}

}  // namespace
}  // namespace autoshovel::app
