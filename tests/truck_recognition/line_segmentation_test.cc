// Step 1 of §4.1: scanlines into straight segments (split-and-merge).
#include "runtime/perception/truck/line_segmentation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

namespace autoshovel::perception {
namespace {

// A scanline from points given in order; all valid.
Scanline MakeScanline(const std::vector<Eigen::Vector3d>& points,
                      const Eigen::Vector3d& sensor = Eigen::Vector3d(0, 0, 4)) {
  Scanline line;
  line.p_world_sensor = sensor;
  for (const Eigen::Vector3d& p : points) line.points.push_back({p, true});
  return line;
}

// A wall at x = 6 from z = 0.5 to the corner at (6, 0, 2), then a floor going away at z = 2
// (a concave L as a scan circle meets a step), sampled every 4 cm.
std::vector<Eigen::Vector3d> LShape() {
  std::vector<Eigen::Vector3d> points;
  for (double z = 0.5; z < 2.0 - 1e-9; z += 0.04) points.emplace_back(6.0, 0.0, z);
  for (double x = 6.0; x <= 7.5 + 1e-9; x += 0.04) points.emplace_back(x, 0.0, 2.0);
  return points;
}

TEST(LineSegmentation, SplitsAnLShapeAtItsCorner) {
  const std::vector<LineSegment> segments = SegmentScanline(MakeScanline(LShape()), 7);
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[0].scanline, 7);
  EXPECT_NEAR(std::abs(segments[0].direction.z()), 1.0, 1e-6);
  EXPECT_NEAR(std::abs(segments[1].direction.x()), 1.0, 1e-6);
  const Eigen::Vector3d corner(6.0, 0.0, 2.0);
  EXPECT_LT((segments[0].p_world_end - corner).norm(), 0.05);
  EXPECT_LT((segments[1].p_world_start - corner).norm(), 0.05);
  EXPECT_NEAR((segments[0].p_world_start - Eigen::Vector3d(6, 0, 0.5)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((segments[1].p_world_end - Eigen::Vector3d(7.48, 0, 2)).norm(), 0.0, 0.03);
}

TEST(LineSegmentation, KeepsANoisyStraightWallInOneSegment) {
  // σ = 3 cm along the beam, 2 m of wall at 6 m range: 300 draws, never cut by noise alone.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.03);
  const Eigen::Vector3d sensor(0, 0, 4);
  int cut = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Eigen::Vector3d> points;
    for (double z = 0.5; z <= 2.5; z += 0.04) {
      const Eigen::Vector3d p(6.0, 0.0, z);
      points.push_back(p + noise(rng) * (p - sensor).normalized());
    }
    const std::vector<LineSegment> segments = SegmentScanline(MakeScanline(points, sensor), 0);
    ASSERT_FALSE(segments.empty());
    if (segments.size() != 1) ++cut;
  }
  EXPECT_EQ(cut, 0);
}

TEST(LineSegmentation, CutsAtRangeJumps) {
  // Two collinear stretches of ground with 1.5 m missing between them (an occluder's shadow):
  // one line would bridge the shadow.
  std::vector<Eigen::Vector3d> points;
  for (double x = 5.0; x <= 6.0; x += 0.05) points.emplace_back(x, 0, 0);
  for (double x = 7.5; x <= 8.5; x += 0.05) points.emplace_back(x, 0, 0);
  EXPECT_EQ(SegmentScanline(MakeScanline(points), 0).size(), 2u);
}

TEST(LineSegmentation, SkipsInvalidAndNonFiniteReturns) {
  const std::vector<LineSegment> clean = SegmentScanline(MakeScanline(LShape()), 0);
  Scanline dirty = MakeScanline(LShape());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Flagged invalid (dropouts) and flagged valid but NaN (a driver bug) alike are skipped.
  dirty.points.insert(dirty.points.begin() + 10, ScanPoint{});
  dirty.points.insert(dirty.points.begin() + 20, ScanPoint{Eigen::Vector3d(nan, 0, 1), true});
  dirty.points.insert(dirty.points.end(), ScanPoint{Eigen::Vector3d(1, 2, 3), false});
  const std::vector<LineSegment> segments = SegmentScanline(dirty, 0);
  ASSERT_EQ(segments.size(), clean.size());
  for (std::size_t i = 0; i < segments.size(); ++i) {
    EXPECT_TRUE(segments[i].centroid.allFinite());
    EXPECT_EQ(segments[i].points.size(), clean[i].points.size());
    EXPECT_NEAR((segments[i].centroid - clean[i].centroid).norm(), 0.0, 1e-12);
  }
}

TEST(LineSegmentation, DropsPiecesTooSmallToFitAPlaneTo) {
  std::vector<Eigen::Vector3d> points{{6, 0, 1.0}, {6, 0, 1.04}, {6, 0, 1.08}};
  EXPECT_TRUE(SegmentScanline(MakeScanline(points), 0).empty());
}

TEST(LineSegmentation, TrimsReturnsFromTheNextSurfaceOffASegmentsEnd) {
  // A wall whose last three returns come from a surface 10 cm behind its top: within the chord
  // tolerance, they would tilt the least-squares line.
  std::vector<Eigen::Vector3d> points;
  for (double z = 1.0; z <= 2.0; z += 0.04) points.emplace_back(6.0, 0.0, z);
  for (int i = 1; i <= 3; ++i) points.emplace_back(6.10, 0.0, 2.0 + 0.04 * i);
  const std::vector<LineSegment> segments = SegmentScanline(MakeScanline(points), 0);
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_GT(std::abs(segments[0].direction.z()), std::cos(0.5 * std::numbers::pi / 180));
  EXPECT_NEAR(segments[0].centroid.x(), 6.0, 1e-9);
}

TEST(LineSegmentation, RejectsInvalidParametersAndOrigins) {
  const Scanline line = MakeScanline(LShape());
  LineSegmentationParams params;
  params.split_tolerance = 0;
  try {
    SegmentScanline(line, 0, params);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("split_tolerance"), std::string::npos);
  }
  params = {};
  params.min_points = 1;
  EXPECT_THROW(SegmentScanline(line, 0, params), std::invalid_argument);
  params = {};
  params.jump_distance = std::numeric_limits<double>::infinity();
  EXPECT_THROW(SegmentScanline(line, 0, params), std::invalid_argument);
  Scanline bad = line;
  bad.p_world_sensor.x() = std::numeric_limits<double>::quiet_NaN();
  try {
    SegmentScanlines({line, bad});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("scanline 1"), std::string::npos);
  }
}

}  // namespace
}  // namespace autoshovel::perception
