// The shipped machine descriptions load, validate and mean what they say.
#include "runtime/model/description.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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
  ASSERT_NE(m.FindLidar("top_16"), nullptr);
  EXPECT_EQ(m.FindLidar("top_16")->name, "top_16");
  EXPECT_EQ(m.FindLidar("top_1"), nullptr);  // no prefix match
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

// A folder named like a shipped machine in the working directory (a run folder named after it)
// does not hide the description; a folder that names no machine is still said to be a folder.
TEST(Description, AFolderOfTheSameNameDoesNotHideTheMachine) {
  const std::filesystem::path before = std::filesystem::current_path();
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "description_resolve_cwd";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "xcmg_968ev");
  std::filesystem::create_directories(dir / "no_such_machine");
  std::filesystem::current_path(dir);
  const std::string resolved = ResolveMachineDescription("xcmg_968ev", kModels);
  std::string folder_error;
  try {
    ResolveMachineDescription("no_such_machine", kModels);
  } catch (const std::runtime_error& e) {
    folder_error = e.what();
  }
  std::filesystem::current_path(before);
  EXPECT_EQ(std::filesystem::path(resolved).filename(), "xcmg_968ev.yaml");
  EXPECT_NE(folder_error.find("no_such_machine: "), std::string::npos) << folder_error;
  EXPECT_NE(folder_error.find("folder"), std::string::npos) << folder_error;
}

// A loader's derived figures sit in the range of its class (spec sheets of 5–6 t loaders:
// hinge pin height 4.0–4.4 m, dump clearance 2.9–3.4 m).
TEST(MachineSummary, LoaderFiguresAreThoseOfItsClass) {
  const MachineDescription m =
      LoadMachineDescription(ResolveMachineDescription("xcmg_968ev", kModels));
  const MachineSummary s = Summarize(m);
  EXPECT_NEAR(s.max_hinge_pin_height, 4.2, 0.2);
  // Dump at 45° (SAE J732: the bucket floor 45° down at full lift): in the class's range where
  // the bucket's range reaches it; otherwise the floor stops short of 45° down.
  if (s.dump_pose_reachable) {
    EXPECT_NEAR(s.dump_clearance, 3.0, 0.4);
  } else {
    EXPECT_GT(s.dump_floor_at_limit, -std::numbers::pi / 4);
  }
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

// Writes `text` to a file of that name in the test's temporary folder and returns its path.
std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// Identified values flow in through overlays, checked against the description they belong to.
TEST(Overlay, ReplacesIdentifiedValuesAndRefusesForeignOnes) {
  const std::string path = ResolveMachineDescription("xcmg_968ev", kModels);
  const MachineDescription base = LoadMachineDescription(path);
  LoadOptions options;
  options.overlays = {WriteTemp("good.yaml", "machine: xcmg_968ev\nbase_sha256: " + base.sha256 +
                                                 "\narm:\n  links:\n    - name: boom\n"
                                                 "      length: 3.1234\n"
                                                 "      imu_offset_deg: 1.5\n")};
  const MachineDescription calibrated = LoadMachineDescription(path, options);
  EXPECT_DOUBLE_EQ(calibrated.links[0].length, 3.1234);
  EXPECT_NEAR(calibrated.links[0].imu_offset, 1.5 * std::numbers::pi / 180, 1e-15);
  EXPECT_DOUBLE_EQ(calibrated.links[1].length, base.links[1].length);  // untouched
  EXPECT_EQ(calibrated.sha256, base.sha256);  // still the same description underneath
  ASSERT_EQ(calibrated.overlays.size(), 1u);

  auto error_of = [&](const std::string& file) {
    LoadOptions bad;
    bad.overlays = {file};
    try {
      LoadMachineDescription(path, bad);
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string foreign = error_of(WriteTemp("foreign.yaml", "machine: sdlg_l955he\n"));
  EXPECT_NE(foreign.find("foreign.yaml:1:10: machine: this overlay is for 'sdlg_l955he'"),
            std::string::npos)
      << foreign;
  const std::string stale =
      error_of(WriteTemp("stale.yaml", "machine: xcmg_968ev\nbase_sha256: 0123\n"));
  EXPECT_NE(stale.find("stale.yaml:2:14: base_sha256: identified against another version"),
            std::string::npos)
      << stale;
  const std::string typo =
      error_of(WriteTemp("typo.yaml", "machine: xcmg_968ev\narm:\n  links:\n    - name: bom\n"));
  EXPECT_NE(typo.find("typo.yaml:4:13: arm.links[0].name: no link 'bom' in xcmg_968ev; did you "
                      "mean 'boom'?"),
            std::string::npos)
      << typo;
  const std::string negative = error_of(
      WriteTemp("negative.yaml",
                "machine: xcmg_968ev\narm:\n  links:\n    - name: boom\n      length: -1\n"));
  EXPECT_NE(negative.find("negative.yaml:5:15: arm.links[0].length: must be > 0 m"),
            std::string::npos)
      << negative;
}

// Valve dynamics and sensor poses are overlaid the same way, with the description's own rules.
TEST(Overlay, ReplacesValveDynamicsAndSensorPoses) {
  const std::string path = ResolveMachineDescription("xcmg_968ev", kModels);
  const MachineDescription base = LoadMachineDescription(path);
  LoadOptions options;
  options.overlays = {WriteTemp("valves.yaml",
                                "machine: xcmg_968ev\nhydraulics:\n  actuators:\n"
                                "    - name: boom_cylinders\n      dead_zone: 0.07\n"
                                "      transport_delay: 0.45\n      spool_time_constant: 0.09\n"
                                "      rated_flow_lpm: 420\n"
                                "sensors:\n  camera:\n    pose: {xyz: [-1.1, 0.02, 3.5], rpy_deg: "
                                "[0.5, 14, -1]}\n  lidars:\n    - name: front_solid_state\n"
                                "      pose: {xyz: [0, 0, 3], rpy_deg: [0, 10, 0]}\n")};
  const MachineDescription m = LoadMachineDescription(path, options);
  const int boom = m.ActuatorOfJoint(0);
  ASSERT_GE(boom, 0);
  const Valve& valve = m.hydraulics.actuators[boom].valve;
  EXPECT_DOUBLE_EQ(valve.dead_zone, 0.07);
  EXPECT_DOUBLE_EQ(valve.transport_delay, 0.45);
  EXPECT_DOUBLE_EQ(valve.spool_time_constant, 0.09);
  EXPECT_NEAR(valve.rated_flow, 420e-3 / 60, 1e-15);
  // The orifice gain follows the new rated flow at the unchanged rated drop.
  EXPECT_NEAR(valve.flow_gain * std::sqrt(valve.rated_pressure_drop), valve.rated_flow, 1e-15);
  EXPECT_NEAR(m.sensors.camera.pose.rpy[1], 14 * std::numbers::pi / 180, 1e-15);
  EXPECT_DOUBLE_EQ(m.sensors.camera.pose.xyz[1], 0.02);
  EXPECT_EQ(m.sensors.lidars[0].pose.xyz, base.sensors.lidars[0].pose.xyz);  // top_16 untouched
  EXPECT_DOUBLE_EQ(m.sensors.lidars[1].pose.xyz[2], 3.0);

  LoadOptions bad;
  bad.overlays = {WriteTemp("bad_valve.yaml",
                            "machine: xcmg_968ev\nhydraulics:\n  actuators:\n"
                            "    - name: bom_cylinders\n    - name: tilt_cylinder\n"
                            "      dead_zone: 0.6\n")};
  try {
    LoadMachineDescription(path, bad);
    ADD_FAILURE() << "accepted";
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad_valve.yaml:4:13: hydraulics.actuators[0].name: no actuator "
                        "'bom_cylinders' in xcmg_968ev; did you mean 'boom_cylinders'?"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("bad_valve.yaml:6:18: hydraulics.actuators[1].dead_zone:"),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace autoshovel::model
