// The validators every numeric option of the command line carries (runtime/app/cli_checks.h):
// NaN, infinities, wrapped negatives and absurd magnitudes are refused while parsing, with the
// option's name, and values inside the documented range pass unchanged.
#include "runtime/app/cli_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace autoshovel::app {
namespace {

// Parses `arguments` for one option checked by `validator`; returns CLI11's error text, or "".
template <typename T>
std::string Parse(const CLI::Validator& validator, std::vector<std::string> arguments, T& value) {
  CLI::App app{"test"};
  app.add_option("--value", value)->check(validator);
  std::vector<std::string> reversed(arguments.rbegin(), arguments.rend());
  reversed.push_back("test");
  std::reverse(reversed.begin(), reversed.end());
  std::vector<const char*> argv;
  for (const std::string& a : reversed) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(CliChecks, FiniteInRefusesNanInfinityAndOutOfRange) {
  double v = 0;
  EXPECT_EQ(Parse(FiniteIn(0, 3, true), {"--value", "1.5"}, v), "");
  EXPECT_DOUBLE_EQ(v, 1.5);
  for (const char* bad : {"nan", "NaN", "inf", "-inf", "1e308", "0", "-1", "3.0001", "1.5x", ""}) {
    const std::string error = Parse(FiniteIn(0, 3, true), {"--value", bad}, v);
    EXPECT_NE(error, "") << bad << " was accepted";
    EXPECT_NE(error.find("--value"), std::string::npos) << error;
  }
  EXPECT_EQ(Parse(FiniteIn(0, 3), {"--value", "0"}, v), "");  // closed: 0 is in [0, 3]
  EXPECT_EQ(Parse(FiniteIn(0, 3, true), {"--value", "3"}, v), "");
}

TEST(CliChecks, IntegerInNeverWraps) {
  int workers = 0;
  EXPECT_EQ(Parse(IntegerIn(0, 1024), {"--value", "2"}, workers), "");
  EXPECT_EQ(workers, 2);
  for (const char* bad : {"-1", "1025", "1.5", "2e3", "0x10", "99999999999999999999", " 3"}) {
    EXPECT_NE(Parse(IntegerIn(0, 1024), {"--value", bad}, workers), "") << bad;
  }
}

TEST(CliChecks, SeedsStayInTheSignedSixtyFourBitRange) {
  std::uint64_t seed = 0;
  EXPECT_EQ(Parse(SeedRange(), {"--value", "9223372036854775807"}, seed), "");
  EXPECT_EQ(seed, 9223372036854775807ULL);
  // -1 used to become 18446744073709551615 in config.yaml and -1 in SQLite.
  EXPECT_NE(Parse(SeedRange(), {"--value", "-1"}, seed), "");
  EXPECT_NE(Parse(SeedRange(), {"--value", "9223372036854775808"}, seed), "");
  EXPECT_NE(Parse(SeedRange(), {"--value", "18446744073709551616"}, seed), "");
}

TEST(CliChecks, TheFailureLineNamesTheSubcommandOnce) {
  CLI::App app{"autoshovel"};
  double speed = 1;
  CLI::App* run = app.add_subcommand("run");
  run->add_option("--attack-speed", speed)->check(FiniteIn(0, 3, true));
  app.failure_message(FailureLine);
  const char* argv[] = {"./build/autoshovel", "run", "--attack-speed", "nan"};
  try {
    app.parse(4, argv);
    FAIL() << "nan accepted";
  } catch (const CLI::ParseError& e) {
    const std::string line = FailureLine(&app, e);
    EXPECT_EQ(line.rfind("autoshovel run: --attack-speed: ", 0), 0u) << line;
    EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1) << line;
  }
}

}  // namespace
}  // namespace autoshovel::app
