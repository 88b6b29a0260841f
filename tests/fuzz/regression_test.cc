// The fuzz targets' inputs as ordinary tests, in the normal build (no clang, no libFuzzer): every
// seed of tests/fuzz/corpus/<target>/ and every input kept in tests/fuzz/regressions/<target>/
// (a fuzzing finding, since fixed) goes through the reader that target fuzzes, read the same way.
// Seeds named `valid_*` must be read; every other input must be refused with core::InputError,
// located (refusal.h: every diagnostic names the file and a line of it, or 0 for the whole file).
// Any other exception fails the test; a crash fails the whole executable.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "identification/calibration/arm_calibration_csv.h"
#include "identification/camera_lidar/image_header.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "identification/camera_lidar/rig_files.h"
#include "identification/hydraulics/log_reader.h"
#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"
#include "runtime/perception/scan/scan_poses.h"
#include "runtime/recording/recording_tables.h"
#include "runtime/recording/scan_tables.h"
#include "runtime/results/results_db.h"
#include "tests/fuzz/hydraulic_log_formats.h"
#include "tests/fuzz/refusal.h"
#include "tests/fuzz/scan_recording_fixture.h"

namespace autoshovel::fuzz {
namespace {

namespace fs = std::filesystem;

const fs::path kFuzzDir = fs::path(AUTOSHOVEL_SOURCE_DIR) / "tests" / "fuzz";

std::vector<fs::path> FilesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

int LinesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return CountLines(std::string(std::istreambuf_iterator<char>(in), {}));
}

// Reads `path` as the fuzz target does; returns its refusal, if any. Throws whatever else the
// reader throws (a finding).
using Read = std::function<std::optional<core::InputError>(const std::string& path)>;

template <typename F>
std::optional<core::InputError> Refusal(F&& read) {
  try {
    read();
  } catch (const core::InputError& e) {
    return e;
  }
  return std::nullopt;
}

struct Counts {
  int valid = 0, refused = 0;
};

Counts CheckTarget(const std::string& target, const Read& read) {
  Counts counts;
  for (const char* kind : {"corpus", "regressions"}) {
    for (const fs::path& file : FilesIn(kFuzzDir / kind / target)) {
      const std::string path = file.string();
      const bool valid =
          std::string(kind) == "corpus" && file.filename().string().starts_with("valid_");
      SCOPED_TRACE(path);
      const std::optional<core::InputError> refusal = read(path);
      if (valid) {
        EXPECT_FALSE(refusal) << "a valid seed was refused:\n" << refusal->what();
        ++counts.valid;
      } else if (!refusal) {
        ADD_FAILURE() << "a malformed input was accepted";
      } else {
        EXPECT_EQ(RefusalProblem(*refusal, path, LinesOf(path)), "");
        ++counts.refused;
      }
    }
  }
  return counts;
}

// Each target has valid and malformed seeds: an empty or misnamed corpus must not pass quietly.
void ExpectBothKinds(const Counts& counts) {
  EXPECT_GE(counts.valid, 2);
  EXPECT_GE(counts.refused, 2);
}

TEST(FuzzRegressions, Description) {
  model::LoadOptions options;
  options.materials_dir = AUTOSHOVEL_SOURCE_DIR "/models/materials";
  ExpectBothKinds(CheckTarget("description", [&](const std::string& path) {
    return Refusal([&] { model::LoadMachineDescription(path, options); });
  }));
}

TEST(FuzzRegressions, ArmCalibrationCsv) {
  ExpectBothKinds(CheckTarget("arm_calibration_csv", [](const std::string& path) {
    return Refusal([&] { identification::ReadArmCalibrationCsv(path, {"boom", "bucket"}); });
  }));
}

// Read in each format the fuzz target reads it in: every refusal must be located, and an input
// counts as refused when any format refuses it.
TEST(FuzzRegressions, HydraulicLog) {
  ExpectBothKinds(CheckTarget("hydraulic_log", [](const std::string& path) {
    std::optional<core::InputError> first;
    for (const identification::LogFormat& format : HydraulicLogFormatsOf(path)) {
      auto refusal = Refusal([&] { identification::ReadHydraulicLog(path, format); });
      if (refusal && !first) first = refusal;
      if (refusal) {
        EXPECT_EQ(RefusalProblem(*refusal, path, LinesOf(path)), "");
      }
    }
    return first;
  }));
}

TEST(FuzzRegressions, Pcd) {
  ExpectBothKinds(CheckTarget("pcd", [](const std::string& path) {
    return Refusal([&] { identification::ReadPointCloud(path, /*max_points=*/64); });
  }));
}

TEST(FuzzRegressions, Ply) {
  ExpectBothKinds(CheckTarget("ply", [](const std::string& path) {
    return Refusal([&] { identification::ReadPointCloud(path, /*max_points=*/64); });
  }));
}

TEST(FuzzRegressions, ScanPoses) {
  ExpectBothKinds(CheckTarget("scan_poses", [](const std::string& path) {
    return Refusal([&] { perception::ReadScanPoses(path); });
  }));
}

std::string TextOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The recording folder's tables and manifest (fuzz_recording_updates, _frames, _manifest).
TEST(FuzzRegressions, RecordingUpdates) {
  ExpectBothKinds(CheckTarget("recording_updates", [](const std::string& path) {
    return Refusal([&] { recording::ParseUpdatesCsv(TextOf(path), path); });
  }));
}

TEST(FuzzRegressions, RecordingFrames) {
  ExpectBothKinds(CheckTarget("recording_frames", [](const std::string& path) {
    return Refusal([&] { recording::ParseFramesCsv(TextOf(path), path); });
  }));
}

TEST(FuzzRegressions, RecordingScoop) {
  ExpectBothKinds(CheckTarget("recording_scoop", [](const std::string& path) {
    return Refusal([&] { recording::ParseScoopCsv(TextOf(path), path); });
  }));
}

TEST(FuzzRegressions, RecordingTipPath) {
  ExpectBothKinds(CheckTarget("recording_tip_path", [](const std::string& path) {
    return Refusal([&] { recording::ParseTipPathCsv(TextOf(path), path); });
  }));
}

TEST(FuzzRegressions, RecordingManifest) {
  ExpectBothKinds(CheckTarget("recording_manifest", [](const std::string& path) {
    return Refusal([&] { recording::ReadManifest(path); });
  }));
}

// The truck-loading recording's tables and manifest (fuzz_recording_scans, _scanlines,
// _scan_points, _scan_manifest), the later tables read against scan_recording_fixture.h.
TEST(FuzzRegressions, RecordingScans) {
  ExpectBothKinds(CheckTarget("recording_scans", [](const std::string& path) {
    return Refusal([&] { recording::ParseScansCsv(TextOf(path), path); });
  }));
}

TEST(FuzzRegressions, RecordingScanlines) {
  ExpectBothKinds(CheckTarget("recording_scanlines", [](const std::string& path) {
    return Refusal([&] {
      auto scans = ScansWithoutScanlines();
      recording::ParseScanlinesCsv(TextOf(path), path, scans);
    });
  }));
}

TEST(FuzzRegressions, RecordingScanPoints) {
  ExpectBothKinds(CheckTarget("recording_scan_points", [](const std::string& path) {
    return Refusal([&] {
      auto scans = ScansWithScanlines();
      recording::ParseScanPointsCsv(TextOf(path), path, scans);
    });
  }));
}

TEST(FuzzRegressions, RecordingScanManifest) {
  ExpectBothKinds(CheckTarget("recording_scan_manifest", [](const std::string& path) {
    return Refusal([&] { recording::ReadScanManifest(path); });
  }));
}

TEST(FuzzRegressions, ImageHeader) {
  ExpectBothKinds(CheckTarget("image_header", [](const std::string& path) {
    return Refusal([&] { identification::ReadImageHeader(path); });
  }));
}

// The standalone rig's text files (fuzz_calib_txt, fuzz_extrinsic, fuzz_correspondences).
TEST(FuzzRegressions, CalibTxt) {
  ExpectBothKinds(CheckTarget("calib_txt", [](const std::string& path) {
    return Refusal([&] { identification::ReadCalibTxt(path); });
  }));
}

TEST(FuzzRegressions, Extrinsic) {
  ExpectBothKinds(CheckTarget("extrinsic", [](const std::string& path) {
    return Refusal([&] { identification::ReadExtrinsic(path); });
  }));
}

TEST(FuzzRegressions, Correspondences) {
  ExpectBothKinds(CheckTarget("correspondences", [](const std::string& path) {
    return Refusal([&] { identification::ReadCorrespondences(path); });
  }));
}

// The results database read back as fuzz_results_db reads it. Its refusal is ResultsDbError
// naming the file (not a located InputError: the file is SQLite's, not a text format). A valid
// seed from before the predicted-travel column (issue 41) reads that column as not measured.
TEST(FuzzRegressions, ResultsDb) {
  Counts counts;
  for (const char* kind : {"corpus", "regressions"}) {
    for (const fs::path& file : FilesIn(kFuzzDir / kind / "results_db")) {
      const std::string path = file.string();
      SCOPED_TRACE(path);
      const bool valid =
          std::string(kind) == "corpus" && file.filename().string().starts_with("valid_");
      try {
        const results::ResultsDb db(path, results::ResultsDb::Access::kReadOnly);
        std::size_t cycles = 0;
        for (const results::RunInfo& run : db.Runs()) cycles += db.Cycles(run.run_id, true).size();
        const auto crowding = db.CrowdingSamples();
        EXPECT_TRUE(valid) << "a malformed database was read";
        EXPECT_EQ(cycles, 1u);
        ASSERT_EQ(crowding.size(), 1u);
        EXPECT_GT(crowding[0].sample.penetration, 0.0);
        if (file.filename().string().find("before_predicted") != std::string::npos) {
          EXPECT_TRUE(std::isnan(crowding[0].sample.predicted_penetration));
        } else {
          EXPECT_GT(crowding[0].sample.predicted_penetration, 0.0);
        }
        ++counts.valid;
      } catch (const results::ResultsDbError& e) {
        EXPECT_FALSE(valid) << "a valid seed was refused: " << e.what();
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        ++counts.refused;
      }
    }
  }
  ExpectBothKinds(counts);
}

}  // namespace
}  // namespace autoshovel::fuzz
