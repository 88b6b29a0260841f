// Seed §3.2, Algorithm 1 on simulated data with a known extrinsic: the board step (PnP from the
// hole corners) and the auto-calibration from perturbed starts (issue 5: 2°/5 cm back within
// 0.3° and 2 cm, of which 2 cm is not met yet; 3° per axis back within 0.5°).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <utility>

#include "identification/camera_lidar/auto_calibration.h"
#include "identification/camera_lidar/board_detection.h"
#include "identification/camera_lidar/board_simulation.h"
#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/yard_simulation.h"
#include "runtime/model/description.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::identification {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct SimulatedData {
  model::MachineDescription machine;
  model::Lidar lidar;
  Eigen::Isometry3d T_lidar_camera;  // truth: the description's nominal mounting
  Eigen::Vector3d up_lidar;
  std::vector<ScoreFrame> frames;
};

// The ground-class settings (cloud_features.h), overridable from the environment so that the
// variants docs/camera_lidar_calibration.md compares ("Limits" 10) can be rerun with the Explore
// and noise-free tests: AUTOSHOVEL_CALIBRATION_GROUND_SIGMAS, _GROUND_MAX_K and _GROUND_BAND
// (the ground band's half-width, also the no-class band's top) [m].
CloudFeatureOptions GroundOptionsFromEnvironment() {
  CloudFeatureOptions options;
  if (const char* v = std::getenv("AUTOSHOVEL_CALIBRATION_GROUND_SIGMAS")) {
    options.ground_noise_sigmas = std::atof(v);
  }
  if (const char* v = std::getenv("AUTOSHOVEL_CALIBRATION_GROUND_MAX_K")) {
    options.max_ground_smoothing_neighbours = std::atoi(v);
  }
  if (const char* v = std::getenv("AUTOSHOVEL_CALIBRATION_GROUND_BAND")) {
    options.ground_class_threshold = options.object_min_height = std::atof(v);
  }
  return options;
}

SimulatedData Simulate(double range_noise) {
  SimulatedData s;
  const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  s.machine = model::LoadMachineDescription(model::ResolveMachineDescription("xcmg_968ev", models));
  for (const auto& l : s.machine.sensors.lidars) {
    if (l.name == "front_solid_state") s.lidar = l;
  }
  if (range_noise >= 0) s.lidar.range_noise = range_noise;
  const Eigen::Isometry3d T_base_lidar = sensors::PoseToIsometry(s.lidar.pose);
  s.T_lidar_camera =
      T_base_lidar.inverse() * sensors::PoseToIsometry(s.machine.sensors.camera.pose);
  s.up_lidar = T_base_lidar.linear().transpose() * Eigen::Vector3d::UnitZ();
  const CameraIntrinsics intrinsics = IntrinsicsFromDescription(s.machine.sensors.camera);
  for (const YardFrame& f : SimulateYardFrames(s.machine, s.lidar, s.T_lidar_camera, models)) {
    s.frames.push_back(PrepareScoreFrame(f.cloud, f.masks, intrinsics, s.up_lidar, 40000,
                                         GroundOptionsFromEnvironment()));
  }
  return s;
}

const SimulatedData& GetSimulatedData() {
  static const SimulatedData setup = Simulate(-1);  // the description's range noise
  return setup;
}

TEST(BoardCalibration, PnpFromHoleCornersRecoversTheExtrinsic) {
  const SimulatedData& s = GetSimulatedData();
  const BoardGeometry board;
  sensors::Rng rng(3);
  std::vector<BoardObservation> observations;
  const Eigen::Isometry3d T_base_lidar = sensors::PoseToIsometry(s.lidar.pose);
  const Eigen::Vector3d boresight = Eigen::Vector3d::UnitX();
  for (const Eigen::Isometry3d& T_base_board : DefaultBoardPoses(s.machine.sensors.camera)) {
    const SimulatedBoardFrame f = SimulateBoardFrame(
        s.machine.sensors.camera, s.lidar, s.T_lidar_camera, T_base_board, board, 1.0, rng);
    std::vector<Eigen::Vector3f> points;
    for (const auto& p : f.cloud.points) points.push_back(p.p_sensor);
    const BoardCloudDetection cloud = DetectBoardInCloud(points, board, s.up_lidar, boresight);
    ASSERT_TRUE(cloud.ok) << cloud.failure;
    const BoardImageDetection image = DetectBoardInImage(f.image);
    ASSERT_TRUE(image.ok) << image.failure;
    // The cloud's corners against the truth.
    const std::vector<Eigen::Vector3d> truth = board.HoleCorners();
    double worst = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const Eigen::Vector3d p_true = T_base_lidar.inverse() * T_base_board * truth[i];
      worst = std::max(worst, (p_true - cloud.corners_lidar[i]).norm());
    }
    const Eigen::Isometry3d T_true = T_base_lidar.inverse() * T_base_board;
    EXPECT_LT(worst, 0.02) << "edge rms " << cloud.edge_rms << " boundary " << cloud.boundary_points
                           << " inliers " << cloud.plane_inliers << "\ntrue\n"
                           << T_true.matrix() << "\nfound\n"
                           << cloud.T_lidar_board.matrix();
    observations.push_back({cloud.corners_lidar, image.corners_px});
  }
  const BoardCalibration result =
      SolveBoardPnP(observations, IntrinsicsFromDescription(s.machine.sensors.camera).K);
  ASSERT_TRUE(result.ok) << result.failure;
  const PoseError e = ComparePoses(result.T_lidar_camera, s.T_lidar_camera);
  std::printf("board PnP: %d boards, reprojection RMS %.3f px, error %.3f deg, %.1f mm\n",
              result.boards, result.reprojection_rms, e.rotation / kDeg, 1e3 * e.translation);
  EXPECT_LT(e.rotation, 0.2 * kDeg);
  EXPECT_LT(e.translation, 0.02);
  EXPECT_LT(result.reprojection_rms, 1.0);
}

TEST(AutoCalibration, TruthScoresHigherThanPerturbations) {
  const SimulatedData& s = GetSimulatedData();
  for (const ScoreSlice& slice : ScoreSurface(s.frames, s.T_lidar_camera, {}, 3.0, 0.1, 11)) {
    std::printf("%-6s", slice.parameter.c_str());
    for (const double r : slice.rho) std::printf(" %.4f", r);
    std::printf("\n");
  }
  const double truth = ConsistencyScore(s.frames, s.T_lidar_camera).rho;
  for (int k = 0; k < 6; ++k) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
    if (k < 3) {
      w[k] = 2 * kDeg;
    } else {
      t[k - 3] = 0.05;
    }
    EXPECT_GT(truth, ConsistencyScore(s.frames, Perturb(s.T_lidar_camera, w, t)).rho) << k;
  }
}

// The score's bias (docs, "Limits"): on noise-free frames ρ at the truth must not be exceeded
// 2 cm or 0.2° away along any axis.
TEST(AutoCalibration, NoiseFreeTruthIsTheMaximumAlongEveryAxis) {
  const SimulatedData s = Simulate(0.0);
  const double truth = ConsistencyScore(s.frames, s.T_lidar_camera).rho;
  for (int k = 0; k < 6; ++k) {
    for (const double sign : {-1.0, 1.0}) {
      Eigen::Vector3d w = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
      if (k < 3) {
        w[k] = sign * 0.2 * kDeg;
      } else {
        t[k - 3] = sign * 0.02;
      }
      EXPECT_GE(truth, ConsistencyScore(s.frames, Perturb(s.T_lidar_camera, w, t)).rho)
          << "axis " << k << " sign " << sign;
    }
  }
}

void ExpectRecovered(const Eigen::Vector3d& w, const Eigen::Vector3d& t, Lock lock,
                     double max_rotation, double max_translation) {
  const SimulatedData& s = GetSimulatedData();
  const Eigen::Isometry3d T0 = Perturb(s.T_lidar_camera, w, t);
  AutoCalibrationOptions options;
  options.lock = lock;
  const AutoCalibrationResult r = AutoCalibrate(s.frames, T0, options);
  const PoseError before = ComparePoses(T0, s.T_lidar_camera);
  const PoseError after = ComparePoses(r.T_lidar_camera, s.T_lidar_camera);
  // The camera's position error in the LiDAR frame (x forward, z up on the simulated mount).
  const Eigen::Vector3d error_lidar =
      1e3 * (r.T_lidar_camera.translation() - s.T_lidar_camera.translation());
  std::printf(
      "auto-calibration: %.2f deg %.1f mm -> %.3f deg %.1f mm (xyz %+.1f %+.1f %+.1f mm), "
      "rho %.4f -> %.4f, %d evaluations, %d runs, %.1f s\n",
      before.rotation / kDeg, 1e3 * before.translation, after.rotation / kDeg,
      1e3 * after.translation, error_lidar.x(), error_lidar.y(), error_lidar.z(), r.initial.rho,
      r.final.rho, r.evaluations, r.runs, r.seconds);
  EXPECT_LT(after.rotation, max_rotation);
  EXPECT_LT(after.translation, max_translation);
  EXPECT_GE(r.final.rho, r.initial.rho);
}

// Issue 5: from 2° / 5 cm back to within 0.3° and 2 cm. Measured here: 0.141°, 10.1 mm (every
// start of the Explore test below: 0.14–0.18°, 10–15 mm; before the floor's noise-adaptive
// height smoothing, cloud_features.h, 22–28 mm).
TEST(AutoCalibration, TwoDegreesFiveCentimetresRotationBackWithinSpec) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 1.5).normalized();
  const Eigen::Vector3d shift = Eigen::Vector3d(-1, 1, 0.5).normalized();
  ExpectRecovered(2 * kDeg * axis, 0.05 * shift, Lock::kNone, 0.3 * kDeg, 0.02);
}

// Issue 5: from 3° per axis back to within 0.5° (and the translation within 2 cm all the same).
// Measured: 0.146°, 10.5 mm.
TEST(AutoCalibration, ThreeDegreesPerAxisBackWithinHalfADegree) {
  ExpectRecovered(Eigen::Vector3d(3, -3, 3) * kDeg, Eigen::Vector3d::Zero(), Lock::kNone,
                  0.5 * kDeg, 0.02);
}

TEST(AutoCalibration, ThreeDegreesPerAxisTranslationLocked) {
  ExpectRecovered(Eigen::Vector3d(3, -3, 3) * kDeg, Eigen::Vector3d::Zero(), Lock::kTranslation,
                  0.3 * kDeg, 1e-12);
}

TEST(AutoCalibration, LockedTranslationKeepsIt) {
  const SimulatedData& s = GetSimulatedData();
  const Eigen::Isometry3d T0 =
      Perturb(s.T_lidar_camera, Eigen::Vector3d(0, 2, -1) * kDeg, Eigen::Vector3d(0.03, 0, 0));
  AutoCalibrationOptions options;
  options.lock = Lock::kTranslation;
  const AutoCalibrationResult r = AutoCalibrate(s.frames, T0, options);
  EXPECT_EQ(r.T_lidar_camera.translation(), T0.translation());
  EXPECT_LT(ComparePoses(r.T_lidar_camera, s.T_lidar_camera).rotation, 0.5 * kDeg);
}

TEST(AutoCalibration, LockedRotationKeepsIt) {
  const SimulatedData& s = GetSimulatedData();
  const Eigen::Isometry3d T0 =
      Perturb(s.T_lidar_camera, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.04, -0.04, 0.03));
  AutoCalibrationOptions options;
  options.lock = Lock::kRotation;
  const AutoCalibrationResult r = AutoCalibrate(s.frames, T0, options);
  EXPECT_TRUE(r.T_lidar_camera.linear().isApprox(T0.linear(), 1e-12));
  EXPECT_LT(ComparePoses(r.T_lidar_camera, s.T_lidar_camera).translation, 0.03);
}

// Opt-in (AUTOSHOVEL_CALIBRATION_EXPLORE=1): other start directions than the tests', printed,
// for docs/camera_lidar_calibration.md's table. The bounds are the 3° test's (0.5°, 2 cm).
TEST(AutoCalibration, Explore) {
  if (std::getenv("AUTOSHOVEL_CALIBRATION_EXPLORE") == nullptr) GTEST_SKIP();
  const std::pair<Eigen::Vector3d, Eigen::Vector3d> twos[] = {{{1, -2, 1.5}, {-1, 1, 0.5}},
                                                              {{-2, 1, 1}, {1, 0.5, -1}},
                                                              {{1, 1, -1}, {0.3, -1, 1}},
                                                              {{0, 1, 0.3}, {0, 0, 1}}};
  for (const auto& [a, b] : twos) {
    ExpectRecovered(2 * kDeg * a.normalized(), 0.05 * b.normalized(), Lock::kNone, 0.5 * kDeg,
                    0.02);
  }
  for (const Eigen::Vector3d& w : {Eigen::Vector3d(3, -3, 3), Eigen::Vector3d(-3, 3, 3)}) {
    ExpectRecovered(w * kDeg, Eigen::Vector3d::Zero(), Lock::kNone, 0.5 * kDeg, 0.02);
  }
}

}  // namespace
}  // namespace autoshovel::identification
