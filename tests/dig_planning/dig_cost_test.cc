// The refined planner's cost (dig_cost.h) and what counts as a usable prediction (dig_action.h).
#include "runtime/planning/dig/dig_cost.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace autoshovel::planning {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

DigPrediction Prediction(double volume, double energy, double duration) {
  DigPrediction p;
  p.executed = true;
  p.volume = volume;
  p.energy = energy;
  p.duration = duration;
  p.tip_path = {{7.0, 0.0, 1.0}, {5.0, 0.0, 0.5}};
  return p;
}

TEST(DigCost, TermsAsDocumented) {
  DigCostConfig c;
  c.bucket_capacity = 1.2;
  c.weight_volume = 1.0;
  c.weight_energy = 0.25;
  c.weight_time = 0.5;
  c.weight_overflow = 2.0;
  c.energy_reference = 4e5;
  c.time_reference = 8.0;
  // Under capacity: 0.9 of 1.2 m^3, 200 kJ, 6 s.
  DigCostTerms t = DigCost(Prediction(0.9, 2e5, 6.0), c);
  EXPECT_NEAR(t.unfilled, 0.25, 1e-15);
  EXPECT_NEAR(t.energy, 0.125, 1e-15);
  EXPECT_NEAR(t.time, 0.375, 1e-15);
  EXPECT_EQ(t.overflow, 0.0);
  EXPECT_NEAR(t.total, 0.75, 1e-15);
  // Over capacity: nothing unfilled, the overflow paid twice over.
  t = DigCost(Prediction(1.5, 0.0, 0.0), c);
  EXPECT_EQ(t.unfilled, 0.0);
  EXPECT_NEAR(t.overflow, 2.0 * 0.3 / 1.2, 1e-15);
  EXPECT_NEAR(t.total, 0.5, 1e-15);
  // The volume terms alone, for screening.
  EXPECT_NEAR(VolumeCost(0.9, c), 0.25, 1e-15);
  EXPECT_NEAR(VolumeCost(1.5, c), 0.5, 1e-15);
  // Exactly full is the best a volume can do.
  EXPECT_EQ(VolumeCost(1.2, c), 0.0);
}

TEST(DigCost, UnusablePredictionsHaveNoCost) {
  const DigCostConfig c;
  std::string why;
  DigPrediction p = Prediction(1.0, 1e5, 5.0);
  EXPECT_TRUE(IsUsable(p, why));
  p.executed = false;
  p.why = "relief valve open";
  EXPECT_FALSE(IsUsable(p, why));
  EXPECT_NE(why.find("relief valve open"), std::string::npos);
  EXPECT_TRUE(std::isnan(DigCost(p, c).total));
  for (auto broken : {Prediction(kNaN, 1e5, 5.0), Prediction(1.0, kNaN, 5.0),
                      Prediction(1.0, 1e5, std::numeric_limits<double>::infinity())}) {
    EXPECT_FALSE(IsUsable(broken, why));
    EXPECT_NE(why.find("non-finite"), std::string::npos) << why;
    const DigCostTerms t = DigCost(broken, c);
    EXPECT_TRUE(std::isnan(t.total) && std::isnan(t.unfilled) && std::isnan(t.energy));
  }
  EXPECT_FALSE(IsUsable(Prediction(-0.1, 1e5, 5.0), why));
  EXPECT_NE(why.find("negative"), std::string::npos) << why;
  p = Prediction(1.0, 1e5, 5.0);
  p.tip_path.push_back({kNaN, 0.0, 0.0});
  EXPECT_FALSE(IsUsable(p, why));
  EXPECT_NE(why.find("tip path"), std::string::npos) << why;
}

TEST(DigCost, InvalidConfigNamesTheField) {
  auto expect_field = [](const DigCostConfig& c, const std::string& field) {
    try {
      Validate(c, "cost");
      ADD_FAILURE() << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("cost." + field), std::string::npos) << e.what();
    }
  };
  DigCostConfig c;
  c.bucket_capacity = -1.0;
  expect_field(c, "bucket_capacity");
  c = {};
  c.weight_volume = kNaN;
  expect_field(c, "weight_volume");
  c = {};
  c.weight_time = -1.0;
  expect_field(c, "weight_time");
  c = {};
  c.weight_overflow = -1.0;
  expect_field(c, "weight_overflow");
  c = {};
  c.energy_reference = 0.0;
  expect_field(c, "energy_reference");
  EXPECT_NO_THROW(Validate(DigCostConfig{}, "cost"));
}

}  // namespace
}  // namespace autoshovel::planning
