#include "runtime/core/strings.h"

#include <gtest/gtest.h>

namespace autoshovel::core {
namespace {

TEST(Strings, EditDistanceCountsSingleCharacterEdits) {
  EXPECT_EQ(EditDistance("", ""), 0u);
  EXPECT_EQ(EditDistance("bore", "bore"), 0u);
  EXPECT_EQ(EditDistance("bore", "bor"), 1u);
  EXPECT_EQ(EditDistance("stroke", "strok3"), 1u);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
}

TEST(Strings, NearestWordSuggestsPlausibleTyposOnly) {
  const std::vector<std::string> keys{"length", "mass", "inertia", "viscous_friction"};
  EXPECT_EQ(NearestWord("lenght", keys), "length");
  EXPECT_EQ(NearestWord("viscous_frction", keys), "viscous_friction");
  EXPECT_EQ(NearestWord("completely_different", keys), "");
}

}  // namespace
}  // namespace autoshovel::core
