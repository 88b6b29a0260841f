// The truck-loading recording (runtime/recording/scan_recording.h, docs/recording_format.md
// "Truck loading"): scans read back bit for bit, misses keep their place, and malformed tables and
// manifests are refused at their place.
#include "runtime/recording/scan_recording.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include "runtime/core/diagnostics.h"
#include "runtime/recording/scan_tables.h"

namespace autoshovel::recording {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("scan_recording_" + name);
  fs::remove_all(dir);
  return dir;
}

fs::path Description(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / "scan_recording_sources";
  fs::create_directories(dir);
  const fs::path path = dir / (name + ".yaml");
  std::ofstream(path) << "# not parsed by the recording library\nname: test_excavator\n";
  return path;
}

RecordedScan TestScan(std::mt19937& rng, ScanKind kind, int pass, int lines) {
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  RecordedScan s;
  s.kind = kind;
  s.pass = pass;
  s.pulses_fired = 1234567;
  s.points = 765432;
  s.dust_evidence = 17;
  s.max_azimuth_step = 0.1 + 0.2;  // not exact in decimal
  s.dust_warning = kind == ScanKind::kBed;
  s.min_speed_scale = 2.0 / 3.0;
  for (int k = 0; k < lines; ++k) {
    perception::Scanline line;
    line.p_world_sensor = {u(rng) / 10, u(rng) / 10, 2.6 + 1.0 / 3.0};
    for (int i = 0; i < 50; ++i) {
      perception::ScanPoint p;
      if (i % 7 == 3) {
        p.valid = false;  // a miss: NaN, kept in mirror order
      } else {
        p.p_world = {u(rng), u(rng), u(rng) / 7};
        p.valid = i % 11 != 5;  // a rejected reading with coordinates
      }
      line.points.push_back(p);
    }
    s.scanlines.push_back(line);
    s.scanline_azimuths.push_back(-3.0 + k * (1.0 / 57.0));
  }
  return s;
}

void ExpectSame(const RecordedScan& a, const RecordedScan& b) {
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.pass, b.pass);
  EXPECT_EQ(a.pulses_fired, b.pulses_fired);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.dust_evidence, b.dust_evidence);
  EXPECT_EQ(a.max_azimuth_step, b.max_azimuth_step);
  EXPECT_EQ(a.dust_warning, b.dust_warning);
  EXPECT_EQ(a.min_speed_scale, b.min_speed_scale);
  ASSERT_EQ(a.scanlines.size(), b.scanlines.size());
  EXPECT_EQ(a.scanline_azimuths, b.scanline_azimuths);
  for (std::size_t k = 0; k < a.scanlines.size(); ++k) {
    EXPECT_EQ(a.scanlines[k].p_world_sensor, b.scanlines[k].p_world_sensor);
    ASSERT_EQ(a.scanlines[k].points.size(), b.scanlines[k].points.size());
    for (std::size_t i = 0; i < a.scanlines[k].points.size(); ++i) {
      const perception::ScanPoint& p = a.scanlines[k].points[i];
      const perception::ScanPoint& q = b.scanlines[k].points[i];
      EXPECT_EQ(p.valid, q.valid);
      if (p.p_world.allFinite()) {
        EXPECT_EQ(p.p_world, q.p_world);  // bit for bit
      } else {
        EXPECT_TRUE(q.p_world.array().isNaN().all());
      }
    }
  }
}

TEST(ScanRecording, ReadsBackBitForBit) {
  const fs::path dir = FreshDir("round_trip");
  std::mt19937 rng(7);
  ScanManifest manifest;
  manifest.scanner = "left_scanner";
  manifest.T_world_base =
      Eigen::Translation3d(1.5, -2.25, 0.125) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ());
  std::vector<RecordedScan> written = {TestScan(rng, ScanKind::kRecognition, 0, 40),
                                       TestScan(rng, ScanKind::kBed, 0, 12),
                                       TestScan(rng, ScanKind::kBed, 2, 9)};
  {
    ScanRecordingWriter writer(dir, Description("round_trip").string(), manifest);
    for (const RecordedScan& s : written) writer.AddScan(s);
    writer.SetTruckReference("1,0,1,2,3,4,5,6,nan,nan,7,8,9");
    writer.AddBedMapReference("0,39,16,59,-0.8,b2d5a22a7114ea54");
    EXPECT_FALSE(fs::exists(dir / "recording.yaml"));  // unfinished until Close
    writer.Close();
  }
  EXPECT_TRUE(IsTruckLoadingManifest(dir / "recording.yaml"));
  const ScanRecording read(dir);
  EXPECT_EQ(read.manifest().scanner, "left_scanner");
  EXPECT_TRUE(read.manifest().T_world_base.isApprox(manifest.T_world_base, 1e-12));
  ASSERT_EQ(read.scans().size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    EXPECT_EQ(read.scans()[i].scan, static_cast<int>(i));
    ExpectSame(written[i], read.scans()[i]);
  }
  EXPECT_NE(read.truck_reference().find("1,0,1,2,3,4,5,6,nan,nan,7,8,9"), std::string::npos);
  EXPECT_NE(read.bed_maps_reference().find("b2d5a22a7114ea54"), std::string::npos);
  // A folder that holds files is not written into.
  EXPECT_THROW(ScanRecordingWriter(dir, Description("again").string(), manifest),
               std::invalid_argument);
}

// Each malformed row is refused with the file, the line and the column of the field.
void ExpectRefused(const std::function<void()>& read, const std::string& where,
                   const std::string& what) {
  try {
    read();
    ADD_FAILURE() << "accepted; expected a refusal at " << where << " (" << what << ")";
  } catch (const core::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(where), std::string::npos) << where << " in: " << message;
    EXPECT_NE(message.find(what), std::string::npos) << what << " in: " << message;
  }
}

TEST(ScanRecording, MalformedTablesAreRefusedAtTheirPlace) {
  const std::string h = std::string(kScansHeader) + "\n";
  const std::string first = "0,recognition,0,10,5,0,0.01,0,1\n";
  auto scans = [](const std::string& text) { return ParseScansCsv(text, "scans.csv"); };
  ExpectRefused([&] { scans(""); }, "scans.csv", "empty");
  ExpectRefused([&] { scans(h); }, "scans.csv:1:1", "no scan");
  ExpectRefused([&] { scans(h + "0,bed,0,10,5,0,0.01,0,1\n"); }, "scans.csv:2:3",
                "the first scan, and only it");
  ExpectRefused([&] { scans(h + first + "2,bed,0,10,5,0,0.01,0,1\n"); }, "scans.csv:3:1",
                "expected 1");
  ExpectRefused([&] { scans(h + first + "1,lidar,0,10,5,0,0.01,0,1\n"); }, "scans.csv:3:3",
                "recognition or bed");
  ExpectRefused([&] { scans(h + "0,recognition,3,10,5,0,0.01,0,1\n1,bed,2,1,1,0,0,0,1\n"); },
                "scans.csv:3:7", "goes back");
  ExpectRefused([&] { scans(h + "0,recognition,0,10,5,0,nan,0,1\n"); }, "scans.csv:2:24", "finite");
  ExpectRefused([&] { scans(h + "0,recognition,0,10,5,0,0.01,0,0\n"); }, "scans.csv:2:31",
                "(0, 1]");
  ExpectRefused([&] { scans(h + "0,recognition,0,10,5,0,0.01,0\n"); }, "scans.csv:2:1",
                "expected 9 fields");

  std::vector<RecordedScan> two = scans(h + first + "1,bed,1,10,5,0,0.01,1,0.5\n");
  const std::string lh = std::string(kScanlinesHeader) + "\n";
  auto lines = [&](const std::string& text) {
    std::vector<RecordedScan> copy = two;
    ParseScanlinesCsv(text, "scanlines.csv", copy);
    return copy;
  };
  ExpectRefused([&] { lines(lh + "2,0,0,0,2.6,0.1\n"); }, "scanlines.csv:2:1", "[0, 1]");
  ExpectRefused([&] { lines(lh + "0,1,0,0,2.6,0.1\n"); }, "scanlines.csv:2:3", "expected 0");
  ExpectRefused([&] { lines(lh + "1,0,0,0,2.6,0.1\n0,0,0,0,2.6,0.1\n"); }, "scanlines.csv:3:1",
                "goes back");
  ExpectRefused([&] { lines(lh + "0,0,0,inf,2.6,0.1\n"); }, "scanlines.csv:2:7", "finite");
  ExpectRefused([&] { lines(lh + "0,0,0,0,2e7,0.1\n"); }, "scanlines.csv:2:9", "1000 km");

  std::vector<RecordedScan> lined = lines(lh + "0,0,0,0,2.6,0.1\n0,1,0,0,2.6,0.2\n");
  const std::string ph = std::string(kScanPointsHeader) + "\n";
  auto points = [&](const std::string& text) {
    std::vector<RecordedScan> copy = lined;
    ParseScanPointsCsv(text, "scan_points.csv", copy);
    return copy;
  };
  ExpectRefused([&] { points(ph + "1,0,1,2,3,1\n"); }, "scan_points.csv:2:1", "no scanline");
  ExpectRefused([&] { points(ph + "0,2,1,2,3,1\n"); }, "scan_points.csv:2:3", "[0, 1]");
  ExpectRefused([&] { points(ph + "0,1,1,2,3,1\n0,0,1,2,3,1\n"); }, "scan_points.csv:3:1",
                "goes back");
  // NaN is a miss's mark: a valid reading must have coordinates, and all three are NaN or none.
  ExpectRefused([&] { points(ph + "0,0,nan,nan,nan,1\n"); }, "scan_points.csv:2:5", "finite");
  ExpectRefused([&] { points(ph + "0,0,nan,2,3,0\n"); }, "scan_points.csv:2:5", "finite");
  ExpectRefused([&] { points(ph + "0,0,1,2,3,2\n"); }, "scan_points.csv:2:11", "0 or 1");
  const std::vector<RecordedScan> ok = points(ph + "0,0,1,2,3,1\n0,0,nan,nan,nan,0\n");
  ASSERT_EQ(ok[0].scanlines[0].points.size(), 2u);
  EXPECT_TRUE(ok[0].scanlines[0].points[0].valid);
  EXPECT_FALSE(ok[0].scanlines[0].points[1].valid);
  EXPECT_TRUE(ok[0].scanlines[0].points[1].p_world.array().isNaN().all());
}

TEST(ScanRecording, DamagedFoldersAreRefused) {
  const fs::path dir = FreshDir("damaged");
  std::mt19937 rng(3);
  ScanManifest scan_manifest;
  scan_manifest.scanner = "left_scanner";
  {
    ScanRecordingWriter writer(dir, Description("damaged").string(), scan_manifest);
    writer.AddScan(TestScan(rng, ScanKind::kRecognition, 0, 3));
    writer.Close();
  }
  const std::string manifest = (dir / "recording.yaml").string();
  const std::string good = [&] {
    std::ifstream in(manifest);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  auto with = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(manifest) << text;
  };
  auto open = [&] { ScanRecording r(dir); };
  EXPECT_THROW(
      ScanRecordingWriter(FreshDir("no_scanner"), Description("x").string(), ScanManifest{}),
      std::invalid_argument);
  with("scans: 1", "scans: 2");
  ExpectRefused(open, "scans.csv", "1 scans, the manifest says 2");
  with("base_yaw_deg: 0", "base_yaw_deg: 0\ncolour: red");
  ExpectRefused(open, "recording.yaml", "colour");
  with("machine: machine.yaml", "machine: ../elsewhere.yaml");
  ExpectRefused(open, "recording.yaml", "in the recording folder");
  with("version: 1", "version: 2");
  ExpectRefused(open, "recording.yaml", "version");
  std::ofstream(manifest) << good;
  fs::remove(dir / "scan_points.csv");
  ExpectRefused(open, "scan_points.csv", "");
  fs::remove(dir / "recording.yaml");
  ExpectRefused(open, "recording.yaml", "missing");
  EXPECT_FALSE(IsTruckLoadingManifest(dir / "recording.yaml"));
}

}  // namespace
}  // namespace autoshovel::recording
