// A user's own scans into the map (issue 43, runtime/perception/scan/): synthetic scans of a
// heap of known volume, taken the way a handheld or tripod LiDAR records them (the scanner's
// frame with z along its range axis, the floor tilted in it, range noise), must give that
// volume back.
#include "runtime/perception/scan/scan_map.h"

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>

#include "identification/camera_lidar/point_cloud_io.h"
#include "runtime/perception/scan/geotiff_export.h"
#include "runtime/perception/scan/scan_poses.h"
#include "tests/perception/synthetic_scan.h"

namespace autoshovel::perception {
namespace {

constexpr double kPi = std::numbers::pi;

// A cone heap of radius R and height H on the floor z = 0 (world, z up), around the origin.
struct ConeHeap {
  double radius = 1.0, height = 0.6;
  double Surface(double x, double y) const {
    return std::max(0.0, height * (1.0 - std::hypot(x, y) / radius));
  }
  double Volume() const { return kPi * radius * radius * height / 3.0; }
};

// Scans the cone heap on the floor z = 0 (synthetic_scan.h).
ScanCloud Scan(const ConeHeap& heap, const Eigen::Vector3d& scanner, const Eigen::Vector3d& target,
               unsigned seed, Eigen::Isometry3d& T_world_scanner) {
  return ScanSolid([&](const Eigen::Vector3d& p) { return p.z() <= heap.Surface(p.x(), p.y()); },
                   scanner, target, seed, T_world_scanner);
}

TEST(ScanMap, TwoScansOfAConeGiveItsVolume) {
  const ConeHeap heap;
  Eigen::Isometry3d T_world_a, T_world_b;
  ScanCloud a = Scan(heap, {-3.5, 0.3, 2.2}, {0, 0, 0.2}, 1, T_world_a);
  ScanCloud b = Scan(heap, {3.2, -0.6, 2.4}, {0, 0, 0.2}, 2, T_world_b);
  // The second scanner's pose in the first's frame, as a user's --pose gives it.
  b.T_first_scan = T_world_a.inverse() * T_world_b;
  const ScanMap map = BuildScanMap({a, b});
  ASSERT_TRUE(map.ok) << map.failure;
  // The floor is found facing up in the world (the scans' frames are tilted 30°).
  const Eigen::Vector3d up_world = T_world_a.linear() * map.ground.floor.normal;
  EXPECT_GT(up_world.z(), std::cos(0.5 * kPi / 180)) << up_world.transpose();
  ASSERT_FALSE(map.heaps.empty());
  const Heap& h = map.heaps.front();
  std::printf("cone: %.4f m^3 (+/- %.4f, filled %.4f) against %.4f; peak %.3f m; %zu heaps\n",
              h.volume, h.volume_sigma, h.filled_volume, heap.Volume(), h.peak, map.heaps.size());
  // Within 3 % (issue 43); the skirt below the heap threshold (1 cm) is a part of the error.
  EXPECT_NEAR(h.volume, heap.Volume(), 0.03 * heap.Volume());
  EXPECT_NEAR(h.peak, heap.height, 0.02);
  EXPECT_GT(h.volume_sigma, 0.0);
  EXPECT_LT(h.volume_sigma, 0.05 * heap.Volume());
}

// --reference: a scan of the place empty, from the same scanner pose, and one with the heap;
// the heap is what the second holds above the first.
TEST(ScanMap, AboveAReferenceScanOfTheEmptyPlace) {
  const ConeHeap heap;
  ConeHeap flat;
  flat.height = 0;
  Eigen::Isometry3d T_world_scanner;
  const ScanCloud full = Scan(heap, {-3.0, 0.4, 2.6}, {0, 0, 0.2}, 4, T_world_scanner);
  const ScanCloud empty = Scan(flat, {-3.0, 0.4, 2.6}, {0, 0, 0.2}, 5, T_world_scanner);
  const std::vector<ScanCloud> reference{empty};
  const ScanMap map = BuildScanMap({full}, {}, &reference);
  ASSERT_TRUE(map.ok) << map.failure;
  ASSERT_FALSE(map.heaps.empty());
  const Heap& h = map.heaps.front();
  std::printf("cone above the empty scan: %.4f m^3 (filled %.4f) against %.4f\n", h.volume,
              h.filled_volume, heap.Volume());
  // One side only: the far side of the cone is hidden and filled (Eq. 9) from the near one.
  EXPECT_NEAR(h.volume, heap.Volume(), 0.10 * heap.Volume());
  EXPECT_GT(h.filled_volume, 0.0);
}

// The GeoTIFF export: heights, sigma and the filled flag at the right cells, row 0 north, the
// geotransform placing cell centres where the grid does; NaN where nothing is known.
TEST(ScanMap, GeoTiffHoldsTheMapWhereTheGridHasIt) {
  GridMap map(0.5, {3.0, 2.0}, {10.0, -4.0});
  map.Add("elevation");
  map.Add("variance");
  map.Add("filled", 0.f);
  const Index cell(1, 3);  // x = 8.75 + 0.5, y = −5 + 1.75
  map.at("elevation", cell) = 0.42f;
  map.at("variance", cell) = 0.0009f;
  map.at("filled", cell) = 1.f;
  const std::string path = (std::filesystem::temp_directory_path() / "scan_map_test.tif").string();
  WriteGeoTiff(path, map);
  GDALAllRegister();
  std::unique_ptr<GDALDataset> data(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
  ASSERT_TRUE(data);
  ASSERT_EQ(data->GetRasterXSize(), 6);
  ASSERT_EQ(data->GetRasterYSize(), 4);
  double t[6];
  data->GetGeoTransform(t);
  // The centre of pixel (column 1, row 4 − 1 − 3 = 0) is the grid's cell centre.
  const Eigen::Vector2d centre = map.PositionOf(cell);
  EXPECT_NEAR(t[0] + 1.5 * t[1], centre.x(), 1e-9);
  EXPECT_NEAR(t[3] + 0.5 * t[5], centre.y(), 1e-9);
  float v[3];
  for (int band = 1; band <= 3; ++band) {
    ASSERT_EQ(data->GetRasterBand(band)->RasterIO(GF_Read, 1, 0, 1, 1, &v[band - 1], 1, 1,
                                                  GDT_Float32, 0, 0),
              CE_None);
  }
  EXPECT_FLOAT_EQ(v[0], 0.42f);
  EXPECT_NEAR(v[1], 0.03f, 1e-6);
  EXPECT_FLOAT_EQ(v[2], 1.f);
  float unknown = 0;
  ASSERT_EQ(
      data->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 1, 1, &unknown, 1, 1, GDT_Float32, 0, 0),
      CE_None);
  EXPECT_TRUE(std::isnan(unknown));
}

// Real scans (tests/data/pile_scans/README.md): balls in a box above a scan of the empty box,
// the scanner's frame with z along its range axis. Three times the balls hold more than twice
// the volume, and 25 balls hold some.
TEST(ScanMap, RealScansOfBallsInABoxGrowWithTheBalls) {
  const std::string dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/tests/data/pile_scans/";
  auto read = [&](const std::string& name) {
    ScanCloud c;
    c.name = name;
    c.cloud = identification::ReadPointCloud(dir + name);
    return c;
  };
  const std::vector<ScanCloud> empty{read("empty_box.pcd")};
  ScanMapOptions options;
  options.cell = 0.01;  // 12 000 points over 0.5 m x 0.4 m
  const ScanMap few = BuildScanMap({read("balls_25.pcd")}, options, &empty);
  const ScanMap many = BuildScanMap({read("balls_75.pcd")}, options, &empty);
  ASSERT_TRUE(few.ok) << few.failure;
  ASSERT_TRUE(many.ok) << many.failure;
  auto total = [](const ScanMap& m) {
    double v = 0;
    for (const Heap& h : m.heaps) v += h.volume;
    return v;
  };
  std::printf("25 balls %.5f m^3, 75 balls %.5f m^3\n", total(few), total(many));
  EXPECT_GT(total(few), 0.001);  // 25 balls of ≈ 6 cm under their surface: ≈ 2.5 litres
  EXPECT_GT(total(many), 2.0 * total(few));
  EXPECT_LT(total(many), 4.0 * total(few));
}

// A poses file places the second station as --pose does: the same volume as the test above.
TEST(ScanMap, APosesFilePlacesTheStations) {
  const ConeHeap heap;
  Eigen::Isometry3d T_world_a, T_world_b;
  ScanCloud a = Scan(heap, {-3.5, 0.3, 2.2}, {0, 0, 0.2}, 1, T_world_a);
  ScanCloud b = Scan(heap, {3.2, -0.6, 2.4}, {0, 0, 0.2}, 2, T_world_b);
  const Eigen::Isometry3d T_a_b = T_world_a.inverse() * T_world_b;
  const Eigen::Vector3d t = T_a_b.translation();
  // Roll, pitch, yaw of R = Rz Ry Rx, in degrees.
  const Eigen::Matrix3d& R = T_a_b.linear();
  const double pitch = std::asin(-R(2, 0)) * 180 / kPi;
  const double roll = std::atan2(R(2, 1), R(2, 2)) * 180 / kPi;
  const double yaw = std::atan2(R(1, 0), R(0, 0)) * 180 / kPi;
  char text[256];
  std::snprintf(
      text, sizeof text,
      "name,x,y,z,roll,pitch,yaw\na.pcd,0,0,0,0,0,0\nb.pcd,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f\n", t.x(),
      t.y(), t.z(), roll, pitch, yaw);
  const auto poses = ParseScanPoses(text, "poses.csv");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_LT((poses.at("b.pcd").matrix() - T_a_b.matrix()).cwiseAbs().maxCoeff(), 1e-6);
  b.T_first_scan = poses.at("b.pcd");
  const ScanMap map = BuildScanMap({a, b});
  ASSERT_TRUE(map.ok) << map.failure;
  EXPECT_NEAR(map.heaps.front().volume, heap.Volume(), 0.03 * heap.Volume());
}

TEST(ScanMap, ACloudWithoutAFloorIsToldSo) {
  // Points on a sphere only: no plane holds 5 % of them.
  ScanCloud ball;
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    Eigen::Vector3d p(n(rng), n(rng), n(rng));
    sensors::LidarPoint point;
    point.p_sensor = (Eigen::Vector3d(0, 0, 5) + 0.5 * p.normalized()).cast<float>();
    ball.cloud.points.push_back(point);
  }
  const ScanMap map = BuildScanMap({ball});
  EXPECT_FALSE(map.ok);
  EXPECT_NE(map.failure.find("no floor"), std::string::npos) << map.failure;
}

}  // namespace
}  // namespace autoshovel::perception
