// `autoshovel calibrate camera-lidar` end to end on its own simulated data set, and its refusal
// of bad input: the message names the file and line, and nothing is written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "identification/camera_lidar/calibrate_camera_lidar_command.h"
#include "identification/camera_lidar/rig_files.h"

namespace autoshovel::identification {
namespace {

const std::string kSource = AUTOSHOVEL_SOURCE_DIR;

TEST(CalibrateCameraLidarCommand, SimulatedDataSetEndToEnd) {
  const std::string dir = (std::filesystem::temp_directory_path() / "camera_lidar_cli").string();
  std::filesystem::remove_all(dir);
  CalibrateCameraLidarOptions options;
  options.machine = "xcmg_968ev";
  options.models_dir = kSource + "/models";
  options.simulate = dir;
  std::ostringstream out, err;
  ASSERT_EQ(RunCalibrateCameraLidar(options, out, err), 0) << err.str();
  options.simulate.clear();
  options.frames = dir + "/frames";
  options.board = dir + "/board";
  std::ostringstream out2, err2;
  ASSERT_EQ(RunCalibrateCameraLidar(options, out2, err2), 0) << err2.str();
  std::printf("%s", out2.str().c_str());
  EXPECT_NE(out2.str().find("against the simulation truth"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir + "/camera_lidar.overlay.yaml"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/camera_lidar.overlay.projection.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/camera_lidar.overlay.surface.png"));
}

TEST(CalibrateCameraLidarCommand, TruncatedCloudNamesFileAndLineAndWritesNothing) {
  const std::string overlay =
      (std::filesystem::temp_directory_path() / "camera_lidar_bad.overlay.yaml").string();
  std::filesystem::remove(overlay);
  CalibrateCameraLidarOptions options;
  options.machine = "xcmg_968ev";
  options.models_dir = kSource + "/models";
  options.frames = kSource + "/tests/data/camera_lidar/frames_truncated";
  options.masks = "none";
  options.overlay = overlay;
  std::ostringstream out, err;
  EXPECT_EQ(RunCalibrateCameraLidar(options, out, err), 2);
  EXPECT_EQ(err.str(), options.frames +
                           "/frame_000.pcd:14:1: truncated: the header promises 4 points, 2 "
                           "follow\n");
  EXPECT_FALSE(std::filesystem::exists(overlay));
  EXPECT_FALSE(std::filesystem::exists(overlay + ".tmp"));
}

// A standalone rig (no machine): a synthetic street scene in the CalibAnything layout, started
// 1° per axis off its calib.txt; the result is written as a 4×4 LiDAR→optical matrix and is
// closer in rotation than the start.
TEST(CalibrateCameraLidarCommand, StandaloneSceneFolderFromAPerturbedStart) {
  const std::string dir = (std::filesystem::temp_directory_path() / "camera_lidar_scene").string();
  std::filesystem::remove_all(dir);
  CalibrateCameraLidarOptions simulate;
  simulate.simulate = dir + "/scene";
  std::ostringstream out0, err0;
  ASSERT_EQ(RunCalibrateCameraLidar(simulate, out0, err0), 0) << err0.str();
  CalibrateCameraLidarOptions options;
  options.scenes = {dir + "/scene"};
  options.perturb = {1, -1, 1, 0, 0, 0};
  options.extrinsic_out = dir + "/out/extrinsic.txt";
  options.overlay = dir + "/out/run.yaml";
  std::ostringstream out, err;
  ASSERT_EQ(RunCalibrateCameraLidar(options, out, err), 0) << err.str();
  std::printf("%s", out.str().c_str());
  EXPECT_NE(out.str().find("a standalone rig"), std::string::npos);
  EXPECT_NE(out.str().find("against the reference"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/run.yaml"));  // no machine: no overlay
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/run.projection.png"));
  const Eigen::Isometry3d truth = ReadExtrinsic(dir + "/scene/calib.txt");
  const Eigen::Isometry3d start =
      truth * ProtocolDelta(Eigen::Vector3d(1, -1, 1) * std::numbers::pi / 180, {0, 0, 0});
  const Eigen::Isometry3d result = ReadExtrinsic(options.extrinsic_out);
  EXPECT_LT(CompareExtrinsics(truth, result).rotation, CompareExtrinsics(truth, start).rotation);
  EXPECT_LT(CompareExtrinsics(truth, result).rotation, 0.8 * std::numbers::pi / 180);
}

// The board step from picked corners: exact correspondences give the truth as the start.
TEST(CalibrateCameraLidarCommand, CorrespondencesGiveThePnPStart) {
  const std::string dir = (std::filesystem::temp_directory_path() / "camera_lidar_pnp").string();
  std::filesystem::remove_all(dir);
  CalibrateCameraLidarOptions simulate;
  simulate.simulate = dir + "/scene";
  std::ostringstream out0, err0;
  ASSERT_EQ(RunCalibrateCameraLidar(simulate, out0, err0), 0) << err0.str();
  const RigCalibrationFile calib = ReadCalibTxt(dir + "/scene/calib.txt");
  std::ofstream corners(dir + "/corners.txt");
  corners << "# u v x y z\n";
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(6, 1, -1), Eigen::Vector3d(7, -1.5, 0.5), Eigen::Vector3d(9, 2, 1),
        Eigen::Vector3d(5, -0.5, -1.2), Eigen::Vector3d(12, 0, 2), Eigen::Vector3d(8, 3, -0.3)}) {
    const Eigen::Vector3d q = *calib.T_optical_lidar * p;
    const Eigen::Vector3d uv = *calib.K * (q / q.z());
    corners << uv.x() << " " << uv.y() << " " << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  corners.close();
  CalibrateCameraLidarOptions options;
  options.scenes = {dir + "/scene"};
  options.correspondences = dir + "/corners.txt";
  options.evaluate_only = true;
  options.extrinsic_out = dir + "/out/extrinsic.txt";
  options.overlay = dir + "/out/run.yaml";
  std::ostringstream out, err;
  ASSERT_EQ(RunCalibrateCameraLidar(options, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("PnP on 6 of 6 correspondences"), std::string::npos) << out.str();
  const ProtocolError e =
      CompareExtrinsics(*calib.T_optical_lidar, ReadExtrinsic(options.extrinsic_out));
  EXPECT_LT(e.rotation, 1e-5);
  EXPECT_LT(e.translation, 1e-4);
}

TEST(CalibrateCameraLidarCommand, AStandaloneRigWithoutIntrinsicsIsToldWhatToGive) {
  const std::string dir = (std::filesystem::temp_directory_path() / "camera_lidar_noK").string();
  std::filesystem::remove_all(dir);
  CalibrateCameraLidarOptions simulate;
  simulate.simulate = dir + "/scene";
  std::ostringstream out0, err0;
  ASSERT_EQ(RunCalibrateCameraLidar(simulate, out0, err0), 0) << err0.str();
  std::filesystem::remove(dir + "/scene/calib.txt");
  CalibrateCameraLidarOptions options;
  options.scenes = {dir + "/scene"};
  std::ostringstream out, err;
  EXPECT_EQ(RunCalibrateCameraLidar(options, out, err), 2);
  EXPECT_NE(err.str().find("no intrinsics: give --intrinsics camera_info.yaml or --calib "
                           "calib.txt"),
            std::string::npos)
      << err.str();
}

}  // namespace
}  // namespace autoshovel::identification
