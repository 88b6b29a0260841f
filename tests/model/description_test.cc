// The shipped machine descriptions load, validate and mean what they say.
#include "runtime/model/description.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/model/machine_summary.h"

namespace autoshovel::model {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

TEST(Description, EveryShippedMachineLoads) {
  const auto files = FindMachineDescriptions(kModels);
  ASSERT_GE(files.size(), 3u);
  for (const auto& file : files) {
    const MachineDescription m = LoadMachineDescription(file);
    EXPECT_EQ(m.sha256.size(), 64u);
    EXPECT_EQ(m.num_links(), m.kind == MachineKind::kWheelLoader ? 2u : 3u) << file;
    for (const auto& path : m.estimated) EXPECT_TRUE(m.locations.count(path)) << path;
  }
}

TEST(Description, XcmgArmMatchesTheSeedAndIsInSI) {
  const MachineDescription m =
      LoadMachineDescription(ResolveMachineDescription("xcmg_968ev", kModels));
  EXPECT_EQ(m.kind, MachineKind::kWheelLoader);
  EXPECT_EQ(m.drive, DriveKind::kElectric);
  EXPECT_DOUBLE_EQ(m.links[0].length, 3.11);  // seed §7.1
  EXPECT_DOUBLE_EQ(m.links[1].length, 1.295);
  EXPECT_NEAR(m.links[0].joint_max, 46.0 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_DOUBLE_EQ(m.hydraulics.pump_pressure, 250e5);
  // K_v = rated flow / sqrt(rated drop): 400 l/min at 15 bar.
  const auto& valve = m.hydraulics.actuators[0].valve;
  EXPECT_NEAR(valve.flow_gain, (400e-3 / 60) / std::sqrt(15e5), 1e-15);
  ASSERT_NE(m.FindMaterial("river_sand"), nullptr);
  EXPECT_TRUE(m.FindMaterial("river_sand")->difficult);
  EXPECT_FALSE(m.FindMaterial("big_gravel")->difficult);
}

TEST(Description, UnknownMachineNamesSuggestTheNearest) {
  try {
    ResolveMachineDescription("xcmg_968", kModels);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'xcmg_968ev'"), std::string::npos)
        << e.what();
  }
}

// A loader's derived figures sit in the range of its class (spec sheets of 5–6 t loaders:
// hinge pin height 4.0–4.4 m, dump clearance 2.9–3.4 m).
TEST(MachineSummary, LoaderFiguresAreThoseOfItsClass) {
  const MachineDescription m =
      LoadMachineDescription(ResolveMachineDescription("xcmg_968ev", kModels));
  const MachineSummary s = Summarize(m);
  EXPECT_NEAR(s.max_hinge_pin_height, 4.2, 0.2);
  ASSERT_TRUE(s.dump_pose_reachable);
  EXPECT_NEAR(s.dump_clearance, 3.15, 0.25);
  // Hinge pin height is exactly pivot height + l1 sin(φ1,max).
  EXPECT_NEAR(s.max_hinge_pin_height, m.arm_pivot.y() + 3.11 * std::sin(m.links[0].joint_max),
              1e-9);
  for (const auto& a : s.actuators) {
    if (a.is_motor) continue;
    EXPECT_LE(a.stroke_used, a.stroke + 1e-9) << a.name;
    EXPECT_GT(a.lever_min, 0.02) << a.name;
  }
  EXPECT_GT(s.lift_capacity_at_carry, m.bucket.rated_load);
}

}  // namespace
}  // namespace autoshovel::model
