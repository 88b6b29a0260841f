// The scan geometry of the excavator's rangefinders (excavator seed §2, Figs. 2–4): 12 kHz
// pulses, a vertical scan circle, panning at up to 120°/s.
#include "runtime/sensors/rangefinder/scanner_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace autoshovel::sensors {
namespace {

TEST(ScannerGeometry, PulsesFireAt12kHz) {
  const ScannerGeometry geometry(LeftScannerConfig());
  for (const std::int64_t k : {0LL, 1LL, 11999LL, 1234567LL}) {
    EXPECT_NEAR(geometry.PulseTime(k + 1) - geometry.PulseTime(k), 1.0 / 12000.0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(geometry.PulseTime(12000), 1.0);
  // The first pulse at or after t is the one whose time is not before t, and the one before
  // it is.
  for (const double t : {0.0, 1e-5, 0.5, 0.5000001, 3.14159}) {
    const std::int64_t k = geometry.FirstPulseAtOrAfter(t);
    EXPECT_GE(geometry.PulseTime(k), t);
    EXPECT_LT(geometry.PulseTime(k - 1), t);
  }
}

TEST(ScannerGeometry, MirrorSweepsTheCircleAtItsRate) {
  const ScannerGeometry geometry(LeftScannerConfig());
  // 20 rev/s at 12 kHz: 600 pulses per circle, 0.6° apart.
  EXPECT_DOUBLE_EQ(geometry.pulses_per_circle(), 600.0);
  EXPECT_NEAR(geometry.elevation_step(), 0.6 * kDegree, 1e-12);
  for (std::int64_t k = 0; k < 1200; ++k) {
    const double step = std::remainder(geometry.ElevationAt(geometry.PulseTime(k + 1)) -
                                           geometry.ElevationAt(geometry.PulseTime(k)),
                                       2 * std::numbers::pi);
    ASSERT_NEAR(step, 0.6 * kDegree, 1e-9) << "pulse " << k;
  }
  // One revolution later the mirror is back where it was.
  for (const std::int64_t k : {7LL, 123LL, 100000LL}) {
    EXPECT_NEAR(std::remainder(geometry.ElevationAt(geometry.PulseTime(k + 600)) -
                                   geometry.ElevationAt(geometry.PulseTime(k)),
                               2 * std::numbers::pi),
                0.0, 1e-9);
  }
}

TEST(ScannerGeometry, OnlyTheActiveArcIsFired) {
  const ScannerGeometry geometry(LeftScannerConfig());
  int fired = 0;
  for (std::int64_t k = 0; k < 600; ++k) {
    const ScanRay ray = geometry.Ray(k, HoldPan(0.0));
    if (ray.active) {
      ++fired;
      EXPECT_GE(ray.elevation, -75.0 * kDegree - 1e-12);
      EXPECT_LE(ray.elevation, 30.0 * kDegree + 1e-12);
    }
  }
  // 105° of 360° at 0.6° per pulse.
  EXPECT_NEAR(fired, 175, 1);
}

TEST(ScannerGeometry, RaysLieOnTheVerticalScanCircle) {
  ScannerConfig config = LeftScannerConfig();
  // A scanner mounted tilted and turned, to check that the cab frame is applied.
  config.T_cab_scanner.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                                      .toRotationMatrix();
  const ScannerGeometry geometry(config);
  for (const double pan_deg : {-120.0, -35.0, 0.0, 60.0, 120.0}) {
    const double pan = pan_deg * kDegree;
    const Eigen::Vector3d plane_normal(-std::sin(pan), std::cos(pan), 0.0);  // scanner frame
    for (std::int64_t k = 0; k < 600; ++k) {
      const ScanRay ray = geometry.Ray(k, HoldPan(pan));
      ASSERT_NEAR(ray.direction_scanner.norm(), 1.0, 1e-12);
      ASSERT_NEAR(ray.direction_scanner.dot(plane_normal), 0.0, 1e-12);
      ASSERT_NEAR(std::asin(ray.direction_scanner.z()), std::asin(std::sin(ray.elevation)), 1e-9);
      ASSERT_TRUE(
          ray.direction_cab.isApprox(config.T_cab_scanner.linear() * ray.direction_scanner, 1e-12));
      ASSERT_TRUE(ray.origin_cab.isApprox(config.T_cab_scanner.translation(), 1e-12));
      EXPECT_DOUBLE_EQ(ray.pan, pan);
    }
  }
}

TEST(ScannerGeometry, PanningTurnsTheCircleAtTheCommandedRate) {
  const ScannerGeometry geometry(LeftScannerConfig());
  const double rate = 120.0 * kDegree;
  const PanSweep sweep{0.25, -30.0 * kDegree, 90.0 * kDegree, rate};
  EXPECT_DOUBLE_EQ(geometry.PanAt(sweep, 0.0), -30.0 * kDegree);
  EXPECT_NEAR(geometry.PanAt(sweep, 0.75), 30.0 * kDegree, 1e-12);
  EXPECT_NEAR(geometry.PanAt(sweep, 1.25), 90.0 * kDegree, 1e-12);
  EXPECT_NEAR(geometry.PanAt(sweep, 5.0), 90.0 * kDegree, 1e-12);
  // Every pulse's beam lies in the scan plane of the pan angle at its own firing time.
  for (std::int64_t k = geometry.FirstPulseAtOrAfter(0.3); k < geometry.FirstPulseAtOrAfter(1.2);
       k += 7) {
    const ScanRay ray = geometry.Ray(k, sweep);
    const double expected_pan = -30.0 * kDegree + rate * (ray.time - 0.25);
    ASSERT_NEAR(ray.pan, expected_pan, 1e-9);
    const Eigen::Vector3d d = ray.direction_scanner;
    if (std::cos(ray.elevation) > 0.1) {
      ASSERT_NEAR(std::atan2(d.y(), d.x()), expected_pan, 1e-9);
    }
  }
  // Turning the other way.
  const PanSweep back{0.0, 90.0 * kDegree, 0.0, 60.0 * kDegree};
  EXPECT_NEAR(geometry.PanAt(back, 0.5), 60.0 * kDegree, 1e-12);
}

TEST(ScannerGeometry, PanRateAndRangeAreLimited) {
  const ScannerGeometry geometry(LeftScannerConfig());
  EXPECT_NO_THROW(geometry.Validate({0.0, -120.0 * kDegree, 120.0 * kDegree, 120.0 * kDegree}));
  EXPECT_THROW(geometry.Validate({0.0, 0.0, 90.0 * kDegree, 121.0 * kDegree}),
               std::invalid_argument);
  EXPECT_THROW(geometry.Validate({0.0, 0.0, 125.0 * kDegree, 60.0 * kDegree}),
               std::invalid_argument);
  EXPECT_THROW(geometry.Validate({0.0, 0.0, 10.0 * kDegree, 0.0}), std::invalid_argument);
  EXPECT_THROW(geometry.Validate({0.0, 0.0, 10.0 * kDegree, -1.0}), std::invalid_argument);
  EXPECT_THROW(geometry.Validate({std::nan(""), 0.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(geometry.Ray(0, {0.0, 0.0, 90.0 * kDegree, 200.0 * kDegree}), std::invalid_argument);
}

TEST(ScannerGeometry, LeftAndRightScannersAreMirrorImagesBesideTheBoom) {
  const ScannerGeometry left(LeftScannerConfig());
  const ScannerGeometry right(RightScannerConfig());
  EXPECT_GT(left.config().T_cab_scanner.translation().y(), 0.0);
  const Eigen::Vector3d mirror(1.0, -1.0, 1.0);
  for (std::int64_t k = 0; k < 600; k += 13) {
    const ScanRay l = left.Ray(k, HoldPan(40.0 * kDegree));
    const ScanRay r = right.Ray(k, HoldPan(-40.0 * kDegree));
    EXPECT_TRUE(r.origin_cab.isApprox(l.origin_cab.cwiseProduct(mirror), 1e-12));
    EXPECT_TRUE(r.direction_cab.isApprox(l.direction_cab.cwiseProduct(mirror), 1e-12));
  }
}

TEST(ScannerGeometry, BadConfigurationsAreRefused) {
  auto with = [](auto change) {
    ScannerConfig config = LeftScannerConfig();
    change(config);
    return config;
  };
  EXPECT_THROW(ScannerGeometry(with([](ScannerConfig& c) { c.pulse_rate = 0; })),
               std::invalid_argument);
  EXPECT_THROW(ScannerGeometry(with([](ScannerConfig& c) { c.mirror_rate = std::nan(""); })),
               std::invalid_argument);
  EXPECT_THROW(ScannerGeometry(with([](ScannerConfig& c) { c.mirror_rate = 7000; })),
               std::invalid_argument);
  EXPECT_THROW(ScannerGeometry(with([](ScannerConfig& c) { c.active_elevation_max = -1.4; })),
               std::invalid_argument);
  EXPECT_THROW(ScannerGeometry(with([](ScannerConfig& c) { c.pan_min = c.pan_max; })),
               std::invalid_argument);
  EXPECT_THROW(ScannerGeometry(with([](ScannerConfig& c) { c.pan_rate_limit = -1; })),
               std::invalid_argument);
  EXPECT_THROW(ScannerGeometry(with([](ScannerConfig& c) {
                 c.T_cab_scanner.linear() = 2.0 * Eigen::Matrix3d::Identity();
               })),
               std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::sensors
