// `autoshovel identify hydraulics --simulate DIR --format controldesk`: an excavator's boom step
// tests written in the real ControlDesk layout (plant_logs.h), with the truth chain beside
// them, read back by the log reader with numbered columns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "generated/registry.h"
#include "identification/hydraulics/identify_hydraulics_command.h"
#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/plant_logs.h"
#include "runtime/model/description.h"
#include "runtime/plant/valve_command.h"
#include "tests/hydraulics/controldesk_campaign.h"

namespace autoshovel::identification {
namespace {

namespace fs = std::filesystem;

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::size_t Cells(const std::string& line) {
  // Cells outside quotes (the Origin header cell holds a quoted comma).
  std::size_t cells = 1;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    if (c == ',' && !quoted) ++cells;
  }
  return cells;
}

// The boom's columns, 1-based (the leading `trace_values`/empty cell is column 1).
LogFormat BoomUpFormat() {
  LogFormat format;
  format.columns = {{"time", "2"},       {"command", "14"},   {"joint_angle", "29"},
                    {"pressure_a", "8"}, {"pressure_b", "7"}, {"pilot_pressure", "26"}};
  format.command_units = CommandUnits::kPercent;
  format.angle_units = AngleUnits::kDegrees;
  format.pressure_units = PressureUnits::kBar;
  format.header_lines = 28;
  format.actuator = "boom_cylinders";
  return format;
}

TEST(ControlDeskSimulation, WritesTheRealLayoutWithItsTruthAndReadsBack) {
  const std::string dir = ::testing::TempDir() + "/controldesk_boom";
  testing::WriteBoomControlDeskCampaign(dir, kModels);

  // 2 directions × 7 duties × H/L, named as the real files.
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".csv") names.push_back(entry.path().filename().string());
  }
  EXPECT_EQ(names.size(), 28u);
  for (const char* name : {"B-up-40-H-S.csv", "B-dn-100-L-S.csv", "B-up-70-L-S.csv"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }

  // The truth overlay loads on the description and holds the chain.
  model::LoadOptions load;
  load.overlays = {dir + "/truth.overlay.yaml"};
  const model::MachineDescription truth = model::LoadMachineDescription(
      model::ResolveMachineDescription("excavator_25t", kModels), load);
  const model::Valve& valve = truth.hydraulics.actuators[truth.ActuatorOfJoint(0)].valve;
  EXPECT_GT(valve.pilot_time_constant, 0.0);
  EXPECT_GT(valve.pilot_delay, 0.0);
  EXPECT_EQ(valve.dead_zone, 0.0);
  ASSERT_FALSE(valve.opening_curve_extend.empty());
  ASSERT_FALSE(valve.opening_curve_retract.empty());
  const double dead_band = valve.opening_curve_extend.front().duty;
  EXPECT_GT(dead_band, 0.3);
  EXPECT_LT(dead_band, 0.4);

  // The layout: 28 header lines as exported, then rows `trace_values,` / `,` of 29 cells.
  const std::vector<std::string> lines = Lines(dir + "/B-up-60-H-S.csv");
  ASSERT_GT(lines.size(), 400u);
  EXPECT_EQ(lines[0].rfind("descriptions,", 0), 0u);
  EXPECT_EQ(lines[14], "trace_size," + std::to_string(lines.size() - 28));
  EXPECT_EQ(lines[16].rfind("trace_names,,In1,In1,", 0), 0u);
  EXPECT_NE(lines[16].find(",Boom_dn_duty,Boom_up_duty,"), std::string::npos);
  EXPECT_EQ(lines[22].rfind("path,", 0), 0u);
  EXPECT_NE(lines[22].find("/Boom_UpH_Cyl_P"), std::string::npos);
  EXPECT_EQ(lines[27].rfind("maxWeak,", 0), 0u);
  EXPECT_EQ(lines[28].rfind("trace_values,0.00000,", 0), 0u);
  EXPECT_EQ(lines[29].rfind(",0.01000,", 0), 0u);
  for (std::size_t i = 15; i < lines.size(); ++i) {
    ASSERT_EQ(Cells(lines[i]), 29u) << "line " << i + 1 << ": " << lines[i];
  }

  // Read back with numbered columns.
  const HydraulicLog log = ReadHydraulicLog(dir + "/B-up-60-H-S.csv", BoomUpFormat());
  ASSERT_EQ(log.size(), lines.size() - 28);
  ASSERT_EQ(log.pilot_pressure.size(), log.size());
  // The step: 0 before 1 s, 60 % from 1 s.
  std::size_t step = 0;
  while (step < log.size() && log.command[step] == 0) ++step;
  ASSERT_LT(step, log.size());
  EXPECT_NEAR(log.time[step], 1.0, 1e-9);
  EXPECT_NEAR(log.command[step], 0.6, 1e-12);
  // Pilot pressure: within noise at rest, then 35 bar × 0.6 after a few lags.
  const double full = ControlDeskOptions{}.pilot_pressure_full;
  for (std::size_t i = 0; i < step + 6; ++i) EXPECT_LT(std::abs(log.pilot_pressure[i]), 1.5e5);
  EXPECT_NEAR(log.pilot_pressure[step + 60], 0.6 * full, 1.5e5);
  // The pilot rises 1 bar (3 noise sigmas) within a few samples of τ_p + 1 bar's share of T_p.
  std::size_t rise = step;
  while (log.pilot_pressure[rise] < 1e5) ++rise;
  const double expected_rise =
      valve.pilot_delay - valve.pilot_time_constant * std::log(1.0 - 1e5 / (0.6 * full));
  EXPECT_NEAR(log.time[rise] - log.time[step], expected_rise, 0.025);
  // The boom rises, runs into its stop and stalls there with the cap side near the pump's
  // limit for the last second of the step.
  std::size_t off = step;
  while (off < log.size() && log.command[off] > 0) ++off;
  ASSERT_LT(off, log.size());
  EXPECT_GT(log.joint_angle[off - 1] - log.joint_angle[step], 20 * std::numbers::pi / 180);
  for (std::size_t i = off - 90; i < off; ++i) {
    EXPECT_NEAR(log.joint_angle[i], log.joint_angle[off - 1], 0.2 * std::numbers::pi / 180);
    EXPECT_GT(log.pressure_a[i], 0.85 * truth.hydraulics.pump_pressure - 4e5);  // 4σ noise
  }
}

// The same seed gives the same bytes; another seed other noise on the same motion.
TEST(ControlDeskSimulation, DeterministicForASeed) {
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription("excavator_25t", kModels));
  const generated::MachineFunctions& functions = *generated::FindMachine("excavator_25t");
  ControlDeskOptions options;
  options.duties = {80};
  const std::vector<int> arm = {machine.ActuatorOfJoint(1)};
  const std::string a = ::testing::TempDir() + "/controldesk_a";
  const std::string b = ::testing::TempDir() + "/controldesk_b";
  const std::string c = ::testing::TempDir() + "/controldesk_c";
  const std::vector<std::string> pa =
      WriteControlDeskCampaign(machine, functions, arm, a, 3, options);
  const std::vector<std::string> pb =
      WriteControlDeskCampaign(machine, functions, arm, b, 3, options);
  const std::vector<std::string> pc =
      WriteControlDeskCampaign(machine, functions, arm, c, 4, options);
  ASSERT_EQ(pa.size(), 4u);  // A-in/out-80-H/L
  EXPECT_EQ(fs::path(pa[0]).filename(), "A-in-80-H-S.csv");
  auto text = [](const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(text(pa[i]), text(pb[i])) << pa[i];
    EXPECT_NE(text(pa[i]), text(pc[i])) << pa[i];
  }
  // A bucket test has no real counterpart: refused by name.
  try {
    WriteControlDeskCampaign(machine, functions, {machine.ActuatorOfJoint(2)}, a, 3, options);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bucket_cylinder"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace autoshovel::identification
