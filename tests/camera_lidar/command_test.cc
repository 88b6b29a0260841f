// `autoshovel calibrate camera-lidar` end to end on its own simulated data set, and its refusal
// of bad input: the message names the file and line, and nothing is written.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "identification/camera_lidar/calibrate_camera_lidar_command.h"

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

}  // namespace
}  // namespace autoshovel::identification
