// The standalone rig's pieces (issue 42): calib.txt and extrinsic files, the published
// perturbation protocol, PnP from given correspondences, depth edges and the segmentation of a
// cloud without an up axis.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <random>

#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/cloud_features.h"
#include "identification/camera_lidar/correspondence_pnp.h"
#include "identification/camera_lidar/depth_edges.h"
#include "identification/camera_lidar/rig_files.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The CalibAnything scene's calib.txt layout (values of a real 1920×1200 camera).
const char* kCalibTxt =
    "K: 2152.8 0 971.3 0 2155.5 605.9 0 0 1\n"
    "D: -0.1192 0.162 0.00073985 0.0014\n"
    "T: 0.0188623 -0.999822 -9.36529e-05 -0.0323222 0.0288601 0.000638227 -0.999583 -0.396685 "
    "0.999405 0.0188516 0.028867 -0.0869361\n";

TEST(RigFiles, CalibTxtGivesIntrinsicsAndTheLidarToOpticalMatrix) {
  const RigCalibrationFile file = ParseCalibTxt(kCalibTxt, "calib.txt");
  ASSERT_TRUE(file.K && file.T_optical_lidar);
  EXPECT_DOUBLE_EQ((*file.K)(0, 0), 2152.8);
  EXPECT_DOUBLE_EQ((*file.K)(1, 2), 605.9);
  ASSERT_EQ(file.D.size(), 4u);
  EXPECT_DOUBLE_EQ(file.D[0], -0.1192);
  // The LiDAR's forward axis (x) is the camera's optical axis (z) within 2°: row 3 of R.
  const Eigen::Isometry3d& T = *file.T_optical_lidar;
  EXPECT_GT(T.linear()(2, 0), std::cos(2 * kDeg));
  EXPECT_NEAR(T.translation().y(), -0.396685, 1e-6);
  // Re-orthonormalised: rigid to rounding.
  EXPECT_LT((T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(RigFiles, ExtrinsicRoundTripsThroughItsText) {
  const Eigen::Isometry3d T = *ParseCalibTxt(kCalibTxt, "calib.txt").T_optical_lidar;
  const std::string text = ExtrinsicText(T, "a comment\nover two lines");
  EXPECT_EQ(text.rfind("# a comment\n# over two lines\n", 0), 0u);
  const Eigen::Isometry3d back = ParseExtrinsic(text, "out.txt");
  EXPECT_LT((back.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-8);
  // A calib.txt is an extrinsic file too (its T: line).
  EXPECT_LT((ParseExtrinsic(kCalibTxt, "calib.txt").matrix() - T.matrix()).norm(), 1e-12);
}

TEST(RigFiles, RefusalsNameTheLineAndColumn) {
  try {
    ParseCalibTxt("K: 1 0 0 0 1 0 0 0 1\nT: 1 0 0 0 0 1 0 0 0 0 1 zz\n", "c.txt");
    FAIL() << "accepted a letter in T";
  } catch (const core::InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("c.txt:2:26: expected a finite number, got 'zz'", 0), 0u)
        << e.what();
  }
  EXPECT_THROW(ParseExtrinsic("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 2\n", "m.txt"), core::InputError);
}

TEST(RigFiles, ProtocolDeltaIsZYXAppliedToTheLidarPointsFirst) {
  const Eigen::Vector3d rpy(3 * kDeg, -2 * kDeg, 1 * kDeg), xyz(0.1, -0.05, 0.02);
  const Eigen::Isometry3d delta = ProtocolDelta(rpy, xyz);
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_LT((delta.linear() - expected).norm(), 1e-15);
  // Roll, pitch, yaw read back with the project's convention (camera_model.h).
  EXPECT_LT((RollPitchYaw(delta.linear()) - rpy).norm(), 1e-12);
  // The error of a perturbed start against its reference is the perturbation itself.
  const Eigen::Isometry3d T_ref = *ParseCalibTxt(kCalibTxt, "calib.txt").T_optical_lidar;
  const ProtocolError e = CompareExtrinsics(T_ref, T_ref * delta);
  EXPECT_NEAR(e.rotation, Eigen::AngleAxisd(expected).angle(), 1e-12);
  // A pure translation t: T_ref · (T_ref Δ)⁻¹ = T_ref Δ⁻¹ T_ref⁻¹ moves by −R_ref t, |t| long.
  const ProtocolError shift =
      CompareExtrinsics(T_ref, T_ref * ProtocolDelta(Eigen::Vector3d::Zero(), xyz));
  EXPECT_NEAR(shift.rotation, 0.0, 1e-12);
  EXPECT_NEAR(shift.translation, xyz.norm(), 1e-12);
}

// A known rig: points in front of the camera, their pixels through K and D.
struct SyntheticRig {
  CameraIntrinsics intrinsics;
  Eigen::Isometry3d T_optical_lidar;
  std::vector<Correspondence> pairs;
};

SyntheticRig MakeRig(int count, int outliers) {
  SyntheticRig rig;
  const RigCalibrationFile file = ParseCalibTxt(kCalibTxt, "calib.txt");
  rig.intrinsics.width = 1920;
  rig.intrinsics.height = 1200;
  rig.intrinsics.K = *file.K;
  rig.intrinsics.D = file.D;
  rig.T_optical_lidar = *file.T_optical_lidar * ProtocolDelta({0.01, -0.02, 0.03}, {0.05, 0, 0});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> lateral(-2.0, 2.0), range(4.0, 12.0);
  cv::Mat K(3, 3, CV_64F), D(rig.intrinsics.D);
  for (int i = 0; i < 9; ++i) K.at<double>(i / 3, i % 3) = rig.intrinsics.K(i / 3, i % 3);
  while (static_cast<int>(rig.pairs.size()) < count) {
    const Eigen::Vector3d p_lidar(range(rng), lateral(rng), 0.5 * lateral(rng));
    const Eigen::Vector3d p = rig.T_optical_lidar * p_lidar;
    // Distort the ideal pixel as the camera does (cv::projectPoints with D).
    std::vector<cv::Point3d> object{{p.x(), p.y(), p.z()}};
    std::vector<cv::Point2d> image;
    cv::projectPoints(object, cv::Mat::zeros(3, 1, CV_64F), cv::Mat::zeros(3, 1, CV_64F), K, D,
                      image);
    if (image[0].x < 0 || image[0].y < 0 || image[0].x > 1920 || image[0].y > 1200) continue;
    rig.pairs.push_back({{image[0].x, image[0].y}, p_lidar});
  }
  for (int k = 0; k < outliers; ++k)
    rig.pairs[static_cast<std::size_t>(3 * k)].uv += Eigen::Vector2d(60, -45);
  return rig;
}

TEST(CorrespondencePnP, RecoversTheExtrinsicFromDistortedPixels) {
  const SyntheticRig rig = MakeRig(12, 0);
  const CorrespondencePnP pnp = SolveCorrespondencePnP(rig.pairs, rig.intrinsics);
  ASSERT_TRUE(pnp.calibration.ok) << pnp.calibration.failure;
  EXPECT_EQ(pnp.inliers, 12);
  EXPECT_LT(pnp.calibration.reprojection_rms, 1e-3);
  const ProtocolError e =
      CompareExtrinsics(rig.T_optical_lidar, OpticalFromLidar(pnp.calibration.T_lidar_camera));
  EXPECT_LT(e.rotation, 1e-5);
  EXPECT_LT(e.translation, 1e-5);
}

TEST(CorrespondencePnP, RansacRejectsMismatchedPairs) {
  const SyntheticRig rig = MakeRig(20, 3);
  const CorrespondencePnP pnp = SolveCorrespondencePnP(rig.pairs, rig.intrinsics);
  ASSERT_TRUE(pnp.calibration.ok) << pnp.calibration.failure;
  EXPECT_EQ(pnp.inliers, 17);
  const ProtocolError e =
      CompareExtrinsics(rig.T_optical_lidar, OpticalFromLidar(pnp.calibration.T_lidar_camera));
  EXPECT_LT(e.rotation, 1e-4);
  EXPECT_LT(e.translation, 1e-4);
}

// A 1 m wide board 5 m ahead of a wall 10 m ahead, scanned in rows: the board's left and right
// columns are the only foreground edges.
TEST(DepthEdges, TheSilhouetteOfANearObjectAgainstAFarOne) {
  std::vector<Eigen::Vector3f> points;
  std::vector<int> on_board_edge;
  for (int row = -3; row <= 3; ++row) {
    const double elevation = row * 0.5 * kDeg;
    for (int column = -100; column <= 100; ++column) {
      const double azimuth = column * 0.2 * kDeg;
      // The ray hits the board (|y| < 0.5 at x = 5) or the wall at x = 10.
      const double y_board = 5.0 * std::tan(azimuth);
      const double x = std::abs(y_board) < 0.5 ? 5.0 : 10.0;
      const Eigen::Vector3f p(static_cast<float>(x), static_cast<float>(x * std::tan(azimuth)),
                              static_cast<float>(x * std::tan(elevation) / std::cos(azimuth)));
      points.push_back(p);
      const double y_next = 5.0 * std::tan(azimuth + 0.2 * kDeg);
      const double y_prev = 5.0 * std::tan(azimuth - 0.2 * kDeg);
      on_board_edge.push_back(x == 5.0 && (std::abs(y_next) >= 0.5 || std::abs(y_prev) >= 0.5));
    }
  }
  const std::vector<float> weight = DepthEdgeWeights(points);
  int edges = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(weight[i] > 0, on_board_edge[i] == 1) << "point " << i;
    if (weight[i] > 0) {
      ++edges;
      // X = (10 − 5 m)^0.5 up to the wall's slant range.
      EXPECT_NEAR(weight[i], std::sqrt(5.0), 0.1);
    }
  }
  EXPECT_EQ(edges, 2 * 7);  // one column each side, seven rows
}

// Without an up axis: a floor and a wall are planes (each its own class) and a box off both is a
// cluster of its own.
TEST(CloudFeaturesWithoutUp, PlanesThenClusters) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 60; ++j) {
      points.emplace_back(1.0f + 0.1f * i, -3.0f + 0.1f * j, -1.5f);   // floor
      points.emplace_back(8.0f, -3.0f + 0.1f * j, -1.4f + 0.05f * i);  // wall
    }
  }
  const std::size_t box_begin = points.size();
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 8; ++k) {
        points.emplace_back(4.0f + 0.05f * i, 0.05f * j, -0.5f + 0.05f * k);  // a cube of points
      }
    }
  }
  const CloudFeatures f = ComputeCloudFeatures(points, std::nullopt);
  const int floor = f.segment[0], wall = f.segment[1], box = f.segment[box_begin];
  EXPECT_GT(floor, 0);
  EXPECT_GT(wall, 0);
  EXPECT_NE(floor, wall);
  EXPECT_GE(box, 0);
  EXPECT_NE(box, floor);
  EXPECT_NE(box, wall);
  int floor_same = 0;
  for (std::size_t i = 0; i < box_begin; i += 2) floor_same += f.segment[i] == floor;
  EXPECT_EQ(floor_same, 3600);
}

}  // namespace
}  // namespace autoshovel::identification
