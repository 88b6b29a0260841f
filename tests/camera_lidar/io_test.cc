// The readers of the camera–LiDAR calibration: point clouds (PCD in its three encodings, KITTI
// .bin), masks (PNG folder, COCO RLE), undistortion, and the exact messages for bad files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/mask_io.h"
#include "identification/camera_lidar/ply_io.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {
namespace {

const std::string kData = std::string(AUTOSHOVEL_SOURCE_DIR) + "/tests/data/camera_lidar";

std::string TempDir(const std::string& name) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("camera_lidar_" + name)).string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

sensors::PointCloud RandomCloud(int n) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-20, 20), r(0, 1);
  sensors::PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    sensors::LidarPoint p;
    p.p_sensor = Eigen::Vector3f(u(rng), u(rng), u(rng));
    p.intensity = r(rng);
    cloud.points.push_back(p);
  }
  return cloud;
}

// PLY (issue 43): our binary little-endian writer read back, and a big-endian file of doubles
// with a ushort intensity written byte by byte.
TEST(PointCloudIo, PlyRoundTripAndOtherTypesAndByteOrders) {
  const std::string dir = TempDir("ply");
  const sensors::PointCloud cloud = RandomCloud(300);
  WritePly(dir + "/cloud.ply", cloud);
  const sensors::PointCloud back = ReadPointCloud(dir + "/cloud.ply");
  ASSERT_EQ(back.points.size(), cloud.points.size());
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    EXPECT_EQ(back.points[i].p_sensor, cloud.points[i].p_sensor);
    EXPECT_EQ(back.points[i].intensity, cloud.points[i].intensity);
  }
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\n"
      "property double y\nproperty double z\nproperty ushort intensity\nend_header\n";
  auto big = [&](const void* p, int n) {
    for (int k = n - 1; k >= 0; --k) bytes.push_back(static_cast<const char*>(p)[k]);
  };
  const double xyz[3] = {1.25, -2.5, 3.75};
  for (const double v : xyz) big(&v, 8);
  const std::uint16_t intensity = 513;
  big(&intensity, 2);
  std::ofstream(dir + "/big.ply", std::ios::binary) << bytes;
  const sensors::PointCloud one = ReadPointCloud(dir + "/big.ply");
  ASSERT_EQ(one.points.size(), 1u);
  EXPECT_EQ(one.points[0].p_sensor, Eigen::Vector3f(1.25f, -2.5f, 3.75f));
  EXPECT_EQ(one.points[0].intensity, 513.0f);
}

TEST(PointCloudIo, PcdInEveryEncodingAndKittiBinRoundTrip) {
  const std::string dir = TempDir("io");
  const sensors::PointCloud cloud = RandomCloud(500);
  const std::pair<std::string, PcdEncoding> cases[] = {
      {"ascii.pcd", PcdEncoding::kAscii},
      {"binary.pcd", PcdEncoding::kBinary},
      {"compressed.pcd", PcdEncoding::kBinaryCompressed}};
  for (const auto& [name, encoding] : cases) {
    WritePcd(dir + "/" + name, cloud, encoding);
    const sensors::PointCloud back = ReadPointCloud(dir + "/" + name);
    ASSERT_EQ(back.points.size(), cloud.points.size()) << name;
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
      EXPECT_LT((back.points[i].p_sensor - cloud.points[i].p_sensor).norm(), 1e-4f) << name;
      EXPECT_NEAR(back.points[i].intensity, cloud.points[i].intensity, 1e-5f) << name;
    }
  }
  WriteKittiBin(dir + "/cloud.bin", cloud);
  const sensors::PointCloud back = ReadPointCloud(dir + "/cloud.bin");
  ASSERT_EQ(back.points.size(), cloud.points.size());
  EXPECT_EQ(back.points[17].p_sensor, cloud.points[17].p_sensor);
  EXPECT_EQ(ReadPointCloud(dir + "/cloud.bin", 100).points.size(), 100u);  // reservoir cap
  EXPECT_EQ(ReadPointCloud(dir + "/compressed.pcd", 100).points.size(), 100u);
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(PointCloudIo, BadFilesAreRefusedWithFileAndLine) {
  EXPECT_EQ(ErrorOf([] { ReadPointCloud(kData + "/truncated.pcd"); }),
            kData + "/truncated.pcd:14:1: truncated: the header promises 4 points, 2 follow");
  EXPECT_EQ(ErrorOf([] { ReadPointCloud(kData + "/truncated_binary.pcd"); }),
            kData +
                "/truncated_binary.pcd:10:1: DATA: truncated: the header promises 10 points "
                "(160 bytes), 48 follow");
  EXPECT_EQ(
      ErrorOf([] { ReadPointCloud(kData + "/wrong_field_count.pcd"); }),
      kData + "/wrong_field_count.pcd:3:1: SIZE: has 3 values for 4 FIELDS (x y z intensity)");
  EXPECT_EQ(ErrorOf([] { ReadPointCloud(kData + "/short_row.pcd"); }),
            kData + "/short_row.pcd:12:1: expected 4 values (x y z intensity), got 3");
  EXPECT_EQ(ErrorOf([] { ReadPointCloud(kData + "/nan_header.pcd"); }),
            kData + "/nan_header.pcd:8:1: VIEWPOINT: value 3 'nan' is not a finite number");
  EXPECT_EQ(ErrorOf([] { ReadPointCloud(kData + "/size_not_16.bin"); }),
            kData +
                "/size_not_16.bin: size 19 bytes is not a multiple of 16 (float32 x, y, z, "
                "intensity per point)");
}

TEST(Masks, FolderAndRleRoundTrip) {
  cv::Mat a(40, 60, CV_8U, cv::Scalar(0)), b = a.clone();
  cv::circle(a, {20, 20}, 12, 255, -1);
  cv::rectangle(b, {30, 5}, {55, 35}, 255, -1);
  const std::string dir = TempDir("masks");
  WriteMaskFolder(dir, MaskSet{60, 40, {a, b}});
  const MaskSet back = ReadMasks(dir, 60, 40);
  ASSERT_EQ(back.masks.size(), 2u);
  EXPECT_EQ(cv::countNonZero(back.masks[0] != a), 0);
  EXPECT_EQ(cv::countNonZero(back.masks[1] != b), 0);
  // Compressed strings (pycocotools' encoding) and uncompressed counts decode to the same mask.
  for (const cv::Mat& m : {a, b}) {
    const cv::Mat decoded = DecodeRle(DecodeRleString(EncodeRleString(m)), 40, 60);
    EXPECT_EQ(cv::countNonZero(decoded != m), 0);
  }
  // Column-major runs: 2 background, 3 inside in a 4 x 3 image -> (2,0), (3,0), (0,1).
  const cv::Mat small = DecodeRle({2, 3, 7}, 4, 3);
  EXPECT_EQ(small.at<std::uint8_t>(2, 0), 255);
  EXPECT_EQ(small.at<std::uint8_t>(3, 0), 255);
  EXPECT_EQ(small.at<std::uint8_t>(0, 1), 255);
  EXPECT_EQ(small.at<std::uint8_t>(1, 1), 0);
  EXPECT_EQ(cv::countNonZero(small), 3);
  // pycocotools' string for that mask: counts 2, 3, 7 → '2' '3' '7' (48 + count; deltas to the
  // count two before start with the fourth count).
  EXPECT_EQ(EncodeRleString(small), "237");
  EXPECT_EQ(DecodeRleString("237"), (std::vector<std::uint32_t>{2, 3, 7}));
  const std::string json = TempDir("rle") + "/masks.json";
  std::ofstream(json) << "[{\"segmentation\": {\"size\": [40, 60], \"counts\": \""
                      << EncodeRleString(a) << "\"}}]\n";
  EXPECT_EQ(cv::countNonZero(ReadMasks(json, 60, 40).masks[0] != a), 0);
  // Smallest mask wins where masks overlap.
  const cv::Mat labels = MaskLabelImage(MaskSet{60, 40, {a, b}});
  EXPECT_EQ(labels.at<int>(20, 31), 1);  // inside both: the circle is smaller
}

TEST(Masks, BadMasksAreRefusedNamingTheFile) {
  EXPECT_EQ(ErrorOf([] { ReadMasks(kData + "/wrong_size_masks/frame", 480, 383); }),
            kData + "/wrong_size_masks/frame/0.png: mask is 8 x 6 px, the image is 480 x 383 px");
  EXPECT_EQ(ErrorOf([] { ReadMasks(kData + "/empty_masks", 480, 383); }),
            kData + "/empty_masks: no mask PNGs in the folder");
  EXPECT_EQ(ErrorOf([] { ReadMasks(kData + "/bad_rle.json", 3, 4); }),
            kData +
                "/bad_rle.json:3:20: [1].segmentation.counts: run lengths add up to 6, not "
                "4 x 3 = 12");
}

TEST(CameraModel, UndistortionRestoresThePinholeImage) {
  CameraIntrinsics c;
  c.width = 320;
  c.height = 240;
  c.K << 250, 0, 160, 0, 250, 120, 0, 0, 1;
  c.D = {-0.25, 0.08, 0.001, -0.0005, 0};
  cv::Mat ideal(240, 320, CV_8U);
  for (int v = 0; v < 240; ++v) {
    for (int u = 0; u < 320; ++u) ideal.at<std::uint8_t>(v, u) = ((u / 20 + v / 20) % 2) ? 220 : 30;
  }
  // The distorted image a real lens gives: pixel p_d shows the ideal image at undistort(p_d).
  cv::Mat K(3, 3, CV_64F), D(1, 5, CV_64F);
  for (int i = 0; i < 9; ++i) K.at<double>(i / 3, i % 3) = c.K(i / 3, i % 3);
  for (int i = 0; i < 5; ++i) D.at<double>(0, i) = c.D[i];
  std::vector<cv::Point2f> distorted, ideal_points;
  for (int v = 0; v < 240; ++v) {
    for (int u = 0; u < 320; ++u)
      distorted.emplace_back(static_cast<float>(u), static_cast<float>(v));
  }
  cv::undistortPoints(distorted, ideal_points, K, D, cv::noArray(), K);
  cv::Mat map(240, 320, CV_32FC2);
  for (int i = 0; i < 240 * 320; ++i)
    map.at<cv::Vec2f>(i / 320, i % 320) = {ideal_points[i].x, ideal_points[i].y};
  cv::Mat raw;
  cv::remap(ideal, raw, map, cv::noArray(), cv::INTER_LINEAR);
  const cv::Mat restored = Undistort(raw, c, false);
  const cv::Rect centre(40, 30, 240, 180);
  cv::Mat diff_before, diff_after;
  cv::absdiff(raw(centre), ideal(centre), diff_before);
  cv::absdiff(restored(centre), ideal(centre), diff_after);
  EXPECT_GT(cv::mean(diff_before)[0], 15.0);
  EXPECT_LT(cv::mean(diff_after)[0], 6.0);
}

}  // namespace
}  // namespace autoshovel::identification
