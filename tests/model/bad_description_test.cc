// Every fixture under tests/data/bad/ is refused with exactly one diagnostic at the location its
// header names. Header (the first two lines of each fixture):
//   # defect: what is wrong
//   # expect: LINE:COLUMN: key.path: text the message contains
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"

namespace autoshovel::model {
namespace {

namespace fs = std::filesystem;

const fs::path kBad = fs::path(AUTOSHOVEL_SOURCE_DIR) / "tests" / "data" / "bad";
const std::string kMaterials = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/materials";

LoadOptions MaterialsOnly() {
  LoadOptions options;
  options.materials_dir = kMaterials;
  return options;
}

std::vector<fs::path> Fixtures() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kBad)) {
    if (entry.path().extension() == ".yaml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(BadDescriptions, AtLeastTwelveFixtures) { EXPECT_GE(Fixtures().size(), 12u); }

TEST(BadDescriptions, EachIsRefusedWithOneLineAtTheExpectedLocation) {
  for (const auto& fixture : Fixtures()) {
    std::ifstream in(fixture);
    std::string defect, expect;
    std::getline(in, defect);
    std::getline(in, expect);
    ASSERT_EQ(expect.rfind("# expect: ", 0), 0u) << fixture << ": missing '# expect:' header";
    const std::string expected = expect.substr(10);
    const auto first_colon = expected.find(':');
    const auto second_colon = expected.find(':', first_colon + 1);
    const std::string location = expected.substr(0, second_colon);
    const std::string text = expected.substr(second_colon + 2);
    try {
      LoadMachineDescription(fixture.string(), MaterialsOnly());
      ADD_FAILURE() << fixture << " was accepted; " << defect;
    } catch (const core::InputError& e) {
      ASSERT_EQ(e.diagnostics().size(), 1u) << fixture << ":\n" << e.what();
      const std::string line = e.diagnostics()[0].ToString();
      EXPECT_EQ(line.rfind(fixture.string() + ":" + location + ": ", 0), 0u)
          << "expected at " << location << ", got: " << line;
      EXPECT_NE(line.find(text), std::string::npos) << "expected '" << text << "' in: " << line;
    }
  }
}

}  // namespace
}  // namespace autoshovel::model
