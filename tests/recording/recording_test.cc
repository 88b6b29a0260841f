// The recording folder (runtime/recording, docs/recording_format.md): what is written reads back
// bit for bit, and every malformed table, manifest or frame file is refused at its place.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "runtime/core/diagnostics.h"
#include "runtime/core/semantic_class.h"
#include "runtime/recording/recording_reader.h"
#include "runtime/recording/recording_writer.h"

namespace autoshovel::recording {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("recording_" + name);
  fs::remove_all(dir);
  return dir;
}

fs::path WriteDescription(const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path path = dir / "machine_source.yaml";
  std::ofstream(path) << "# not parsed by the recording library\nname: test_loader\n";
  return path;
}

Manifest TestManifest() {
  Manifest m;
  m.source = "recording_test";
  m.map_resolution = 0.3;
  m.map_length = {60.0, 45.0};
  m.map_center = {1.0 / 3.0, -2.0 / 7.0};  // not exact in decimal: must survive the round trip
  m.selection.k_t = 0.1 + 0.2;
  m.selection.entry_angle_offsets = {-std::numbers::pi / 7, 0.0, std::numbers::pi / 11};
  m.selection.max_curvature = 0.123456789012345678;
  m.min_planned_clearance = 0.5;
  m.chen2024 = true;
  return m;
}

perception::SensorFrames TestFrames(std::mt19937& rng, bool camera) {
  std::uniform_real_distribution<float> u(-30.0f, 30.0f);
  perception::SensorFrames frames;
  perception::LidarFrame lidar;
  lidar.lidar = "front_lidar";
  lidar.stamp = 12.0 + 1.0 / 7.0;
  lidar.T_world_lidar = Eigen::Translation3d(3.1, -4.7, 2.2) *
                        Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -0.3, 1.0).normalized());
  for (int i = 0; i < 500; ++i) {
    sensors::LidarPoint p;
    p.p_sensor = {u(rng), u(rng), u(rng) / 10};
    p.intensity = std::abs(u(rng)) / 30;
    p.ring = static_cast<std::uint16_t>(i % 16);
    p.time_offset = static_cast<float>(i) * 1e-4f;
    lidar.cloud.points.push_back(p);
  }
  lidar.health_check_rays = {Eigen::Vector3d::UnitX()};
  frames.lidar.push_back(lidar);
  if (camera) {
    sensors::CameraFrame image;
    image.stamp = 12.5;
    image.width = 40;
    image.height = 30;
    for (int i = 0; i < image.width * image.height; ++i) {
      image.labels.push_back(static_cast<std::uint8_t>(i % core::kNumSemanticClasses));
      for (int c = 0; c < 3; ++c) image.bgr.push_back(static_cast<std::uint8_t>((i * 7 + c) % 256));
    }
    frames.camera = image;
    frames.T_world_camera =
        Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitZ());
  }
  return frames;
}

// A recording of two cycles, three updates, written to `dir`.
void WriteTestRecording(const fs::path& dir, std::mt19937& rng) {
  RecordingWriter writer(dir, WriteDescription(dir.string() + "_src").string(), TestManifest());
  writer.SetPerception(true, 0.75);
  const fs::path overlay = dir.string() + "_src/arm calibration.overlay.yaml";
  std::ofstream(overlay) << "# not parsed by the recording library\nmachine: test_loader\n";
  writer.AddOverlay(overlay.string());
  WorkArea bin;
  bin.front_center = {10.0 / 3.0, 5.0};
  bin.yaw = 0.3;
  bin.width = 8;
  bin.depth = 6;
  writer.BeginCycle({.index = 0, .site = "bin_1", .area = bin, .scoop = std::nullopt});
  UpdateRow row;
  row.stamp = 12.0;
  row.hinge_xy = {0.1, 0.2};
  row.heading = 1.0 / 3.0;
  row.articulation = -0.05;
  row.tip_reach = 5.3;
  EXPECT_EQ(writer.AddUpdate(row, TestFrames(rng, true), "camera"), 0);
  row.stamp = 12.0 + 1.0 / 7.0;
  row.select = true;
  row.select_xy = {0.11, 0.21};
  row.select_heading = 0.3;
  EXPECT_EQ(writer.AddUpdate(row, TestFrames(rng, false), "camera"), 1);
  WorkArea yard;
  yard.kind = WorkArea::Kind::kDiscs;
  yard.discs = {{1, 2, 3.5}, {-4, 5, 2}};
  writer.BeginCycle({.index = 1, .site = "open yard", .area = yard, .scoop = std::nullopt});
  row.stamp = 20.0;
  row.select = false;
  EXPECT_EQ(writer.AddUpdate(row, perception::SensorFrames{}, "camera"), 2);
  writer.AddReference("2,abc", "");
  writer.SetScoop(
      {.material = "river_sand", .target_volume = 3.5, .bucket_max = 0.9, .boom_lift = 0.35});
  const std::vector<Eigen::Vector3d> path = {{1.0 / 3.0, 2, -0.01}, {1.5, 2, -0.02}};
  writer.AddScoop({{.cycle = 1,
                    .time = 20.05,
                    .hinge_xy = {0.2, 0.1},
                    .heading = 0.5,
                    .speed = 1.5,
                    .q_boom = -0.52,
                    .q_bucket = 0.21,
                    .path_points = 2,
                    .predict = true}},
                  {0.0}, {0.125}, path);
  writer.Close();
}

TEST(Recording, RoundTripIsBitExact) {
  const fs::path dir = FreshDir("round_trip");
  std::mt19937 rng(7);
  WriteTestRecording(dir, rng);
  const Recording rec(dir);
  const Manifest m = rec.manifest();
  const Manifest expected = TestManifest();
  EXPECT_EQ(m.map_center, expected.map_center);
  EXPECT_EQ(m.map_length, expected.map_length);
  EXPECT_EQ(m.selection.k_t, expected.selection.k_t);
  EXPECT_EQ(m.selection.max_curvature, expected.selection.max_curvature);
  EXPECT_EQ(m.selection.entry_angle_offsets, expected.selection.entry_angle_offsets);
  EXPECT_TRUE(m.chen2024);
  EXPECT_EQ(m.truth_labels, std::optional<bool>(true));
  EXPECT_EQ(m.segmentation_scale, 0.75);
  // The overlay is copied into the folder and named in the manifest, in order.
  ASSERT_EQ(m.overlays, std::vector<std::string>{"overlay_0_arm calibration.overlay.yaml"});
  ASSERT_EQ(rec.overlay_paths().size(), 1u);
  std::ifstream overlay(rec.overlay_paths()[0]);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(overlay), {}),
            "# not parsed by the recording library\nmachine: test_loader\n");
  ASSERT_EQ(m.cycles.size(), 2u);
  EXPECT_EQ(m.cycles[0].area.front_center.x(), 10.0 / 3.0);
  EXPECT_EQ(m.cycles[1].area.kind, WorkArea::Kind::kDiscs);
  EXPECT_EQ(m.cycles[1].site, "open yard");
  ASSERT_EQ(rec.updates().size(), 3u);
  EXPECT_EQ(rec.updates()[1].stamp, 12.0 + 1.0 / 7.0);
  EXPECT_EQ(rec.updates()[0].heading, 1.0 / 3.0);
  EXPECT_TRUE(rec.updates()[1].select);
  EXPECT_EQ(rec.updates()[2].cycle, 1);
  EXPECT_TRUE(rec.FramesOf(2).empty());
  ASSERT_TRUE(m.cycles[1].scoop.has_value());
  EXPECT_EQ(m.cycles[1].scoop->material, "river_sand");
  EXPECT_FALSE(m.cycles[0].scoop.has_value());
  ASSERT_EQ(rec.decisions().size(), 1u);
  EXPECT_EQ(rec.decisions()[0].q_boom, -0.52);
  EXPECT_TRUE(rec.decisions()[0].predict);
  ASSERT_EQ(rec.TipPathOf(1).size(), 2u);
  EXPECT_EQ(rec.TipPathOf(1)[0].x(), 1.0 / 3.0);
  EXPECT_TRUE(rec.TipPathOf(0).empty());

  // The frames read back as written.
  std::mt19937 again(7);
  const perception::SensorFrames written = TestFrames(again, true);
  const std::vector<FrameRow> frames = rec.FramesOf(0);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_TRUE(frames[0].health_check);
  EXPECT_TRUE(frames[0].T_world_sensor.isApprox(written.lidar[0].T_world_lidar, 0.0));
  const sensors::PointCloud cloud = rec.ReadLidar(frames[0]);
  ASSERT_EQ(cloud.points.size(), written.lidar[0].cloud.points.size());
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const sensors::LidarPoint& a = cloud.points[i];
    const sensors::LidarPoint& b = written.lidar[0].cloud.points[i];
    ASSERT_EQ(a.p_sensor, b.p_sensor) << i;
    ASSERT_EQ(a.intensity, b.intensity) << i;
    ASSERT_EQ(a.ring, b.ring) << i;
    ASSERT_EQ(a.time_offset, b.time_offset) << i;
  }
  EXPECT_EQ(cloud.stamp, written.lidar[0].stamp);
  const sensors::CameraFrame image = rec.ReadCamera(frames[1]);
  EXPECT_EQ(image.bgr, written.camera->bgr);
  EXPECT_EQ(image.labels, written.camera->labels);
  EXPECT_TRUE(frames[1].T_world_sensor.isApprox(written.T_world_camera, 0.0));
}

TEST(Recording, WorkAreaMatchesItsGeometry) {
  WorkArea bin;
  bin.front_center = {0, 0};
  bin.yaw = std::numbers::pi / 2;  // the front edge runs north; the bin lies west of it
  bin.width = 4;
  bin.depth = 6;
  EXPECT_TRUE(bin.Contains({-3, 1.9}));
  EXPECT_FALSE(bin.Contains({-3, 2.1}));  // beside the bin
  EXPECT_TRUE(bin.Contains({0.45, 0}));   // the apron
  EXPECT_FALSE(bin.Contains({0.55, 0}));
  EXPECT_FALSE(bin.Contains({-6.1, 0}));  // beyond the back wall
  WorkArea yard;
  yard.kind = WorkArea::Kind::kDiscs;
  yard.discs = {{10, 0, 2}};
  EXPECT_TRUE(yard.Contains({11.9, 0}));
  EXPECT_FALSE(yard.Contains({12.1, 0}));
}

TEST(Recording, WriterRefusesAFolderThatHoldsFiles) {
  const fs::path dir = FreshDir("not_empty");
  fs::create_directories(dir);
  std::ofstream(dir / "x") << "1";
  EXPECT_THROW(RecordingWriter(dir, WriteDescription(dir.string() + "_src").string(), {}),
               std::invalid_argument);
}

// The error of `fn` as one line, or "" when it did not refuse.
template <typename Fn>
std::string Refusal(Fn fn) {
  try {
    fn();
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kUpdatesHead = std::string(kUpdatesHeader) + "\n";
const std::string kFramesHead = std::string(kFramesHeader) + "\n";

TEST(Recording, MalformedUpdatesAreRefusedAtTheirPlace) {
  auto refusal = [](const std::string& text) {
    return Refusal([&] { ParseUpdatesCsv(text, "u.csv"); });
  };
  EXPECT_NE(refusal("update,cycle\n").find("u.csv:1:1: expected the header"), std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead).find("no updates"), std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead + "1,0,0,0,0,0,0,5,0,,,\n").find("u.csv:2:1: update: expected 0"),
            std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead + "0,0,nan,0,0,0,0,5,0,,,\n").find("u.csv:2:5: stamp"),
            std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead + "0,0,1,0,0,0,0,5,0,,,\n1,0,0.5,0,0,0,0,5,0,,,\n")
                .find("u.csv:3:5: stamp: goes back in time"),
            std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead + "0,0,1,0,0,0,30,5,0,,,\n").find("given in degrees?"),
            std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead + "0,0,1,0,0,0,0,5,0,1,2,3\n").find("select 0"),
            std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead + "0,0,1,0,0,0,0,5,1,1,,3\n").find("select_y"), std::string::npos);
  EXPECT_NE(refusal(kUpdatesHead + "0,0,1,0,0\n").find("expected 12 fields"), std::string::npos);
  EXPECT_EQ(refusal(kUpdatesHead + "0,0,1,0,0,0,0,5,1,1,2,3\r\n"), "");  // CRLF is fine
}

TEST(Recording, MalformedFramesAreRefusedAtTheirPlace) {
  auto refusal = [](const std::string& text) {
    return Refusal([&] { ParseFramesCsv(text, "f.csv"); });
  };
  const std::string pose = ",0,0,0,1,0,0,0,1,0,0,0,1\n";
  EXPECT_EQ(refusal(kFramesHead + "0,lidar,front,1,lidar/a.pcd,,0" + pose), "");
  EXPECT_NE(refusal(kFramesHead + "0,radar,front,1,lidar/a.pcd,,0" + pose).find("f.csv:2:3: kind"),
            std::string::npos);
  EXPECT_NE(refusal(kFramesHead + "0,lidar,front,1,/etc/passwd,,0" + pose).find("relative"),
            std::string::npos);
  EXPECT_NE(refusal(kFramesHead + "0,lidar,front,1,lidar/../../x.pcd,,0" + pose).find("'..'"),
            std::string::npos);
  EXPECT_NE(
      refusal(kFramesHead + "0,lidar,front,1,lidar/a.pcd,l.png,0" + pose).find("only a camera"),
      std::string::npos);
  EXPECT_NE(refusal(kFramesHead + "0,camera,cam,1,c.png,,1" + pose).find("only a LiDAR"),
            std::string::npos);
  EXPECT_NE(refusal(kFramesHead + "0,lidar,front,1,a.pcd,,0,0,0,0,2,0,0,0,1,0,0,0,1\n")
                .find("not a rotation matrix"),
            std::string::npos);
  EXPECT_NE(refusal(kFramesHead + "0,lidar,front,1,a.pcd,,0,0,0,inf,1,0,0,0,1,0,0,0,1\n")
                .find("f.csv:2:"),
            std::string::npos);
  EXPECT_NE(
      refusal(kFramesHead + "1,lidar,front,1,a.pcd,,0" + pose + "0,lidar,front,1,a.pcd,,0" + pose)
          .find("update order"),
      std::string::npos);
}

// Damage one file of a good recording and check the folder is refused with its name.
std::string RefusalAfter(const std::string& name,
                         const std::function<void(const fs::path&)>& damage) {
  const fs::path dir = FreshDir(name);
  std::mt19937 rng(3);
  WriteTestRecording(dir, rng);
  damage(dir);
  return Refusal([&] {
    Recording rec(dir);
    rec.ReadLidar(rec.FramesOf(0)[0]);
    rec.ReadCamera(rec.FramesOf(0)[1]);
  });
}

void Replace(const fs::path& file, const std::string& from, const std::string& to) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  std::ofstream(file) << text;
}

TEST(Recording, DamagedFoldersAreRefusedWithTheFile) {
  EXPECT_NE(RefusalAfter("no_manifest", [](const fs::path& d) { fs::remove(d / "recording.yaml"); })
                .find("did not finish"),
            std::string::npos);
  EXPECT_NE(RefusalAfter("version",
                         [](const fs::path& d) {
                           Replace(d / "recording.yaml", "version: 1", "version: 2");
                         })
                .find("recording.yaml:3:10: version"),
            std::string::npos);
  EXPECT_NE(RefusalAfter("unknown_key",
                         [](const fs::path& d) {
                           Replace(d / "recording.yaml", "  resolution:", "  resolutoin:");
                         })
                .find("resolution"),
            std::string::npos);
  EXPECT_NE(RefusalAfter(
                "missing_overlay",
                [](const fs::path& d) { fs::remove(d / "overlay_0_arm calibration.overlay.yaml"); })
                .find("overlays: "),
            std::string::npos);
  EXPECT_NE(RefusalAfter("cycle",
                         [](const fs::path& d) { Replace(d / "updates.csv", "\n2,1,", "\n2,5,"); })
                .find("cycle 5 is not among"),
            std::string::npos);
  EXPECT_NE(RefusalAfter("missing_frame",
                         [](const fs::path& d) { fs::remove(d / "camera" / "000000.png"); })
                .find("camera/000000.png: no such file"),
            std::string::npos);
  EXPECT_NE(RefusalAfter("bad_png",
                         [](const fs::path& d) {
                           std::ofstream(d / "camera" / "000000.png") << "not a png";
                         })
                .find("000000.png"),
            std::string::npos);
  EXPECT_NE(RefusalAfter("bad_labels",
                         [](const fs::path& d) {
                           fs::copy_file(d / "camera" / "000000.png",
                                         d / "camera" / "000000_labels.png",
                                         fs::copy_options::overwrite_existing);
                         })
                .find("000000_labels.png"),
            std::string::npos);
  EXPECT_NE(RefusalAfter("truncated_pcd",
                         [](const fs::path& d) {
                           const fs::path pcd = d / "lidar" / "front_lidar" / "000000_0.pcd";
                           fs::resize_file(pcd, fs::file_size(pcd) - 100);
                         })
                .find("000000_0.pcd"),
            std::string::npos);
}

}  // namespace
}  // namespace autoshovel::recording
