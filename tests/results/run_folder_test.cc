// The run folder: default timestamped name, refusal of a non-empty folder unless resuming,
// config.yaml from key/values, the log's format and levels.
#include "runtime/results/run_folder.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "tests/results/test_records.h"

namespace autoshovel::results {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

// Registered once for the whole results_tests binary.
::testing::Environment* const kScratchCleanup =
    ::testing::AddGlobalTestEnvironment(new testing::RemoveScratchWhenPassed);

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(RunFolder, DefaultIsAUniqueUtcTimestampUnderRoot) {
  const fs::path root = ScratchDir("") / "runs";
  RunFolderOptions options;
  options.root = root;
  RunFolder first(options);
  RunFolder second(options);  // same second: gets a suffix
  EXPECT_NE(first.dir(), second.dir());
  EXPECT_EQ(first.dir().parent_path(), root);
  EXPECT_TRUE(
      std::regex_match(first.name(), std::regex(R"(\d{4}-\d\d-\d\dT\d\d-\d\d-\d\dZ(-\d+)?)")))
      << first.name();
  EXPECT_TRUE(fs::is_directory(first.dir() / "figures"));
  EXPECT_TRUE(fs::exists(first.LogPath()));
  EXPECT_EQ(first.DatabasePath(), first.dir() / "results.sqlite");
  EXPECT_EQ(first.FigurePath("a.png"), first.dir() / "figures" / "a.png");
  EXPECT_FALSE(first.resumed());
}

TEST(RunFolder, RefusesNonEmptyFolderUnlessResuming) {
  const fs::path dir = ScratchDir("") / "chosen";
  RunFolderOptions options;
  options.dir = dir;
  { RunFolder folder(options); }  // created
  try {
    RunFolder again(options);
    FAIL() << "reused a non-empty run folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(dir.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not empty"), std::string::npos) << e.what();
  }
  options.resume = true;
  RunFolder resumed(options);
  EXPECT_TRUE(resumed.resumed());
  options.dir = dir.parent_path() / "never_ran";
  EXPECT_THROW(RunFolder missing(options), std::runtime_error);
  // An existing empty folder is fine for a new run.
  fs::create_directories(dir.parent_path() / "empty");
  RunFolderOptions empty;
  empty.dir = dir.parent_path() / "empty";
  EXPECT_NO_THROW(RunFolder folder(empty));
}

TEST(RunFolder, ConfigFromKeyValuesNestsDottedKeys) {
  const std::string yaml = KeyValuesToYaml({{"scenario", "yard_small"},
                                            {"machine", "loader_20t"},
                                            {"rates.control_hz", "100"},
                                            {"rates.map_hz", "7"},
                                            {"seed", "42"},
                                            {"note", "a: colon"}});
  EXPECT_EQ(yaml,
            "scenario: yard_small\nmachine: loader_20t\nrates:\n  control_hz: 100\n  map_hz: 7\n"
            "seed: 42\nnote: \"a: colon\"\n");
  EXPECT_THROW(KeyValuesToYaml({{"a", "1"}, {"a.b", "2"}}), std::invalid_argument);
  EXPECT_THROW(KeyValuesToYaml({{"a.b", "1"}, {"a", "2"}}), std::invalid_argument);
  EXPECT_THROW(KeyValuesToYaml({{"a", "1"}, {"a", "2"}}), std::invalid_argument);
  EXPECT_THROW(KeyValuesToYaml({{"a..b", "1"}}), std::invalid_argument);
}

TEST(RunFolder, ResumedRunMustKeepItsConfiguration) {
  const fs::path dir = ScratchDir("") / "run";
  RunFolderOptions options;
  options.dir = dir;
  {
    RunFolder folder(options);
    folder.WriteConfig(KeyValues{{"seed", "42"}, {"cycles", "10"}});
  }
  EXPECT_EQ(ReadAll(dir / "config.yaml"), "seed: 42\ncycles: 10\n");
  options.resume = true;
  RunFolder resumed(options);
  EXPECT_NO_THROW(resumed.WriteConfig(KeyValues{{"seed", "42"}, {"cycles", "10"}}));
  try {
    resumed.WriteConfig(KeyValues{{"seed", "43"}, {"cycles", "10"}});
    FAIL() << "resumed with another configuration";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "config.yaml").string()), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(ReadAll(dir / "config.yaml"), "seed: 42\ncycles: 10\n");
}

TEST(RunFolder, LogLinesCarryWallAndSimulatedTimeAndLevel) {
  const fs::path dir = ScratchDir("") / "run";
  RunFolderOptions options;
  options.dir = dir;
  RunFolder folder(options);
  RunLog& log = folder.log();
  log.Info("run started");
  log.SetSimulatedTime(12.35);
  log.Debug("hidden at the default level");
  log.Warning("crowd: slip 0.3");
  log.SetMinLevel(LogLevel::kDebug);
  log.Debug("now shown");
  log.Error("stopped");
  std::istringstream lines(ReadAll(folder.LogPath()));
  std::vector<std::string> all;
  for (std::string line; std::getline(lines, line);) all.push_back(line);
  ASSERT_EQ(all.size(), 4u) << ReadAll(folder.LogPath());
  const std::regex format(
      R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z  sim=\s*(-|\d+\.\d{3}) s  (INFO |WARN |DEBUG|ERROR)  .+)");
  for (const std::string& line : all) EXPECT_TRUE(std::regex_match(line, format)) << line;
  EXPECT_NE(all[0].find("sim=         - s  INFO   run started"), std::string::npos) << all[0];
  EXPECT_NE(all[1].find("sim=    12.350 s  WARN   crowd: slip 0.3"), std::string::npos) << all[1];
  EXPECT_NE(all[2].find("DEBUG  now shown"), std::string::npos) << all[2];
  EXPECT_NE(all[3].find("ERROR  stopped"), std::string::npos) << all[3];
}

}  // namespace
}  // namespace autoshovel::results
