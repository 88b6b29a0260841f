// Sensor health checks (issue 9): blind LiDAR sectors and dirt on the camera's lens, on
// synthetic data whose answer is known by construction.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "runtime/perception/lens_dirt_monitor.h"
#include "runtime/perception/lidar_health.h"

namespace autoshovel::perception {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// One ray per 0.5° of azimuth at `elevation`, sensor frame = body frame = world frame.
std::vector<Eigen::Vector3d> Fan(double elevation) {
  std::vector<Eigen::Vector3d> rays;
  for (double a = -179.75; a < 180; a += 0.5) {
    rays.emplace_back(std::cos(elevation) * std::cos(a * kDeg),
                      std::cos(elevation) * std::sin(a * kDeg), std::sin(elevation));
  }
  return rays;
}

// Returns for every ray whose azimuth is not in one of the silent intervals [deg].
sensors::PointCloud Returns(const std::vector<Eigen::Vector3d>& rays,
                            const std::vector<std::pair<double, double>>& silent) {
  sensors::PointCloud cloud;
  for (const Eigen::Vector3d& d : rays) {
    const double a = std::atan2(d.y(), d.x()) / kDeg;
    bool quiet = false;
    for (const auto& [from, to] : silent) quiet = quiet || (a >= from && a < to);
    if (quiet) continue;
    sensors::LidarPoint p;
    p.p_sensor = (10.0 * d).cast<float>();
    cloud.points.push_back(p);
  }
  return cloud;
}

LidarHealthConfig FewRays() {
  LidarHealthConfig c;
  c.min_expected_rays = 5;  // 10 rays per 5° bin in the fan
  return c;
}

TEST(LidarHealth, SilenceAmongDownwardRaysIsABlindSector) {
  const auto rays = Fan(-20 * kDeg);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_TRUE(BlindSectors(rays, Returns(rays, {}), I, I, FewRays()).empty());
  const auto sectors = BlindSectors(rays, Returns(rays, {{30, 50}}), I, I, FewRays());
  ASSERT_EQ(sectors.size(), 1u);
  EXPECT_NEAR(sectors[0].from / kDeg, 30, 1e-9);
  EXPECT_NEAR(sectors[0].to / kDeg, 50, 1e-9);
  EXPECT_TRUE(SectorFaces(sectors[0], 0.0, 35 * kDeg));  // 30° is within 35° of ahead
  EXPECT_FALSE(SectorFaces(sectors[0], 0.0, 25 * kDeg));
  EXPECT_FALSE(SectorFaces(sectors[0], std::numbers::pi, 60 * kDeg));
}

TEST(LidarHealth, ASectorAcrossTheRearIsOneSector) {
  const auto rays = Fan(-20 * kDeg);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const auto sectors =
      BlindSectors(rays, Returns(rays, {{170, 180}, {-180, -160}}), I, I, FewRays());
  ASSERT_EQ(sectors.size(), 1u);
  EXPECT_NEAR(sectors[0].from / kDeg, -190, 1e-9);
  EXPECT_NEAR(sectors[0].to / kDeg, -160, 1e-9);
  EXPECT_TRUE(SectorFaces(sectors[0], std::numbers::pi, 0.0));  // straight behind is inside
  EXPECT_FALSE(SectorFaces(sectors[0], 0.0, 60 * kDeg));
}

// Rays towards the sky may return nothing: silence there is not blindness.
TEST(LidarHealth, SilenceAboveTheHorizonIsNotBlindness) {
  const auto rays = Fan(+5 * kDeg);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_TRUE(BlindSectors(rays, Returns(rays, {{-180, 180}}), I, I, FewRays()).empty());
  // The same fan on a sensor pitched 30° down looks at the floor: now silence is blindness.
  const Eigen::Matrix3d R_world_sensor =
      Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto sectors = BlindSectors(rays, Returns(rays, {{-10, 10}}), I, R_world_sensor, FewRays());
  ASSERT_EQ(sectors.size(), 1u);
  EXPECT_NEAR(sectors[0].from / kDeg, -10, 1e-9);
  EXPECT_NEAR(sectors[0].to / kDeg, 10, 1e-9);
}

// Azimuths are reported in the body frame: a sensor turned 90° left sees its own "ahead" at 90°.
TEST(LidarHealth, SectorsAreInTheBodyFrame) {
  const auto rays = Fan(-20 * kDeg);
  const Eigen::Matrix3d R_body_sensor =
      Eigen::AngleAxisd(90 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const auto sectors =
      BlindSectors(rays, Returns(rays, {{-10, 10}}), R_body_sensor, R_body_sensor, FewRays());
  ASSERT_EQ(sectors.size(), 1u);
  EXPECT_NEAR(sectors[0].from / kDeg, 80, 1e-9);
  EXPECT_NEAR(sectors[0].to / kDeg, 100, 1e-9);
}

// A textured scene that slides across the image as the camera drives on, with an optional dark
// blot fixed on the lens (sensor noise on top, as the simulated camera adds it).
sensors::CameraFrame Frame(int k, bool blot, std::mt19937& rng) {
  sensors::CameraFrame f;
  f.width = 240, f.height = 192;
  f.bgr.resize(3 * static_cast<std::size_t>(f.width) * f.height);
  std::normal_distribution<double> noise(0.0, 2.0);
  for (int v = 0; v < f.height; ++v) {
    for (int u = 0; u < f.width; ++u) {
      // Texture: grey 90–170 in a pattern that moves 9 px a frame.
      double grey = 130 + 40 * std::sin(0.21 * (u + 9 * k)) * std::cos(0.17 * v);
      if (blot && std::hypot(u - 120.0, v - 120.0) < 40) grey = 45;
      grey += noise(rng);
      for (int c = 0; c < 3; ++c) {
        f.bgr[3 * (static_cast<std::size_t>(v) * f.width + u) + c] =
            static_cast<std::uint8_t>(std::clamp(std::round(grey), 0.0, 255.0));
      }
    }
  }
  return f;
}

Eigen::Isometry3d At(double x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = x;
  return T;
}

TEST(LensDirtMonitor, FindsABlotThatStaysWhileTheSceneMoves) {
  std::mt19937 rng(1);
  LensDirtMonitor monitor;
  monitor.Observe(Frame(0, false, rng), At(0.0));  // a clean look first
  for (int k = 1; k <= 3; ++k) monitor.Observe(Frame(k, true, rng), At(0.3 * k));
  // Fallen (masked at once) but not yet confirmed: the first moving frame compares the blot
  // with the clean view, the next two are candidates, three are needed.
  EXPECT_EQ(monitor.dirty_fraction(), 0.0);
  EXPECT_TRUE(monitor.Masked(120, 120));
  monitor.Observe(Frame(4, true, rng), At(1.2));
  EXPECT_TRUE(monitor.Masked(120, 120));
  EXPECT_FALSE(monitor.Masked(10, 10));
  // The blot covers π·40² px = 11 % of the image; tiles round it are masked too.
  EXPECT_GT(monitor.dirty_fraction(), 0.109);
  EXPECT_LT(monitor.dirty_fraction(), 0.40);
  EXPECT_GE(monitor.masked_fraction(), monitor.dirty_fraction());
}

// A dark, even region that was never seen otherwise (a dim yard's floor, or a lens dirty before
// the first frame) never falls: it is not dirt.
TEST(LensDirtMonitor, DarkFromTheStartIsNotDirt) {
  std::mt19937 rng(6);
  LensDirtMonitor monitor;
  for (int k = 0; k < 8; ++k) monitor.Observe(Frame(k, true, rng), At(0.3 * k));
  EXPECT_EQ(monitor.masked_fraction(), 0.0);
}

// A blot thrown onto a clean lens is masked from the very frame it appears in, moving or not;
// it counts as dirt only once confirmed.
TEST(LensDirtMonitor, ASuddenBlotIsMaskedAtOnce) {
  std::mt19937 rng(4);
  LensDirtMonitor monitor;
  monitor.Observe(Frame(0, false, rng), At(0.0));
  monitor.Observe(Frame(0, true, rng), At(0.0));  // standing still
  EXPECT_TRUE(monitor.Masked(120, 120));
  EXPECT_EQ(monitor.dirty_fraction(), 0.0);
  // The first moving frame compares the blot with the clean view; three more confirm it.
  for (int k = 1; k <= 4; ++k) monitor.Observe(Frame(k, true, rng), At(0.3 * k));
  EXPECT_GT(monitor.dirty_fraction(), 0.109);
}

// The machine's own bucket, raised into view, stands still in the image as a blot does; where
// the segmentation says it is the machine, it is never dirt.
TEST(LensDirtMonitor, TheOwnMachineIsNotDirt) {
  std::mt19937 rng(5);
  auto with_bucket = [&](int k, bool bucket) {
    sensors::CameraFrame f = Frame(k, false, rng);
    if (!bucket) return f;
    for (int v = 144; v < f.height; ++v) {
      for (int u = 0; u < f.width; ++u) {
        for (int c = 0; c < 3; ++c) f.bgr[3 * (static_cast<std::size_t>(v) * f.width + u) + c] = 40;
      }
    }
    return f;
  };
  std::vector<std::uint8_t> bucket(240 * 192, 0);
  std::fill(bucket.begin() + 144 * 240, bucket.end(), 1);
  LensDirtMonitor told, untold;
  for (int k = 0; k < 6; ++k) {
    told.Observe(with_bucket(k, k > 0), At(0.3 * k), k > 0 ? bucket : std::vector<std::uint8_t>{});
    untold.Observe(with_bucket(k, k > 0), At(0.3 * k));
  }
  EXPECT_EQ(told.masked_fraction(), 0.0);
  EXPECT_GT(untold.dirty_fraction(), 0.2);  // the rule is what keeps the bucket out
}

TEST(LensDirtMonitor, ACleanLensIsNeverMasked) {
  std::mt19937 rng(2);
  LensDirtMonitor monitor;
  for (int k = 0; k < 10; ++k) monitor.Observe(Frame(k, false, rng), At(0.3 * k));
  EXPECT_EQ(monitor.masked_fraction(), 0.0);
  EXPECT_EQ(monitor.dirty_fraction(), 0.0);
}

// A blot seen while the camera stands still is not confirmed (nothing moved behind it), but a
// wiped lens is seen clean while standing.
TEST(LensDirtMonitor, StillnessConfirmsNothingButAWipeClears) {
  std::mt19937 rng(3);
  LensDirtMonitor standing;
  for (int k = 0; k < 6; ++k) standing.Observe(Frame(0, true, rng), At(0.0));
  EXPECT_EQ(standing.dirty_fraction(), 0.0);

  LensDirtMonitor monitor;
  monitor.Observe(Frame(0, false, rng), At(0.0));
  for (int k = 1; k <= 4; ++k) monitor.Observe(Frame(k, true, rng), At(0.3 * k));
  ASSERT_GT(monitor.dirty_fraction(), 0.1);
  monitor.Observe(Frame(5, false, rng), At(1.2));  // stopped, lens wiped
  EXPECT_FALSE(monitor.Masked(120, 120));
  EXPECT_EQ(monitor.masked_fraction(), 0.0);
  EXPECT_EQ(monitor.dirty_fraction(), 0.0);
}

}  // namespace
}  // namespace autoshovel::perception
