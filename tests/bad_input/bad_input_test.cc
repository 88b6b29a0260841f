// Malformed input for every file reader (issue 9, "Bad input everywhere"). Each folder
// tests/data/bad_input/<reader>/ holds small broken files and an expected.txt, one line per
// fixture:
//   fixture<TAB>error type<TAB>the start of the error's first line
// where `{file}` stands for the fixture's path. Every fixture must be refused with that error
// type and a first line that starts with that text (file and line, row, byte offset or field
// included), every fixture on disk must be listed, and no reader may change the file it reads
// (tests/data/bad_input/README.md).
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "identification/calibration/arm_calibration_csv.h"
#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/image_header.h"
#include "identification/camera_lidar/mask_io.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "identification/camera_lidar/rig_files.h"
#include "identification/hydraulics/log_reader.h"
#include "identification/weights/demonstration_store.h"
#include "runtime/app/campaign/campaign_spec.h"
#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"
#include "runtime/perception/scan/scan_poses.h"
#include "runtime/perception/segmentation.h"
#include "runtime/planning/shovel_weights_file.h"
#include "runtime/plant/scenario.h"
#include "runtime/prediction/model_provenance.h"
#include "runtime/prediction/penetration_predictor.h"

namespace autoshovel {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = fs::path(AUTOSHOVEL_SOURCE_DIR);
const fs::path kBadInput = kSource / "tests" / "data" / "bad_input";

// The size of the image the mask fixtures are checked against.
constexpr int kMaskWidth = 8, kMaskHeight = 6;
// Sample rows a hydraulic log fixture needs (the CLI asks for 20; the fixtures are short).
constexpr std::size_t kLogMinSamples = 5;

struct Expectation {
  std::string fixture;  ///< a file or folder name in the reader's folder (a stem for `svr`)
  std::string type;     ///< InputError | runtime_error
  std::string message;  ///< the start of the error's first line, `{file}` for the path
  int line = 0;         ///< in expected.txt
};

std::vector<Expectation> ReadExpectations(const fs::path& dir) {
  std::ifstream in(dir / "expected.txt");
  std::vector<Expectation> out;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    if (text.empty() || text[0] == '#') continue;
    const auto tab1 = text.find('\t');
    const auto tab2 = tab1 == std::string::npos ? tab1 : text.find('\t', tab1 + 1);
    if (tab2 == std::string::npos) {
      ADD_FAILURE() << (dir / "expected.txt").string() << ":" << line
                    << ": expected fixture<TAB>type<TAB>message";
      continue;
    }
    out.push_back({text.substr(0, tab1), text.substr(tab1 + 1, tab2 - tab1 - 1),
                   text.substr(tab2 + 1), line});
  }
  return out;
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string FirstLine(const std::string& text) { return text.substr(0, text.find('\n')); }

// The bytes and modification times of everything a reader is given, to check it wrote nothing.
std::map<std::string, std::pair<std::string, fs::file_time_type>> Snapshot(
    const std::vector<fs::path>& paths) {
  std::map<std::string, std::pair<std::string, fs::file_time_type>> out;
  for (const fs::path& p : paths) {
    std::vector<fs::path> files;
    if (fs::is_directory(p)) {
      for (const auto& e : fs::directory_iterator(p)) files.push_back(e.path());
      out[p.string() + "/"] = {std::to_string(files.size()), fs::last_write_time(p)};
    } else if (fs::exists(p)) {
      files.push_back(p);
    }
    for (const fs::path& f : files) {
      std::ifstream in(f, std::ios::binary);
      std::ostringstream bytes;
      bytes << in.rdbuf();
      out[f.string()] = {bytes.str(), fs::last_write_time(f)};
    }
  }
  return out;
}

// A database built from a .sql fixture (SQLite files are binary: the fixture is their text).
fs::path BuildDatabase(const fs::path& sql) {
  const fs::path dir = fs::temp_directory_path() / "autoshovel_bad_input";
  fs::create_directories(dir);
  const fs::path db_path = dir / (sql.stem().string() + ".sqlite");
  fs::remove(db_path);
  std::ifstream in(sql);
  std::ostringstream text;
  text << in.rdbuf();
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(db_path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, text.str().c_str(), nullptr, nullptr, &error), SQLITE_OK)
      << sql << ": " << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
  return db_path;
}

model::LoadOptions MaterialsOnly() {
  model::LoadOptions options;
  options.materials_dir = (kSource / "models" / "materials").string();
  return options;
}

// Reader folder → how to read one fixture.
using ReadFn = std::function<void(const std::string&)>;
const std::map<std::string, ReadFn>& Readers() {
  static const std::map<std::string, ReadFn> readers = {
      {"description",
       [](const std::string& p) { model::LoadMachineDescription(p, MaterialsOnly()); }},
      {"material", [](const std::string& p) { model::LoadMaterial(p); }},
      {"overlay",
       [](const std::string& p) {
         model::LoadOptions options = MaterialsOnly();
         options.overlays = {p};
         model::LoadMachineDescription((kSource / "models/loaders/xcmg_968ev.yaml").string(),
                                       options);
       }},
      {"scenario", [](const std::string& p) { plant::LoadScenario(p); }},
      {"campaign_spec", [](const std::string& p) { app::LoadCampaignSpec(p); }},
      {"shovel_weights",
       [](const std::string& p) {
         planning::ShovelPointConfig config;
         planning::ReadShovelWeights(p, config);
       }},
      {"camera_info", [](const std::string& p) { identification::ReadCameraInfoYaml(p); }},
      {"calib_txt", [](const std::string& p) { identification::ReadCalibTxt(p); }},
      {"extrinsic", [](const std::string& p) { identification::ReadExtrinsic(p); }},
      {"correspondences", [](const std::string& p) { identification::ReadCorrespondences(p); }},
      {"image_header", [](const std::string& p) { identification::ReadImageHeader(p); }},
      {"log_format", [](const std::string& p) { identification::ReadLogFormatYaml(p); }},
      {"hydraulic_log",
       [](const std::string& p) {
         identification::ReadHydraulicLog(p, identification::LogFormat{}, kLogMinSamples);
       }},
      {"arm_calibration",
       [](const std::string& p) {
         identification::ReadArmCalibrationCsv(p, {"boom", "bucket"});
       }},
      {"pcd", [](const std::string& p) { identification::ReadPointCloud(p); }},
      {"kitti_bin", [](const std::string& p) { identification::ReadPointCloud(p); }},
      {"ply", [](const std::string& p) { identification::ReadPointCloud(p); }},
      {"scan_poses", [](const std::string& p) { perception::ReadScanPoses(p); }},
      {"masks",
       [](const std::string& p) { identification::ReadMasks(p, kMaskWidth, kMaskHeight); }},
      {"onnx", [](const std::string& p) { perception::Segmenter segmenter(p); }},
      {"svr", [](const std::string& p) { prediction::PenetrationPredictor::Load(p); }},
      {"model_provenance",
       [](const std::string& p) {
         // The fixture is `<stem>.meta.yaml`; the reader takes the model's stem.
         const std::string suffix = ".meta.yaml";
         prediction::LoadProvenance(p.substr(0, p.size() - suffix.size()));
       }},
      {"demonstrations", [](const std::string& p) { identification::ReadDemonstrations(p); }},
  };
  return readers;
}

class BadInput : public ::testing::TestWithParam<std::string> {};

TEST_P(BadInput, EveryFixtureIsRefusedWithItsLocatedMessageAndLeftUntouched) {
  const std::string reader = GetParam();
  const fs::path dir = kBadInput / reader;
  const std::vector<Expectation> expectations = ReadExpectations(dir);
  ASSERT_GE(expectations.size(), 4u) << dir << ": a handful of fixtures per reader";

  // Every fixture on disk is listed, and every listed one exists.
  std::set<std::string> listed, on_disk;
  for (const Expectation& e : expectations) {
    EXPECT_TRUE(listed.insert(e.fixture).second) << e.fixture << " listed twice";
  }
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name == "expected.txt" || name == "make_binary_fixtures.py") continue;
    on_disk.insert(reader == "svr" ? entry.path().stem().string() : name);
  }
  EXPECT_EQ(listed, on_disk) << dir << ": expected.txt and the fixtures differ";

  const bool print = std::getenv("BAD_INPUT_PRINT") != nullptr;
  for (const Expectation& e : expectations) {
    SCOPED_TRACE((dir / "expected.txt").string() + ":" + std::to_string(e.line) + ": " + e.fixture);
    fs::path path = dir / e.fixture;
    std::vector<fs::path> inputs = {path};
    if (reader == "svr") inputs = {path.string() + ".scale", path.string() + ".model"};
    if (path.extension() == ".sql") path = BuildDatabase(path), inputs = {path};
    const auto before = Snapshot(inputs);
    std::string type, message;
    try {
      Readers().at(reader)(path.string());
    } catch (const core::InputError& error) {
      type = "InputError", message = error.what();
    } catch (const std::runtime_error& error) {
      type = "runtime_error", message = error.what();
    } catch (const std::exception& error) {
      type = "std::exception", message = error.what();
    }
    const std::string first = Replace(FirstLine(message), path.string(), "{file}");
    if (print) std::cout << e.fixture << "\t" << type << "\t" << first << "\n";
    if (type.empty()) {
      ADD_FAILURE() << path << " was accepted; expected " << e.type << ": " << e.message;
      continue;
    }
    EXPECT_EQ(type, e.type) << first;
    EXPECT_EQ(first.rfind(e.message, 0), 0u)
        << "expected: " << e.message << "\n     got: " << first;
    EXPECT_EQ(Snapshot(inputs), before) << path << " was changed by its reader";
  }
}

INSTANTIATE_TEST_SUITE_P(Readers, BadInput,
                         ::testing::Values("description", "material", "overlay", "scenario",
                                           "campaign_spec", "shovel_weights", "camera_info",
                                           "calib_txt", "extrinsic", "correspondences",
                                           "log_format", "hydraulic_log", "arm_calibration", "pcd",
                                           "kitti_bin", "ply", "scan_poses", "masks",
                                           "image_header", "onnx", "svr", "model_provenance",
                                           "demonstrations"),
                         [](const auto& param_info) { return param_info.param; });

// Every reader folder is exercised by the test above.
TEST(BadInputFolders, EachHasAReader) {
  for (const auto& entry : fs::directory_iterator(kBadInput)) {
    if (!entry.is_directory()) continue;
    EXPECT_TRUE(Readers().count(entry.path().filename().string())) << entry.path();
  }
}

}  // namespace
}  // namespace autoshovel
