// Issue 38, defects 6 and 8: sizes are checked from headers before anything is decoded (image
// dimensions, a PCD's point count, a .bin's size), and clouds without enough finite points do
// not count as frames.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>
#include <string>

#include "identification/camera_lidar/calibrate_camera_lidar_command.h"
#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/image_header.h"
#include "identification/camera_lidar/mask_io.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {
namespace {

namespace fs = std::filesystem;

const std::string kSource = AUTOSHOVEL_SOURCE_DIR;

std::string TempDir(const std::string& name) {
  const std::string dir = (fs::temp_directory_path() / ("camera_lidar_limits_" + name)).string();
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string BigEndian32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
          static_cast<char>(v)};
}

// A PNG of signature and IHDR only: it announces a size and holds no pixels. cv::imread cannot
// decode it, so a message about its size proves the size was read from the header.
std::string PngHeaderOnly(std::uint32_t width, std::uint32_t height) {
  return std::string("\x89PNG\r\n\x1a\n", 8) + BigEndian32(13) + "IHDR" + BigEndian32(width) +
         BigEndian32(height) + std::string("\x08\x00\x00\x00\x00", 5) + BigEndian32(0);
}

TEST(ImageHeader, ReadsPngAndJpegDimensionsWithoutDecoding) {
  const std::string dir = TempDir("header");
  const cv::Mat image(383, 480, CV_8UC3, cv::Scalar(20, 120, 220));
  ASSERT_TRUE(cv::imwrite(dir + "/a.png", image));
  ASSERT_TRUE(cv::imwrite(dir + "/b.jpg", image));
  ASSERT_TRUE(cv::imwrite(dir + "/c.jpg", image, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}));
  for (const char* name : {"a.png", "b.jpg", "c.jpg"}) {
    const ImageHeader header = ReadImageHeader(dir + "/" + name);
    EXPECT_EQ(header.width, 480) << name;
    EXPECT_EQ(header.height, 383) << name;
  }
  EXPECT_EQ(ReadImageHeader(dir + "/a.png").format, "PNG");
  EXPECT_EQ(ReadImageHeader(dir + "/c.jpg").format, "JPEG");
}

// The probe of the issue: a PNG whose IHDR says 20000 x 20000 px took 1.3 GB in cv::imread.
TEST(ImageHeader, RefusesAPngBombFromItsHeader) {
  const std::string path = TempDir("bomb") + "/bomb.png";
  WriteBytes(path, PngHeaderOnly(20000, 20000));
  EXPECT_EQ(ErrorOf([&] { ReadImageHeader(path); }),
            path +
                ": PNG header says 20000 x 20000 px (400 Mpx), more than the 100 Mpx an input "
                "image may have: not decoded");
}

TEST(ImageHeader, CameraImageOfTheWrongSizeIsRefusedBeforeDecoding) {
  const std::string dir = TempDir("frame_size");
  WriteBytes(dir + "/frame.png", PngHeaderOnly(9000, 9000));
  WriteCameraInfoYaml(dir + "/intrinsics.yaml", [] {
    CameraIntrinsics c;
    c.width = 480;
    c.height = 383;
    c.K << 400, 0, 240, 0, 400, 190, 0, 0, 1;
    return c;
  }());
  CalibrateCameraLidarOptions options;
  options.machine = "xcmg_968ev";
  options.models_dir = kSource + "/models";
  options.pairs = {dir + "/frame.png," + dir + "/frame.pcd"};
  options.intrinsics = dir + "/intrinsics.yaml";
  options.masks = "none";
  std::ostringstream out, err;
  EXPECT_EQ(RunCalibrateCameraLidar(options, out, err), 2);
  EXPECT_EQ(err.str(), dir +
                           "/frame.png: image is 9000 x 9000 px (PNG header), the intrinsics say "
                           "480 x 383 px: not decoded\n");
}

TEST(ImageHeader, MaskPngOfTheWrongSizeIsRefusedBeforeDecoding) {
  const std::string path = TempDir("mask_size") + "/labels.png";
  WriteBytes(path, PngHeaderOnly(4000, 3000));
  EXPECT_EQ(ErrorOf([&] { ReadMasks(path, 8, 6); }),
            path + ": mask is 4000 x 3000 px, the image is 8 x 6 px");
}

TEST(PointCloudLimits, APcdPromisingABillionPointsIsRefusedFromItsHeader) {
  const std::string dir = TempDir("pcd");
  const std::string header =
      "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
      "WIDTH 1000000000\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1000000000\n";
  const std::string limit = "points, more than the 20000000 a point cloud may have: not decoded";
  for (const char* data : {"ascii", "binary", "binary_compressed"}) {
    const std::string path = dir + "/" + data + ".pcd";
    WriteBytes(path, header + "DATA " + data + "\n" + std::string(16, '\0'));
    EXPECT_EQ(ErrorOf([&] { ReadPointCloud(path); }), path + ":9:1: POINTS: 1000000000 " + limit);
  }
  // Without POINTS, WIDTH x HEIGHT says it (and is not multiplied before it is checked).
  const std::string path = dir + "/no_points.pcd";
  WriteBytes(path,
             "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
             "WIDTH 4611686018427387904\nHEIGHT 4\nDATA binary\n");
  EXPECT_EQ(ErrorOf([&] { ReadPointCloud(path); }),
            path +
                ":6:1: WIDTH: 4611686018427387904 x HEIGHT 4 is more than the 20000000 points a "
                "point cloud may have: not decoded");
}

TEST(PointCloudLimits, AKittiBinOverTheLimitIsRefusedFromItsSize) {
  const std::string path = TempDir("bin") + "/huge.bin";
  std::ofstream(path).close();
  // Sparse: no disk is used and nothing is written; the reader must not read it either.
  fs::resize_file(path, (kMaxCloudPoints + 1) * 16);
  EXPECT_EQ(ErrorOf([&] { ReadPointCloud(path, 1000); }),
            path +
                ": size 320000016 bytes is 20000001 points, more than the 20000000 a point "
                "cloud may have: not read");
  fs::remove(path);
}

TEST(PointCloudLimits, NonFinitePointsAreDroppedAndCounted) {
  const std::string dir = TempDir("nan");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  WriteBytes(dir + "/cloud.pcd",
             "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
             "WIDTH 5\nHEIGHT 1\nPOINTS 5\nDATA ascii\n"
             "1 2 3 0.5\nnan nan nan 0\n4 5 6 0.5\n1 nan 2 0\n7 8 9 nan\n");
  PointCloudReadStats stats;
  EXPECT_EQ(ReadPointCloud(dir + "/cloud.pcd", 0, &stats).points.size(), 3u);
  EXPECT_EQ(stats.points_in_file, 5u);
  EXPECT_EQ(stats.non_finite, 2u);
  EXPECT_EQ(stats.finite(), 3u);
  {
    std::ofstream bin(dir + "/cloud.bin", std::ios::binary);
    const float v[4][4] = {{1, 2, 3, 0}, {nan, 0, 0, 0}, {0, inf, 0, 0}, {4, 5, 6, nan}};
    bin.write(reinterpret_cast<const char*>(v), sizeof v);
  }
  EXPECT_EQ(ReadPointCloud(dir + "/cloud.bin", 0, &stats).points.size(), 2u);
  EXPECT_EQ(stats.points_in_file, 4u);
  EXPECT_EQ(stats.non_finite, 2u);
}

// Issue 38, defect 8: an all-NaN cloud counted as a frame ("5 frames", no warning) and worsened
// the calibration.
TEST(CalibrateCameraLidarCommand, AnAllNanCloudIsNoFrame) {
  const std::string root = TempDir("all_nan");
  fs::create_directories(root + "/frames");
  CameraIntrinsics intrinsics;
  intrinsics.width = 64;
  intrinsics.height = 48;
  intrinsics.K << 50, 0, 32, 0, 50, 24, 0, 0, 1;
  WriteCameraInfoYaml(root + "/intrinsics.yaml", intrinsics);
  ASSERT_TRUE(
      cv::imwrite(root + "/frames/frame_000.png", cv::Mat(48, 64, CV_8UC3, cv::Scalar(90))));
  sensors::PointCloud cloud;
  for (int i = 0; i < 2000; ++i) {
    sensors::LidarPoint p;
    p.p_sensor = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
    cloud.points.push_back(p);
  }
  WritePcd(root + "/frames/frame_000.pcd", cloud, PcdEncoding::kBinary);
  CalibrateCameraLidarOptions options;
  options.machine = "xcmg_968ev";
  options.models_dir = kSource + "/models";
  options.frames = root + "/frames";
  options.masks = "none";
  std::ostringstream out, err;
  EXPECT_EQ(RunCalibrateCameraLidar(options, out, err), 2) << out.str();
  EXPECT_EQ(err.str(),
            "autoshovel calibrate camera-lidar: warning: " + root +
                "/frames/frame_000.pcd: 0 of 2000 points are finite (2000 NaN or infinite "
                "dropped), fewer than the 1000 a frame needs: frame 'frame_000' skipped\n" +
                root +
                "/frames: no usable frame: all 1 point clouds have fewer than 1000 finite "
                "points\n");
  EXPECT_FALSE(fs::exists(root + "/camera_lidar.overlay.yaml"));
}

}  // namespace
}  // namespace autoshovel::identification
