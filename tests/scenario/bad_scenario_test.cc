// Every fixture under tests/scenario/bad/ is refused with exactly one diagnostic at the location
// its header names (the same pattern as tests/model/bad_description_test.cc). Header, the first
// two lines of each fixture:
//   # defect: what is wrong
//   # expect: LINE:COLUMN: key.path: text the message contains
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "runtime/core/diagnostics.h"
#include "runtime/plant/scenario.h"

namespace autoshovel::plant {
namespace {

namespace fs = std::filesystem;

const fs::path kBad = fs::path(AUTOSHOVEL_SOURCE_DIR) / "tests" / "scenario" / "bad";

std::vector<fs::path> Fixtures() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kBad)) {
    if (entry.path().extension() == ".yaml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(BadScenarios, AtLeastTenFixtures) { EXPECT_GE(Fixtures().size(), 10u); }

TEST(BadScenarios, EachIsRefusedWithOneLineAtTheExpectedLocation) {
  for (const auto& fixture : Fixtures()) {
    SCOPED_TRACE(fixture.string());
    std::ifstream in(fixture);
    std::string defect, expect;
    std::getline(in, defect);
    std::getline(in, expect);
    ASSERT_EQ(defect.rfind("# defect: ", 0), 0u) << "missing '# defect:' header";
    ASSERT_EQ(expect.rfind("# expect: ", 0), 0u) << "missing '# expect:' header";
    const std::string expected = expect.substr(10);
    const auto first_colon = expected.find(':');
    const auto second_colon = expected.find(':', first_colon + 1);
    const std::string location = expected.substr(0, second_colon);
    const std::string text = expected.substr(second_colon + 2);
    try {
      LoadScenario(fixture.string());
      ADD_FAILURE() << "accepted; " << defect;
    } catch (const core::InputError& e) {
      ASSERT_EQ(e.diagnostics().size(), 1u) << e.what();
      const std::string line = e.diagnostics()[0].ToString();
      EXPECT_EQ(line.rfind(fixture.string() + ":" + location + ": ", 0), 0u)
          << "expected at " << location << ", got: " << line;
      EXPECT_NE(line.find(text), std::string::npos) << "expected '" << text << "' in: " << line;
    }
  }
}

// All problems of a file come in one InputError, one line each.
TEST(BadScenarios, EveryProblemOfAFileIsReportedAtOnce) {
  const fs::path path =
      fs::path(::testing::TempDir()) / ("many_problems_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path)
      << "name: many_problems\n"
         "description: three defects\n"
         "lightning: dim\n"
         "materials: " AUTOSHOVEL_SOURCE_DIR
         "/models/materials\n"
         "yard: {size: [40, -40]}\n"
         "machine: {name: xcmg_968ev, start: {x: 5, y: 5, heading_deg: 0}}\n"
         "piles:\n"
         "  - {name: a, shape: cone, material: gravel, center: [5, 5], height: 2}\n";
  try {
    LoadScenario(path.string());
    ADD_FAILURE() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.diagnostics().size(), 3u) << e.what();
    const std::string all = e.what();
    EXPECT_NE(all.find(":3:1: lightning: unknown key 'lightning' (did you mean 'lighting'?)"),
              std::string::npos)
        << all;
    EXPECT_NE(all.find(":5:19: yard.size[1]: must be > 0 m, got -40 m"), std::string::npos) << all;
    EXPECT_NE(all.find(":8:38: piles[0].material: unknown material 'gravel'"), std::string::npos)
        << all;
  }
}

TEST(BadScenarios, MissingFileIsOneLine) {
  try {
    LoadScenario("/nonexistent/scenario.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const core::InputError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    EXPECT_EQ(e.diagnostics()[0].ToString(),
              "/nonexistent/scenario.yaml: cannot open: no such file");
  }
}

}  // namespace
}  // namespace autoshovel::plant
