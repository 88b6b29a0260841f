// A storage bin scanned the way a site scans one (issue 43): a floor, three walls and the
// material, recorded in a Livox-style scanner frame (z along the range axis) with range noise.
// The floor and the walls must be found, the volume of a heap of spheres come back within 3 %,
// a scan of the empty bin taken from another tripod set-up be registered before it is
// subtracted, a heaped fill be told from a drawn-down one, and a scan that shows no floor say so
// instead of measuring a heap's bumps as its volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>

#include "runtime/perception/scan/scan_map.h"
#include "tests/perception/synthetic_scan.h"

namespace autoshovel::perception {
namespace {

constexpr double kHalf = 1.5;        // the bin's floor: [−1.5, 1.5]² m
constexpr double kWallHeight = 1.5;  // [m]
constexpr double kWallThick = 0.1;   // [m], outside the floor
using Height = std::function<double(double, double)>;

struct Sphere {
  Eigen::Vector3d centre;
  double radius;
};

// The heap of spheres: the highest sphere top over (x, y), 0 where none reaches above the floor.
double SpheresHeight(const std::vector<Sphere>& spheres, double x, double y) {
  double h = 0;
  for (const Sphere& s : spheres) {
    const double d2 = std::pow(x - s.centre.x(), 2) + std::pow(y - s.centre.y(), 2);
    if (d2 < s.radius * s.radius)
      h = std::max(h, s.centre.z() + std::sqrt(s.radius * s.radius - d2));
  }
  return h;
}

const std::vector<Sphere>& HeapOfSpheres() {
  static const std::vector<Sphere> spheres{
      {{0.0, 0.0, -1.2}, 1.5}, {{0.6, 0.5, -1.0}, 1.2}, {{-0.3, -0.6, -0.8}, 1.0}};
  return spheres;
}

// The volume under a heightfield over the bin's floor, by a 2 mm midpoint sum (converged to far
// below the test's 3 %).
double VolumeOf(const Height& height) {
  constexpr double kStep = 0.002;
  double v = 0;
  for (double x = -kHalf + kStep / 2; x < kHalf; x += kStep) {
    for (double y = -kHalf + kStep / 2; y < kHalf; y += kStep) v += height(x, y);
  }
  return v * kStep * kStep;
}

// Solid: the floor (z ≤ 0 everywhere), the material inside the bin, and the back (x = +1.5) and
// side (y = ±1.5) walls; the front is open, where the scanner stands.
bool Solid(const Height& material, const Eigen::Vector3d& p) {
  if (p.z() <= 0) return true;
  const bool inside = std::abs(p.x()) <= kHalf && std::abs(p.y()) <= kHalf;
  if (inside) return p.z() <= material(p.x(), p.y());
  if (p.z() > kWallHeight || p.x() < -kHalf || p.x() > kHalf + kWallThick ||
      std::abs(p.y()) > kHalf + kWallThick) {
    return false;
  }
  return p.x() > kHalf || std::abs(p.y()) > kHalf;
}

// A scan from `scanner` towards `target`: a ray per 3 mrad over ±0.6 × ±0.45 rad, 3 mm range
// noise (synthetic_scan.h).
ScanCloud ScanBin(const Height& material, const Eigen::Vector3d& scanner,
                  const Eigen::Vector3d& target, unsigned seed,
                  Eigen::Isometry3d& T_world_scanner) {
  ScanPattern pattern;
  pattern.half_a = 0.6, pattern.half_b = 0.45, pattern.step = 0.003;
  pattern.march = 0.02, pattern.near = 0.1, pattern.far = 15, pattern.bisections = 25;
  return ScanSolid([&](const Eigen::Vector3d& p) { return Solid(material, p); }, scanner, target,
                   seed, T_world_scanner, pattern);
}

const Eigen::Vector3d kScanner(-2.0, 0.2, 4.5), kTarget(0.4, 0.0, 0.3);

double Total(const ScanMap& map) {
  double v = 0;
  for (const Heap& h : map.heaps) v += h.volume;
  return v;
}

TEST(ScanBin, FloorWallsAndTheVolumeOfAHeapOfSpheres) {
  const Height heap = [](double x, double y) { return SpheresHeight(HeapOfSpheres(), x, y); };
  Eigen::Isometry3d T_world_scanner;
  const ScanCloud scan = ScanBin(heap, kScanner, kTarget, 1, T_world_scanner);
  const ScanMap map = BuildScanMap({scan});
  ASSERT_TRUE(map.ok) << map.failure;
  ASSERT_TRUE(map.floor_found) << map.failure;
  const Eigen::Vector3d up = T_world_scanner.linear() * map.ground.floor.normal;
  EXPECT_GT(up.z(), std::cos(0.5 * std::numbers::pi / 180)) << up.transpose();
  // The back wall and both side walls, each upright and facing into the bin.
  ASSERT_EQ(map.ground.walls.size(), 3u);
  for (const ScanPlane& wall : map.ground.walls) {
    const Eigen::Vector3d n = T_world_scanner.linear() * wall.normal;
    EXPECT_LT(std::abs(n.z()), 0.02) << n.transpose();
  }
  const double truth = VolumeOf(heap);
  ASSERT_EQ(map.heaps.size(), 1u);
  std::printf("heap of spheres: %.4f m^3 (+/- %.4f, floor %.4f, filled %.4f) against %.4f; %s\n",
              map.heaps[0].volume, map.heaps[0].volume_sigma, map.heaps[0].floor_bias,
              map.heaps[0].filled_volume, truth, map.heaps[0].form.name.c_str());
  EXPECT_NEAR(map.heaps[0].volume, truth, 0.03 * truth);
  EXPECT_EQ(map.heaps[0].form.name, "heaped");
  EXPECT_GT(map.heaps[0].floor_bias, 0.0);
}

// The empty bin scanned again from a tripod set up 12 cm and 3° away, its pose not given:
// registered, then subtracted, it gives the heap's volume; the registration finds the set-up.
TEST(ScanBin, AnEmptyScanFromAnotherSetUpIsRegisteredFirst) {
  const Height heap = [](double x, double y) { return SpheresHeight(HeapOfSpheres(), x, y); };
  const Height empty = [](double, double) { return 0.0; };
  Eigen::Isometry3d T_world_full, T_world_empty;
  const ScanCloud full = ScanBin(heap, kScanner, kTarget, 2, T_world_full);
  const ScanCloud reference = ScanBin(empty, kScanner + Eigen::Vector3d(0.08, -0.09, 0.02),
                                      kTarget + Eigen::Vector3d(0.0, 0.25, -0.1), 3, T_world_empty);
  const Eigen::Isometry3d T_full_empty = T_world_full.inverse() * T_world_empty;
  ASSERT_GT(Eigen::AngleAxisd(T_full_empty.linear()).angle(), 2.5 * std::numbers::pi / 180);
  const std::vector<ScanCloud> references{reference};
  ScanMapOptions registered;
  registered.register_reference = true;
  const ScanMap map = BuildScanMap({full}, registered, &references);
  ASSERT_TRUE(map.ok) << map.failure;
  ASSERT_TRUE(map.registration.has_value());
  const Eigen::Isometry3d error = map.registration->T_target_source * T_full_empty.inverse();
  std::printf("registration: overlap %.2f, rms %.1f mm; error %.3f deg, %.1f mm\n",
              map.registration->overlap, 1e3 * map.registration->rms,
              Eigen::AngleAxisd(error.linear()).angle() * 180 / std::numbers::pi,
              1e3 * error.translation().norm());
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle(), 0.1 * std::numbers::pi / 180);
  EXPECT_LT(error.translation().norm(), 0.01);
  const double truth = VolumeOf(heap);
  std::printf("above the registered empty scan: %.4f m^3 against %.4f\n", Total(map), truth);
  EXPECT_NEAR(Total(map), truth, 0.03 * truth);

  // Without registration the same reference is 3° off: the volume is not to be trusted.
  const ScanMap off = BuildScanMap({full}, {}, &references);
  ASSERT_TRUE(off.ok) << off.failure;
  EXPECT_GT(std::abs(Total(off) - truth), 0.05 * truth) << Total(off);
}

TEST(ScanBin, AReferenceOfAnotherPlaceIsRefused) {
  const Height heap = [](double x, double y) { return SpheresHeight(HeapOfSpheres(), x, y); };
  Eigen::Isometry3d T_world_scanner;
  const ScanCloud full = ScanBin(heap, kScanner, kTarget, 4, T_world_scanner);
  ScanCloud ball;  // points on a sphere 5 m off: nothing of the bin
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d p(n(rng), n(rng), n(rng));
    sensors::LidarPoint point;
    point.p_sensor = (Eigen::Vector3d(0, 0, 5) + 0.5 * p.normalized()).cast<float>();
    ball.cloud.points.push_back(point);
  }
  const std::vector<ScanCloud> references{ball};
  ScanMapOptions registered;
  registered.register_reference = true;
  const ScanMap map = BuildScanMap({full}, registered, &references);
  EXPECT_FALSE(map.ok);
  EXPECT_NE(map.failure.find("does not match"), std::string::npos) << map.failure;
}

// A bin drawn down through an outlet in its floor: full to 0.9 m along the walls, a crater in
// the middle. Told from the heaped one by its form, with the floor in view and without.
TEST(ScanBin, ADrawnDownFillIsToldFromAHeapedOne) {
  const Height crater = [](double x, double y) {
    return std::clamp(0.25 + 0.6 * std::hypot(x - 0.1, y) / 1.2, 0.0, 0.9);
  };
  Eigen::Isometry3d T_world_scanner;
  const ScanCloud scan = ScanBin(crater, kScanner, kTarget, 6, T_world_scanner);
  const ScanMap map = BuildScanMap({scan});
  ASSERT_TRUE(map.ok) << map.failure;
  ASSERT_TRUE(map.floor_found) << map.failure;
  ASSERT_FALSE(map.heaps.empty());
  std::printf("drawn down: %.4f m^3 against %.4f; form %s (%+.3f m); %zu walls, %zu heaps\n",
              map.heaps[0].volume, VolumeOf(crater), map.heaps[0].form.name.c_str(),
              map.heaps[0].form.height, map.ground.walls.size(), map.heaps.size());
  EXPECT_EQ(map.heaps[0].form.name, "drawn down");
  // Its walls are found though the material hides most of them, and bound the heap.
  EXPECT_EQ(map.ground.walls.size(), 3u);
  EXPECT_NEAR(map.heaps[0].volume, VolumeOf(crater), 0.03 * VolumeOf(crater));
}

// Only the material's top surface, as the site bins' scans come (walls and floor cleaned away,
// a surface bumpy everywhere): no plane has the scene above it, so there is no floor and no
// volume, but the surface's form is still read. (A smooth dome with a clean rim would pass for a
// floor at its rim's level: scan_ground.h.)
TEST(ScanBin, ASurfaceWithoutFloorHasAFormButNoVolume) {
  auto bumps = [](double x, double y) { return 0.1 * std::sin(3.1 * x) * std::sin(2.7 * y + 0.4); };
  const Height dome = [&](double x, double y) {
    return 0.4 + 0.5 * (1 - (x * x + y * y) / (2 * kHalf * kHalf)) + bumps(x, y);
  };
  const Height crater = [&](double x, double y) {
    return std::clamp(0.25 + 0.6 * std::hypot(x - 0.1, y) / 1.2, 0.0, 0.9) + bumps(x, y);
  };
  for (const auto& [height, form] : {std::pair{dome, "heaped"}, std::pair{crater, "drawn down"}}) {
    Eigen::Isometry3d T_world_scanner;
    ScanCloud scan = ScanBin(height, kScanner, kTarget, 7, T_world_scanner);
    // Keep the material inside the bin, 5 cm in from the walls: the top surface alone.
    std::erase_if(scan.cloud.points, [&](const sensors::LidarPoint& p) {
      const Eigen::Vector3d w = T_world_scanner * p.p_sensor.cast<double>();
      return std::abs(w.x()) > kHalf - 0.05 || std::abs(w.y()) > kHalf - 0.05 || w.z() < 0.05;
    });
    const ScanMap map = BuildScanMap({scan});
    ASSERT_TRUE(map.ok) << map.failure;
    std::printf("surface only (%s): floor %d, form %s (%+.3f m, spread %.3f m)\n", form,
                map.floor_found, map.surface_form.name.c_str(), map.surface_form.height,
                map.surface_form.spread);
    EXPECT_FALSE(map.floor_found);
    EXPECT_TRUE(map.heaps.empty());
    EXPECT_NE(map.failure.find("no floor in view"), std::string::npos) << map.failure;
    EXPECT_EQ(map.surface_form.name, form);
  }
}

// The floor given by the user where the scan does not show it: the surface-only scan of the
// heap of spheres, with the bin's floor plane in the scanner's frame, gives the volume again.
TEST(ScanBin, AGivenFloorMeasuresASurfaceOnlyScan) {
  const Height heap = [](double x, double y) { return SpheresHeight(HeapOfSpheres(), x, y); };
  Eigen::Isometry3d T_world_scanner;
  ScanCloud scan = ScanBin(heap, kScanner, kTarget, 8, T_world_scanner);
  std::erase_if(scan.cloud.points, [&](const sensors::LidarPoint& p) {
    const Eigen::Vector3d w = T_world_scanner * p.p_sensor.cast<double>();
    return std::abs(w.x()) > kHalf - 0.02 || std::abs(w.y()) > kHalf - 0.02 || w.z() < 0.02;
  });
  // The world floor z = 0 in the scanner's frame: n_s · p_s = d with n_s = Rᵀ e_z, d = −n_s · R^T
  // t.
  const Eigen::Vector3d n = T_world_scanner.linear().transpose() * Eigen::Vector3d::UnitZ();
  const double d = -n.dot(T_world_scanner.linear().transpose() * T_world_scanner.translation());
  ScanMapOptions options;
  options.ground.floor = Eigen::Vector4d(2 * n.x(), 2 * n.y(), 2 * n.z(), 2 * d);  // not unit
  // The scan shows no floor to read a noise off: the heaps' threshold is given.
  options.min_heap_height = 0.01;
  const ScanMap map = BuildScanMap({scan}, options);
  ASSERT_TRUE(map.ok) << map.failure;
  ASSERT_TRUE(map.floor_found);
  EXPECT_TRUE(map.ground.floor_given);
  const double truth = VolumeOf(heap);
  std::printf("given floor: %.4f m^3 against %.4f\n", Total(map), truth);
  EXPECT_NEAR(Total(map), truth, 0.03 * truth);
}

}  // namespace
}  // namespace autoshovel::perception
