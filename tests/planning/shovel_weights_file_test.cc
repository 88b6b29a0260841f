// The Eq. (18) weights file: read as written by `autoshovel train weights`, and every malformed
// file refused with its file:line:column, leaving the configuration untouched.
#include "runtime/planning/shovel_weights_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "runtime/core/diagnostics.h"

namespace autoshovel::planning {
namespace {

std::string Write(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("autoshovel_w_" + std::to_string(::getpid()) + "_" + name + ".yaml");
  std::ofstream(path) << text;
  return path.string();
}

// The error of reading `text`, and that the configuration kept Table 1's weights.
std::string ErrorOf(const std::string& name, const std::string& text) {
  ShovelPointConfig config;
  std::string message;
  try {
    ReadShovelWeights(Write(name, text), config);
  } catch (const core::InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(config.k_t, ShovelPointConfig{}.k_t) << name;
  EXPECT_EQ(config.k_a, ShovelPointConfig{}.k_a) << name;
  return message;
}

TEST(ShovelWeightsFile, ReadsTheFiveWeights) {
  ShovelPointConfig config;
  ReadShovelWeights(Write("good", "# tuned\nk_t: 0.1\nk_s: 0.2\nk_c: 0\nk_e: 0.3\nk_a: 0.4\n"),
                    config);
  EXPECT_EQ(config.k_t, 0.1);
  EXPECT_EQ(config.k_s, 0.2);
  EXPECT_EQ(config.k_c, 0.0);
  EXPECT_EQ(config.k_e, 0.3);
  EXPECT_EQ(config.k_a, 0.4);
}

TEST(ShovelWeightsFile, MalformedFilesNameFileLineAndKey) {
  const std::string negative =
      ErrorOf("negative", "k_t: 0.1\nk_s: -0.2\nk_c: 0\nk_e: 0.3\nk_a: 0.4\n");
  EXPECT_NE(negative.find("negative.yaml:2:6: k_s: must be >= 0, got -0.2"), std::string::npos)
      << negative;
  const std::string missing = ErrorOf("missing", "k_t: 0.1\nk_s: 0.2\nk_c: 0\nk_e: 0.3\n");
  EXPECT_NE(missing.find("k_a"), std::string::npos) << missing;
  EXPECT_NE(missing.find("missing.yaml:1:1"), std::string::npos) << missing;
  const std::string typo =
      ErrorOf("typo", "k_t: 0.1\nk_s: 0.2\nk_c: 0\nk_e: 0.3\nk_a: 0.4\nk_x: 1\n");
  EXPECT_NE(typo.find("typo.yaml:6:1: k_x: unknown key"), std::string::npos) << typo;
  const std::string zeros = ErrorOf("zeros", "k_t: 0\nk_s: 0\nk_c: 0\nk_e: 0\nk_a: 0\n");
  EXPECT_NE(zeros.find("all five weights are zero"), std::string::npos) << zeros;
  const std::string text = ErrorOf("text", "k_t: heavy\nk_s: 0.2\nk_c: 0\nk_e: 0.3\nk_a: 0.4\n");
  EXPECT_NE(text.find("text.yaml:1:6: k_t"), std::string::npos) << text;
  const std::string syntax = ErrorOf("syntax", "k_t: [0.1\n");
  EXPECT_NE(syntax.find("syntax.yaml:"), std::string::npos) << syntax;
  ShovelPointConfig config;
  EXPECT_THROW(ReadShovelWeights("/nonexistent/weights.yaml", config), core::InputError);
}

}  // namespace
}  // namespace autoshovel::planning
