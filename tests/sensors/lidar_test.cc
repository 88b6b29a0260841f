// LiDARs: returns on an analytic cone lie on it within the bound of the grid's bilinear
// interpolation; the range noise has the configured σ(r); the spinning and rosette patterns;
// detection limits; determinism.
#include "runtime/sensors/lidar.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <utility>

#include "runtime/sensors/sensor_pose.h"
#include "tests/sensors/sensor_test_support.h"

namespace autoshovel::sensors {
namespace {

using testing::ConeHeight;
using testing::FindLidar;
using testing::FlatWorld;
using testing::Xcmg;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

// The test cone: apex 3 m, base radius 4 m (slope s = 0.75, steeper than a 35° repose angle),
// on a 0.02 m grid.
constexpr double kH = 3.0, kR = 4.0, kGrid = 0.02;
const Eigen::Vector2d kApex(0.0, 0.0);

struct ConeScene {
  plant::World world;
  std::unique_ptr<RaycastScene> scene;
  ConeScene() : world(FlatWorld(24, 24, kGrid)) {
    testing::AddCone(world.terrain, kApex, kH, kR, 0);
    scene = std::make_unique<RaycastScene>(world);
  }
};

const ConeScene& Cone() {
  static const ConeScene s;
  return s;
}

// The front LiDAR as mounted on the XCMG (3.65 m up, pitched 20° down), 9 m before the apex.
Eigen::Isometry3d FrontLidarPose() {
  model::Pose3 pose = FindLidar(Xcmg(), "front_solid_state").pose;
  pose.xyz = Eigen::Vector3d(-9.0, 0.3, pose.xyz.z());
  return PoseToIsometry(pose);
}

TEST(Lidar, NoiseFreeReturnsLieOnTheAnalyticCone) {
  model::Lidar lidar = FindLidar(Xcmg(), "front_solid_state");
  lidar.range_noise = 0;
  const Eigen::Isometry3d T = FrontLidarPose();
  Rng rng(7);
  const PointCloud cloud = SimulateLidarFrame(lidar, *Cone().scene, T, 0.0, rng);
  ASSERT_GT(cloud.points.size(), 15000u);

  const double s = kH / kR;
  // Bilinear interpolation of a surface of slope ≤ s: |error| ≤ s·h/√2 everywhere (kinks at
  // the apex and the rim included); where the cone is smooth (curvature s/r across, 0 along
  // the slope), |error| ≤ h²/8·(|f_xx| + |f_yy|) ≤ h²/8·2s/r_min. Float storage of the points
  // adds ≤ 1e-5 m at these ranges.
  const double kink_bound = s * kGrid / std::sqrt(2.0) + 2e-5;
  int on_cone = 0, on_floor = 0, smooth = 0;
  double worst_smooth = 0;
  for (const auto& p : cloud.points) {
    const Eigen::Vector3d w = T * p.p_sensor.cast<double>();
    const double r = std::hypot(w.x() - kApex.x(), w.y() - kApex.y());
    const double expected = ConeHeight(kApex, kH, kR, w.x(), w.y());
    const double err = std::abs(w.z() - expected);
    ASSERT_LE(err, kink_bound) << "at r = " << r;
    if (r < kR) ++on_cone;
    if (r >= 0.5 && r <= kR - 2 * kGrid) {
      const double r_min = r - kGrid * std::sqrt(2.0);
      const double bound = kGrid * kGrid / 8 * 2 * s / r_min + 2e-5;
      ASSERT_LE(err, bound) << "at r = " << r;
      worst_smooth = std::max(worst_smooth, err);
      ++smooth;
    }
    if (r >= kR + 2 * kGrid) {
      ASSERT_LE(std::abs(w.z()), 2e-5) << "floor point at r = " << r;
      ++on_floor;
    }
  }
  EXPECT_GT(on_cone, 6000);
  EXPECT_GT(smooth, 5000);
  EXPECT_GT(on_floor, 3000);
  // The kink bound is 1.1 cm; on the smooth flank the error is sub-millimetre.
  EXPECT_LT(worst_smooth, 1e-3);
}

TEST(Lidar, RangeNoiseHasTheConfiguredSigma) {
  // The same seed gives the same dropout draws, so the noisy and the noise-free frame hold the
  // same returns in the same order; their range difference is the noise alone.
  model::Lidar clean = FindLidar(Xcmg(), "front_solid_state");
  clean.range_noise = 0;
  model::Lidar noisy = clean;
  noisy.range_noise = 0.03;
  const Eigen::Isometry3d T = FrontLidarPose();
  Rng rng_a(99), rng_b(99);
  const PointCloud a = SimulateLidarFrame(clean, *Cone().scene, T, 0.3, rng_a);
  const PointCloud b = SimulateLidarFrame(noisy, *Cone().scene, T, 0.3, rng_b);
  ASSERT_EQ(a.points.size(), b.points.size());
  // Normalised residuals, in a near (< 10 m) and a far bin, to check the growth law too.
  double sum[2] = {0, 0}, sum2[2] = {0, 0};
  int count[2] = {0, 0};
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    const double r = a.points[i].p_sensor.cast<double>().norm();
    const double m = b.points[i].p_sensor.cast<double>().norm();
    // Along the ray: the directions agree.
    ASSERT_LT((a.points[i].p_sensor / a.points[i].p_sensor.norm() -
               b.points[i].p_sensor / b.points[i].p_sensor.norm())
                  .norm(),
              1e-5f);
    const double z = (m - r) / (0.03 * (0.5 + 0.5 * r / 10));
    const int bin = r < 10 ? 0 : 1;
    sum[bin] += z;
    sum2[bin] += z * z;
    ++count[bin];
  }
  for (int bin = 0; bin < 2; ++bin) {
    ASSERT_GT(count[bin], 2000) << "bin " << bin;
    const double mean = sum[bin] / count[bin];
    const double sd = std::sqrt(sum2[bin] / count[bin] - mean * mean);
    EXPECT_NEAR(mean, 0.0, 4.0 / std::sqrt(count[bin])) << "bin " << bin;
    EXPECT_NEAR(sd, 1.0, 0.05) << "bin " << bin;  // brief: within 20 %; n > 2000 gives ±1.6 %
  }
}

TEST(Lidar, SameSeedIsByteIdenticalAndAnotherSeedDiffers) {
  const model::Lidar& lidar = FindLidar(Xcmg(), "front_solid_state");
  const Eigen::Isometry3d T = FrontLidarPose();
  Rng r1(5), r2(5), r3(6);
  const auto a = testing::Bytes(SimulateLidarFrame(lidar, *Cone().scene, T, 1.0, r1));
  const auto b = testing::Bytes(SimulateLidarFrame(lidar, *Cone().scene, T, 1.0, r2));
  const auto c = testing::Bytes(SimulateLidarFrame(lidar, *Cone().scene, T, 1.0, r3));
  EXPECT_GT(a.size(), 100000u);
  EXPECT_TRUE(a == b);
  EXPECT_FALSE(a == c);
}

TEST(Lidar, SpinningPatternIsVlp16Like) {
  const model::Lidar& lidar = FindLidar(Xcmg(), "top_16");
  const auto rays = LidarScanPattern(lidar, 0.0);
  // 300 000 pts/s / (10 Hz · 16 lines) = 1875 azimuth steps of 0.192°.
  ASSERT_EQ(rays.size(), 1875u * 16u);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const auto& r = rays[i];
    EXPECT_NEAR(r.direction.norm(), 1.0, 1e-12);
    const double elevation = std::asin(r.direction.z());
    EXPECT_EQ(r.ring, i % 16);
    EXPECT_NEAR(elevation, (-15.0 + 2.0 * r.ring) * kDeg, 1e-12);  // ±15° in 2° steps
    EXPECT_GE(r.time_offset, 0.0f);
    EXPECT_LT(r.time_offset, 0.1f);
  }
  // Clockwise: the azimuth decreases by 0.192° per column.
  const double az0 = std::atan2(rays[0].direction.y(), rays[0].direction.x());
  const double az1 = std::atan2(rays[16].direction.y(), rays[16].direction.x());
  EXPECT_NEAR(az0 - az1, 0.192 * kDeg, 1e-12);
  EXPECT_NEAR(rays[16].time_offset - rays[0].time_offset, 0.1 / 1875, 1e-8);
}

TEST(Lidar, SpinningOnFlatGroundRingsAndIntensity) {
  // A flat 160 m yard. The 15° ring meets the floor 3.75/tan 15° = 14.0 m out, at 75° incidence:
  // ρ cos θ = 0.2 · sin 15°, well within the detection limit (r_det = 25 m, P(return) =
  // 0.9999), so (nearly) every ray of ring 0 returns, on z = 0 and the circle of that radius. The
  // −3° ring would meet it 71.6 m out at 87° incidence, where r_det = 11 m: it drops out.
  const plant::World world = FlatWorld(160, 160, 0.25);
  const RaycastScene scene(world);
  model::Lidar lidar = FindLidar(Xcmg(), "top_16");
  lidar.range_noise = 0;
  const Eigen::Isometry3d T = PoseToIsometry(lidar.pose);
  Rng rng(1);
  const PointCloud cloud = SimulateLidarFrame(lidar, scene, T, 0.0, rng);
  int ring0 = 0, ring6 = 0, upward = 0;
  const double height = lidar.pose.xyz.z();
  for (const auto& p : cloud.points) {
    if (p.ring == 0) {
      ++ring0;
      const Eigen::Vector3d w = T * p.p_sensor.cast<double>();
      EXPECT_NEAR(w.z(), 0.0, 1e-5);
      EXPECT_NEAR((w - T.translation()).head<2>().norm(), height / std::tan(15 * kDeg), 1e-4);
      EXPECT_NEAR(p.intensity, 0.2 * std::sin(15 * kDeg), 1e-6);
    }
    if (p.ring == 6) ++ring6;
    if (p.ring >= 8) ++upward;
  }
  EXPECT_GE(ring0, 1870);
  EXPECT_LE(ring0, 1875);
  EXPECT_LT(ring6, 19);  // < 1 %
  EXPECT_EQ(upward, 0);  // 0° and above: sky
  EXPECT_DOUBLE_EQ(LidarReturnProbability(lidar, 101, 1.0, 1.0), 0.0);
  EXPECT_NEAR(LidarReturnProbability(lidar, 50, 0.2, 1.0), 0.5, 1e-12);  // r_det = 100·√¼
}

// 1° cells of the rosette's elliptical FoV (cell centre inside the ellipse).
struct FovGrid {
  double hfov, vfov, cell;
  int nx, ny;
  FovGrid(const model::Lidar& l, double cell_deg)
      : hfov(l.horizontal_fov),
        vfov(l.vertical_fov),
        cell(cell_deg * kDeg),
        nx(static_cast<int>(std::ceil(hfov / cell))),
        ny(static_cast<int>(std::ceil(vfov / cell))) {}
  bool Inside(int ix, int iy) const {
    const double a = -0.5 * hfov + (ix + 0.5) * cell, b = -0.5 * vfov + (iy + 0.5) * cell;
    return std::pow(a / (0.5 * hfov), 2) + std::pow(b / (0.5 * vfov), 2) <= 1.0;
  }
  std::pair<int, int> CellOf(const Eigen::Vector3d& d) const {
    const double a = std::atan2(d.y(), d.x()), b = std::asin(d.z());
    return {static_cast<int>(std::floor((a + 0.5 * hfov) / cell)),
            static_cast<int>(std::floor((b + 0.5 * vfov) / cell))};
  }
  int InsideCount() const {
    int n = 0;
    for (int iy = 0; iy < ny; ++iy) {
      for (int ix = 0; ix < nx; ++ix) n += Inside(ix, iy);
    }
    return n;
  }
};

double Coverage(const model::Lidar& lidar, const FovGrid& grid, int frames, double t0 = 0) {
  std::set<std::pair<int, int>> seen;
  for (int f = 0; f < frames; ++f) {
    for (const auto& r : LidarScanPattern(lidar, t0 + f / lidar.rate)) {
      const auto c = grid.CellOf(r.direction);
      if (grid.Inside(c.first, c.second)) seen.insert(c);
    }
  }
  return static_cast<double>(seen.size()) / grid.InsideCount();
}

TEST(Lidar, RosetteStaysInItsFieldOfView) {
  const model::Lidar& lidar = FindLidar(Xcmg(), "front_solid_state");
  const auto rays = LidarScanPattern(lidar, 12.3);
  ASSERT_EQ(rays.size(), 24000u);  // 240 000 pts/s at 10 Hz
  for (const auto& r : rays) {
    const double a = std::atan2(r.direction.y(), r.direction.x()), b = std::asin(r.direction.z());
    EXPECT_LE(
        std::pow(a / (0.5 * lidar.horizontal_fov), 2) + std::pow(b / (0.5 * lidar.vertical_fov), 2),
        1.0 + 1e-9);
    EXPECT_LT(r.ring, kRosetteEmitters);
    EXPECT_GE(r.time_offset, 0.0f);
    EXPECT_LT(r.time_offset, 0.1f);
  }
}

TEST(Lidar, RosetteCoverageGrowsWithIntegrationTime) {
  const model::Lidar& lidar = FindLidar(Xcmg(), "front_solid_state");
  // Consecutive frames see different directions: at 0.25° the two frames together cover far
  // more than either alone, and no direction repeats exactly.
  const FovGrid fine(lidar, 0.25);
  const double one = Coverage(lidar, fine, 1), two = Coverage(lidar, fine, 2);
  EXPECT_GT(two, 1.5 * one);
  const auto f0 = LidarScanPattern(lidar, 0.0), f1 = LidarScanPattern(lidar, 0.1);
  std::set<std::pair<double, double>> first;
  for (const auto& r : f0) first.insert({r.direction.y(), r.direction.z()});
  int repeated = 0;
  for (const auto& r : f1) repeated += first.count({r.direction.y(), r.direction.z()});
  EXPECT_EQ(repeated, 0);
  // Coverage grows with integration time: at 0.25°, 0.1 s < 0.5 s < 1 s, and 1 s covers
  // nearly all of it; at 1° (the brief's grid) 1 s covers ≥ 90 %.
  const double c01 = one, c05 = Coverage(lidar, fine, 5);
  const double c10 = Coverage(lidar, fine, 10);
  EXPECT_LT(c01, 0.4);
  EXPECT_GT(c05, c01 + 0.3);
  EXPECT_GT(c10, c05 + 0.05);
  EXPECT_GE(c10, 0.95);
  const FovGrid grid(lidar, 1.0);
  EXPECT_GE(Coverage(lidar, grid, 10), 0.90);
  // Also from another start time (the pattern is a function of absolute time).
  EXPECT_GE(Coverage(lidar, fine, 10, 1234.5), 0.95);
}

TEST(Lidar, UnknownModelIsRefused) {
  model::Lidar lidar = FindLidar(Xcmg(), "top_16");
  lidar.model = "flash";
  EXPECT_THROW(LidarScanPattern(lidar, 0), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::sensors
