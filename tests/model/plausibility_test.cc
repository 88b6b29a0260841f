// Plausibility of description values (runtime/model/plausibility.h) and where materials are
// searched (LoadOptions). Fixtures: tests/data/implausible/*.yaml load with exactly one warning
// named by their header; impossible values are among tests/data/bad/ (refused).
#include "runtime/model/plausibility.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "runtime/model/description.h"

namespace autoshovel::model {
namespace {

namespace fs = std::filesystem;

const std::string kSource = AUTOSHOVEL_SOURCE_DIR;
const std::string kModels = kSource + "/models";

TEST(Plausibility, BoreInMillimetresIsImpossibleAndNamesTheUnit) {
  bool impossible = false;
  const std::string message =
      PlausibilityMessage("bore", 180, {0.02, 0.6, "m", "a cylinder bore"}, impossible);
  EXPECT_TRUE(impossible);
  EXPECT_EQ(message,
            "bore 180 m is impossible for a cylinder bore (0.02–0.6 m): given in mm? 0.18 m");
}

TEST(Plausibility, PressureInMegapascalIsAWarningNamingTheUnit) {
  bool impossible = true;
  const std::string message = PlausibilityMessage(
      "relief_pressure_bar", 28, {50, 550, "bar", "a relief pressure"}, impossible);
  EXPECT_FALSE(impossible);
  EXPECT_EQ(message,
            "relief_pressure_bar 28 bar is implausible for a relief pressure (50–550 bar): given "
            "in MPa? 280 bar");
}

TEST(Plausibility, PressureInPascalAndMassInTonnesAreNamed) {
  bool impossible = false;
  EXPECT_NE(PlausibilityMessage("pump_pressure_bar", 2.5e7, {50, 500, "bar", "a pump pressure"},
                                impossible)
                .find("given in Pa? 250 bar"),
            std::string::npos);
  EXPECT_TRUE(impossible);
  EXPECT_NE(
      PlausibilityMessage("operating_mass", 16.8, {500, 1e6, "kg", "an operating mass"}, impossible)
          .find("given in tonnes? 16800 kg"),
      std::string::npos);
  EXPECT_TRUE(impossible);
}

TEST(Plausibility, ValuesInRangeSayNothing) {
  bool impossible = true;
  EXPECT_EQ(PlausibilityMessage("bore", 0.18, {0.02, 0.6, "m", "a cylinder bore"}, impossible), "");
  EXPECT_FALSE(impossible);
  EXPECT_EQ(
      PlausibilityMessage("tank_pressure_bar", 0, {0, 30, "bar", "a tank pressure"}, impossible),
      "");
}

TEST(Plausibility, EveryShippedMachineIsPlausible) {
  for (const std::string& path : FindMachineDescriptions(kModels)) {
    const MachineDescription m = LoadMachineDescription(path);
    EXPECT_TRUE(m.warnings.empty()) << path << ": " << m.warnings.front().ToString();
  }
}

TEST(Plausibility, FixturesLoadWithTheWarningTheirHeaderNames) {
  const fs::path dir = fs::path(kSource) / "tests" / "data" / "implausible";
  int fixtures = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++fixtures;
    std::ifstream in(entry.path());
    std::string defect, expect;
    std::getline(in, defect);
    std::getline(in, expect);
    ASSERT_EQ(expect.rfind("# expect: ", 0), 0u) << entry.path();
    LoadOptions options;
    options.materials_dir = kModels + "/materials";
    const MachineDescription m = LoadMachineDescription(entry.path().string(), options);
    ASSERT_EQ(m.warnings.size(), 1u) << entry.path();
    const std::string line = m.warnings[0].ToString();
    EXPECT_EQ(line, entry.path().string() + ":" + expect.substr(10)) << defect;
  }
  EXPECT_GE(fixtures, 2);
}

TEST(Plausibility, AWarningPrintsLikeACompilerWarning) {
  core::Diagnostic d;
  d.where.file = "x.yaml";
  d.where.line = 3;
  d.where.column = 7;
  d.key_path = "chassis.max_speed";
  d.message = "too fast";
  d.severity = core::Severity::kWarning;
  EXPECT_EQ(d.ToString(), "x.yaml:3:7: warning: chassis.max_speed: too fast");
}

// A description outside models/, with no materials folder beside it.
std::string LonelyCopy(const std::string& machine) {
  const fs::path dir =
      fs::temp_directory_path() / ("autoshovel_lonely_" + std::to_string(getpid()));
  fs::create_directories(dir / "loaders");
  const fs::path copy = dir / "loaders" / (machine + ".yaml");
  fs::copy_file(kModels + "/loaders/" + machine + ".yaml", copy,
                fs::copy_options::overwrite_existing);
  return copy.string();
}

TEST(MaterialFolders, UnknownMaterialSaysWhichFoldersWereSearched) {
  const std::string path = LonelyCopy("xcmg_968ev");
  try {
    LoadMachineDescription(path);
    ADD_FAILURE() << "loaded without materials";
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown material 'small_gravel' (known: none)"), std::string::npos)
        << what;
    const std::string folder =
        (fs::path(path).parent_path() / ".." / "materials").lexically_normal().string();
    EXPECT_NE(what.find("searched " + folder + " (no such folder)"), std::string::npos) << what;
  }
}

TEST(MaterialFolders, ModelsFolderIsSearchedAfterTheDescriptionsOwn) {
  const std::string path = LonelyCopy("xcmg_968ev");
  LoadOptions options;
  options.models_dir = kModels;
  const MachineDescription m = LoadMachineDescription(path, options);
  ASSERT_EQ(m.materials_searched.size(), 2u);
  EXPECT_EQ(m.materials_searched[1], (fs::path(kModels) / "materials").lexically_normal().string());
  EXPECT_NE(m.FindMaterial("small_gravel"), nullptr);
}

TEST(MaterialFolders, AnExplicitFolderIsTheOnlyOneSearched) {
  LoadOptions options;
  options.materials_dir = "/nonexistent/materials";
  options.models_dir = kModels;
  EXPECT_EQ(MaterialFolders(kModels + "/loaders/xcmg_968ev.yaml", options),
            std::vector<std::string>{"/nonexistent/materials"});
}

TEST(MaterialFolders, TheSameFolderReachedTwoWaysIsSearchedOnce) {
  LoadOptions options;
  options.models_dir = kModels + "/loaders/..";
  EXPECT_EQ(MaterialFolders(kModels + "/loaders/xcmg_968ev.yaml", options).size(), 1u);
}

TEST(MaterialFolders, ProcessDefaultsApplyWhenTheOptionsAreEmpty) {
  SetDefaultMaterialFolders("/cli/materials", "");
  EXPECT_EQ(MaterialFolders(kModels + "/loaders/xcmg_968ev.yaml", {}),
            std::vector<std::string>{"/cli/materials"});
  SetDefaultMaterialFolders("", "");
  EXPECT_EQ(MaterialFolders(kModels + "/loaders/xcmg_968ev.yaml", {}).size(), 1u);
}

}  // namespace
}  // namespace autoshovel::model
