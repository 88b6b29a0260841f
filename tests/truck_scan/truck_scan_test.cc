// The truck seen from the excavator on its bench (excavator seed §2, §4.1, §4.3), the scene of
// `autoshovel run truck_loading`: the left scanner of the shipped 25 t excavator, simulated
// down to the return waveform with trailing-edge detection, recognises trucks of three sizes on
// the haul road 2 m below, reports nothing on an empty road, and maps soil in the bed.
//
// Cost: a first-pass scan (FirstPassScan at 42°/s) fires 33 860 pulses, about 1.3 s on one
// core of the build machine (≈ 37 µs per simulated waveform); the suite runs ten scans.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "runtime/app/truck_scan/truck_placement.h"
#include "runtime/app/truck_scan/truck_scanner.h"
#include "runtime/app/truck_scan/world_rangefinder_scene.h"
#include "runtime/sensors/raycast.h"
#include "truck_scan_test_support.h"

namespace autoshovel::app {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kSwingRate = 42 * kDeg;  // peak swing of the standard 90° pass
                                          // (docs/excavator_scripts.md)

TruckScannerConfig LeftScanner() {
  TruckScannerConfig config;
  config.scanner = ScannerConfigFromDescription(testing::Excavator25t(), "left_scanner");
  return config;
}

double YawError(double a, double b) {
  return std::abs(std::remainder(a - b, 2 * std::numbers::pi));
}

struct Case {
  TruckClass truck;
  Eigen::Vector2d p_bed;
  double yaw_deg;
};

struct Outcome {
  bool found = false;
  bool below = false;
  double position_error = 0;  ///< 3-D, bed frame origin [m]
  double yaw_error = 0;       ///< [rad]
  double length_error = 0, width_error = 0, corner_error = 0;
  double max_step = 0;  ///< scan-plane azimuth per revolution [rad]
  long pulses = 0;
  double seconds = 0;
  std::string reason;
};

// The truck on the road below the bench, the first pass's scan, recognition.
Outcome ScanCase(const Case& c, const std::vector<TruckScanMotion>& phases, std::uint64_t seed,
                 const TruckPlacementOptions& options = {},
                 const TruckScannerConfig& config = LeftScanner()) {
  plant::World world = testing::MakeBenchYard({}, testing::Excavator25t());
  const TruckPlacement truth =
      PlaceTruck(TruckBodyOf(c.truck), {c.p_bed, c.yaw_deg * kDeg, -2.0}, &world, options);
  const sensors::RaycastScene raycast(world);
  const WorldRangefinderScene scene(raycast);
  const TruckScanner scanner(config);
  sensors::Rng rng(seed);
  const auto start = std::chrono::steady_clock::now();
  const TruckScanReport report =
      scanner.ScanAndRecognize(scene, Eigen::Isometry3d::Identity(), phases, rng);
  Outcome o;
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.pulses = static_cast<long>(report.scan.pulses_fired);
  o.max_step = report.scan.max_azimuth_step;
  const perception::TruckRecognitionResult& r = report.recognition;
  o.found = r.found;
  o.below = report.truck_below_machine;
  o.reason = r.reason;
  if (r.found) {
    o.position_error = (r.T_world_bed.translation() - truth.T_world_bed.translation()).norm();
    o.yaw_error = YawError(r.YawRad(), truth.pose.yaw);
    o.length_error = r.dimensions.length - truth.inner_length;
    o.width_error = r.dimensions.width - truth.inner_width;
    for (int i = 0; i < 4; ++i) {
      o.corner_error =
          std::max(o.corner_error, (r.p_world_corners[i] - truth.p_world_corners[i]).norm());
    }
  }
  return o;
}

std::vector<TruckScanMotion> FirstPass() {
  return FirstPassScan(LeftScanner().scanner, 0.0, 90 * kDeg, kSwingRate);
}

TEST(TruckScan, RecognisesTrucksBelowTheBenchFromTheLeftScanner) {
  // Bed centres 5.6 m (tippers) and 6.0 m (hauler) to the left, from 1 m aft of abeam to 1.5 m
  // ahead, cab forward or back, turned by up to 10°.
  const std::vector<Case> cases = {
      {TruckClass::kTipper15t, {0.0, 5.6}, 0},  {TruckClass::kTipper15t, {1.5, 5.6}, 190},
      {TruckClass::kTipper20t, {-1.0, 5.6}, 0}, {TruckClass::kTipper20t, {0.0, 5.6}, 180},
      {TruckClass::kTipper20t, {0.5, 5.6}, 10}, {TruckClass::kHauler38t, {0.0, 6.0}, 180},
      {TruckClass::kHauler38t, {1.0, 6.0}, -10}};
  const std::vector<TruckScanMotion> phases = FirstPass();
  std::uint64_t seed = 11;
  for (const Case& c : cases) {
    const Outcome o = ScanCase(c, phases, seed++);
    std::printf(
        "[truck_scan] %-24s bed (%4.1f, %3.1f) yaw %4.0f°: found %d below %d  position %.3f m  "
        "yaw %.2f°  length %+.3f  width %+.3f  corners %.3f m  (%ld pulses, step %.2f°, %.1f s)\n",
        std::string(ToString(c.truck)).c_str(), c.p_bed.x(), c.p_bed.y(), c.yaw_deg, o.found,
        o.below, o.position_error, o.yaw_error / kDeg, o.length_error, o.width_error,
        o.corner_error, o.pulses, o.max_step / kDeg, o.seconds);
    SCOPED_TRACE(std::string(ToString(c.truck)) + " at yaw " + std::to_string(c.yaw_deg));
    ASSERT_TRUE(o.found) << o.reason;
    EXPECT_TRUE(o.below);  // found with the bench's returns withheld
    EXPECT_LT(o.position_error, 0.10);
    EXPECT_LT(o.yaw_error, 2 * kDeg);
    EXPECT_LT(std::abs(o.length_error), 0.15);  // the recogniser's own bound (0.142 m)
    EXPECT_LT(std::abs(o.width_error), 0.10);
    EXPECT_LT(o.corner_error, 0.15);
    EXPECT_LE(o.max_step, kMaxRecognitionPanStep * 1.001);
  }
}

TEST(TruckScan, ReportsNoTruckOnAnEmptyRoad) {
  plant::World world = testing::MakeBenchYard({}, testing::Excavator25t());
  const sensors::RaycastScene raycast(world);
  const WorldRangefinderScene scene(raycast);
  const TruckScanner scanner(LeftScanner());
  sensors::Rng rng(5);
  const TruckScanReport report =
      scanner.ScanAndRecognize(scene, Eigen::Isometry3d::Identity(), FirstPass(), rng);
  std::printf("[truck_scan] empty road: found %d (%s); %ld of %ld pulses returned\n",
              report.recognition.found, report.recognition.reason.c_str(),
              static_cast<long>(report.scan.points), static_cast<long>(report.scan.pulses_fired));
  EXPECT_FALSE(report.recognition.found);
  EXPECT_FALSE(report.bed_map);
  EXPECT_GT(report.scan.points, 10000);  // the yard was seen
}

TEST(TruckScan, PanRangeAloneDoesNotReportATruckReachingPastIt) {
  // The 20 t tipper 1 m aft of abeam: with the pan alone (to 120°) its near wall's rear end
  // (at 141° from the scanner) is never swept. Recognition would take the last scanline for the
  // rear (the bed 1.1 m short); the coverage check refuses it.
  const Outcome o =
      ScanCase({TruckClass::kTipper20t, {-1.0, 5.6}, 0},
               {PanAcross(LeftScanner().scanner, 0.0, 0.0, 120 * kDeg, 0.8 * kDeg)}, 3);
  std::printf("[truck_scan] pan alone, 20 t 1 m aft: found %d (%s)\n", o.found, o.reason.c_str());
  EXPECT_FALSE(o.found);
  EXPECT_NE(o.reason.find("edge of the scan"), std::string::npos) << o.reason;
}

TEST(TruckScan, BedMapShowsSoilWhereItLies) {
  // The scene's 20 t tipper, cab forward, recognised empty; then a block of soil in the far half
  // of its bed, measured while the excavator swings back from the truck (§2, §4.3).
  plant::World world = testing::MakeBenchYard({}, testing::Excavator25t());
  const TruckPlacement truth =
      PlaceTruck(TruckBodyOf(TruckClass::kTipper20t), {{0.5, 5.6}, 0.0, -2.0}, &world);
  sensors::RaycastScene raycast(world);
  const WorldRangefinderScene scene(raycast);
  const TruckScanner scanner(LeftScanner());
  sensors::Rng rng(21);
  const TruckScanReport first =
      scanner.ScanAndRecognize(scene, Eigen::Isometry3d::Identity(), FirstPass(), rng);
  ASSERT_TRUE(first.recognition.found) << first.recognition.reason;
  ASSERT_TRUE(first.bed_map);

  // Soil as terrain material on the bed floor: a levelled first load 0.35 m deep, and on it a
  // heap 0.6 m higher over x ∈ [2.0, 4.0] m, y ∈ [0.9, 2.35] m of the bed-corner frame (up to
  // the far wall).
  const Eigen::Isometry3d T_corner_world = truth.T_world_bed_corner().inverse();
  const double layer = 0.35, heap = 0.6;
  const auto in_heap = [](const Eigen::Vector2d& p, double margin) {
    return p.x() > 2.0 + margin && p.x() < 4.0 - margin && p.y() > 0.9 + margin &&
           p.y() < 2.35 - margin;
  };
  plant::Terrain& terrain = world.terrain;
  const double volume_before = terrain.MaterialVolume();
  double depth_sum = 0;
  for (const int i : truth.floor_cells) {
    const int ix = i % terrain.nx(), iy = i / terrain.nx();
    const Eigen::Vector2d c = terrain.CellCenter(ix, iy);
    const bool on_heap = in_heap((T_corner_world * Eigen::Vector3d(c.x(), c.y(), 0)).head<2>(), 0);
    terrain.SetHeight(ix, iy, truth.floor_z + layer + (on_heap ? heap : 0.0));
    terrain.SetMaterial(ix, iy, 0);
    depth_sum += layer + (on_heap ? heap : 0.0);
  }
  // The bed's bookkeeping counts exactly what was put on its floor, and the yard's agrees.
  EXPECT_NEAR(truth.MaterialInBed(terrain), depth_sum * terrain.cell_area(), 1e-9);
  EXPECT_NEAR(truth.MaterialInBed(terrain), terrain.MaterialVolume() - volume_before, 1e-9);
  raycast.UpdateTerrain(0, 0, terrain.nx() - 1, terrain.ny() - 1);

  // Swinging back from the truck (90° → 0 at 42°/s) while the scan plane crosses the bed
  // from 130° to 50° (1.9° per revolution).
  const TruckScanMotion back = SwingWithCounterPan(scanner.config().scanner, 90 * kDeg, 0.0,
                                                   kSwingRate, 130 * kDeg, 50 * kDeg, 20.0);
  const planning::BedHeightMap map =
      scanner.MeasureBed(scene, Eigen::Isometry3d::Identity(), back, first.recognition, rng);

  // Heights in the bed-corner frame: the rim is 0, the floor −1.15.
  const double layer_top = -truth.wall_height + layer;
  const double heap_top = layer_top + heap;
  int heap_known = 0, heap_cells = 0, layer_known = 0;
  double heap_error = 0, layer_error = 0;
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      const Eigen::Vector2d c = map.CellCentre(ix, iy);
      const double half = 0.5 * map.cell_size_m();
      if (in_heap(c, half + 0.05)) {
        ++heap_cells;
        if (!map.known(ix, iy)) continue;
        ++heap_known;
        heap_error = std::max(heap_error, std::abs(map.height(ix, iy) - heap_top));
      } else if (!in_heap(c, -half - 0.1) && c.x() > 0.3 && c.x() < 5.5 && c.y() > 0.3 &&
                 c.y() < 2.05 && map.known(ix, iy)) {
        // Clear of the heap's flanks and of the walls: the levelled layer.
        ++layer_known;
        layer_error = std::max(layer_error, std::abs(map.height(ix, iy) - layer_top));
      }
    }
  }
  std::printf(
      "[truck_scan] bed map of the empty bed: %d of %d cells known; with soil: %d known, "
      "heap %d of %d cells known, |error| max %.3f m; layer %d cells known, |error| max "
      "%.3f m\n",
      first.bed_map->known_count(), map.cells_x() * map.cells_y(), map.known_count(), heap_known,
      heap_cells, heap_error, layer_known, layer_error);
  EXPECT_GE(heap_known, heap_cells / 2);
  EXPECT_LT(heap_error, 0.04);
  EXPECT_GE(layer_known, 10);
  EXPECT_LT(layer_error, 0.04);
}

// The figures of docs/truck_scan.md: every truck class at 3 positions × 4 headings, the
// first-pass scan, with and without the wall ring. About 45 s each.
void Sweep(const TruckPlacementOptions& options) {
  const std::vector<TruckScanMotion> phases = FirstPass();
  std::uint64_t seed = 100;
  for (const TruckClass t :
       {TruckClass::kTipper15t, TruckClass::kTipper20t, TruckClass::kHauler38t}) {
    int found = 0, total = 0;
    double pos_max = 0, pos_sum = 0, yaw_max = 0, length_max = 0, width_max = 0, corner_max = 0;
    for (const double x : {-1.0, 0.0, 1.5}) {
      for (const double yaw : {0.0, 180.0, 10.0, -170.0}) {
        const double y = t == TruckClass::kHauler38t ? 6.0 : 5.6;
        const Outcome o = ScanCase({t, {x, y}, yaw}, phases, seed++, options);
        ++total;
        if (!o.found) {
          std::printf("[truck_scan] %s at (%.1f, %.1f) yaw %.0f: not found (%s)\n",
                      std::string(ToString(t)).c_str(), x, y, yaw, o.reason.c_str());
          continue;
        }
        ++found;
        pos_max = std::max(pos_max, o.position_error);
        pos_sum += o.position_error;
        yaw_max = std::max(yaw_max, o.yaw_error);
        length_max = std::max(length_max, std::abs(o.length_error));
        width_max = std::max(width_max, std::abs(o.width_error));
        corner_max = std::max(corner_max, o.corner_error);
      }
    }
    std::printf(
        "[truck_scan] %-24s wall ring %d: found %d/%d  position mean %.3f max %.3f m  "
        "yaw max %.2f°  |length| %.3f  |width| %.3f  corners %.3f m\n",
        std::string(ToString(t)).c_str(), options.wall_cells_at_rim, found, total,
        found ? pos_sum / found : 0.0, pos_max, yaw_max / kDeg, length_max, width_max, corner_max);
    EXPECT_EQ(found, total);
  }
}

TEST(TruckScanSweep, DISABLED_AllClassesPositionsAndHeadings) { Sweep({}); }

TEST(TruckScanSweep, DISABLED_WithoutWallRing) {
  TruckPlacementOptions options;
  options.wall_cells_at_rim = false;
  Sweep(options);
}

// Where a pan-only scan at the dig (swing 0, pan 0 → pan_max at 0.8°/rev) suffices: the shipped
// ±120° and a head that pans to 155°. About 70 s.
TEST(TruckScanSweep, DISABLED_PanAloneCoverage) {
  for (const double pan_max_deg : {120.0, 155.0}) {
    TruckScannerConfig config = LeftScanner();
    config.scanner.pan_max = pan_max_deg * kDeg;
    const std::vector<TruckScanMotion> phases{
        PanAcross(config.scanner, 0.0, 0.0, pan_max_deg * kDeg, 0.8 * kDeg)};
    for (const TruckClass t :
         {TruckClass::kTipper15t, TruckClass::kTipper20t, TruckClass::kHauler38t}) {
      std::printf("[truck_scan] pan to %.0f°, %-24s", pan_max_deg,
                  std::string(ToString(t)).c_str());
      double pos_max = 0;
      for (const double x : {-1.0, 0.0, 1.0, 1.5, 2.0}) {
        for (const double yaw : {0.0, 180.0}) {
          const double y = t == TruckClass::kHauler38t ? 6.0 : 5.6;
          const Outcome o = ScanCase({t, {x, y}, yaw}, phases, 300, {}, config);
          std::printf(" x=%+.1f/%3.0f°:%s", x, yaw, o.found ? "found" : "-");
          if (o.found) pos_max = std::max(pos_max, o.position_error);
        }
      }
      std::printf("  (position error max %.3f m)\n", pos_max);
    }
  }
}

}  // namespace
}  // namespace autoshovel::app
