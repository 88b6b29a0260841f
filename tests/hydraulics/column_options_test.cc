// Explicit column options against a sibling `<log>.columns.yaml` (issue 38, defect 3): what the
// user typed wins, with a one-line notice, and an explicit map is always checked against the
// log: a wrong name, a number beyond the row, one column read as two quantities are refused
// naming the option, and nothing is written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "generated/registry.h"
#include "identification/hydraulics/hydraulic_identification.h"
#include "identification/hydraulics/identify_hydraulics_command.h"
#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/plant_logs.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
constexpr const char* kGoodColumns = "time=t,command=command,joint_angle=joint_angle,spool=spool";

// A boom step in the plant-step format (t,command,spool,pressure,joint_angle) with a sibling
// column map `step.columns.yaml` holding `sidecar`, in a folder of its own.
class SiblingMap : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::replace(test.begin(), test.end(), '/', '_');
    dir_ = ::testing::TempDir() + "/hydraulics_columns_" + std::to_string(getpid()) + "_" + test;
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ + "/out");
    const model::MachineDescription machine =
        model::LoadMachineDescription(model::ResolveMachineDescription("xcmg_968ev", kModels));
    const int actuator = FindActuator(machine, "boom");
    const HydraulicLog log = SimulatePlantLog(machine, *generated::FindMachine(machine.name),
                                              actuator, StepCommand(0.6, 0.3, 1.5), 2.3);
    log_ = dir_ + "/step.csv";
    WriteLog(log, log_, LogStyle::kPlantStep, machine.name);
    options_.machine = "xcmg_968ev";
    options_.models_dir = kModels;
    options_.logs = {log_};
    options_.overlay = dir_ + "/out/overlay.yaml";
    options_.png = dir_ + "/out/residuals.png";
    options_.cross_validate = false;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  void WriteSidecar(const std::string& text) { std::ofstream(dir_ + "/step.columns.yaml") << text; }
  std::string sidecar() const { return dir_ + "/step.columns.yaml"; }

  int Run() { return RunIdentifyHydraulics(options_, out_, err_); }
  bool WroteNothing() const { return std::filesystem::is_empty(dir_ + "/out"); }

  std::string dir_, log_;
  IdentifyHydraulicsOptions options_;
  std::ostringstream out_, err_;
};

constexpr const char* kValidSidecar =
    "columns: {time: t, command: command, joint_angle: joint_angle, spool: spool}\n";

// The sibling names columns the log does not have: it used to win and fail the run although
// the command line was right.
TEST_F(SiblingMap, ExplicitColumnsBeatTheSiblingWithANotice) {
  WriteSidecar("columns: {time: Zeit, command: Befehl, joint_angle: Winkel}\n");
  options_.columns = kGoodColumns;
  ASSERT_EQ(Run(), 0) << err_.str();
  EXPECT_EQ(err_.str(), "autoshovel identify hydraulics: note: " + sidecar() + " ignored for " +
                            log_ + ": --columns given\n");
  EXPECT_TRUE(std::filesystem::exists(options_.overlay));
}

TEST_F(SiblingMap, ExplicitColumnMapFileBeatsTheSibling) {
  WriteSidecar("columns: {time: Zeit, command: Befehl, joint_angle: Winkel}\n");
  options_.column_map = dir_ + "/mine.yaml";
  std::ofstream(options_.column_map)
      << "columns: {time: t, command: command, joint_angle: joint_angle}\n";
  ASSERT_EQ(Run(), 0) << err_.str();
  EXPECT_EQ(err_.str(), "autoshovel identify hydraulics: note: " + sidecar() + " ignored for " +
                            log_ + ": --column-map given\n");
}

// Other explicit options override the sibling's fields (here its degrees): said on stderr.
TEST_F(SiblingMap, UnitOptionsOverrideTheSiblingWithANotice) {
  WriteSidecar(std::string(kValidSidecar) + "units: {angle: deg}\nactuator: stick\n");
  options_.angle_units = "rad";
  options_.actuator = "boom";
  options_.model = "linear";  // its rated flow shows a unit mistake in l/min
  ASSERT_EQ(Run(), 0) << err_.str();
  EXPECT_EQ(err_.str(), "autoshovel identify hydraulics: note: " + log_ + " read with " +
                            sidecar() + ", --angle-units and --actuator overriding it\n");
  EXPECT_NE(out_.str().find("boom_cylinders: 1 files"), std::string::npos) << out_.str();
  // Radians read as degrees would shrink the motion 57-fold and the flow with it (~7 l/min).
  std::stringstream overlay;
  overlay << std::ifstream(options_.overlay).rdbuf();
  const std::size_t at = overlay.str().find("rated_flow_lpm: ");
  ASSERT_NE(at, std::string::npos) << overlay.str();
  EXPECT_NEAR(std::stod(overlay.str().substr(at + 16)), 400, 40) << overlay.str();
}

struct BadColumns {
  const char* name;
  const char* columns;
  const char* message;  // after "<log>:"
};

class BadExplicitColumns : public SiblingMap, public ::testing::WithParamInterface<BadColumns> {};

// A valid sibling beside the log used to hide each of these (exit 0, the sibling's fit).
TEST_P(BadExplicitColumns, AreRefusedNamingTheOptionEvenWithAValidSibling) {
  WriteSidecar(kValidSidecar);
  options_.columns = GetParam().columns;
  EXPECT_EQ(Run(), 2);
  const std::string prefix = GetParam().message[0] == '-' ? "" : log_ + ":";
  EXPECT_EQ(err_.str(), "autoshovel identify hydraulics: note: " + sidecar() + " ignored for " +
                            log_ + ": --columns given\n" + prefix + GetParam().message + "\n");
  EXPECT_TRUE(WroteNothing());
}

INSTANTIATE_TEST_SUITE_P(
    Columns, BadExplicitColumns,
    ::testing::Values(
        BadColumns{"MissingName", "time=t,command=comand,joint_angle=joint_angle",
                   "3:1: --columns: command: no column 'comand' (did you mean 'command'?)"},
        BadColumns{"NumberBeyondTheRow", "time=t,command=command,joint_angle=99",
                   "4:1: --columns: joint_angle: column 99 does not exist; the rows have 5 cells"},
        BadColumns{"HugeNumber", "time=t,command=command,joint_angle=99999999999999999999",
                   "4:1: --columns: joint_angle: column 99999999999999999999 does not exist; the "
                   "rows have 5 cells"},
        BadColumns{"OneColumnTwoQuantities", "time=t,command=t,joint_angle=joint_angle",
                   "3:1: --columns: command and time both read column 1 ('t'); each quantity "
                   "needs its own column"},
        BadColumns{"SameColumnByNameAndNumber", "time=1,command=t,joint_angle=joint_angle",
                   "3:1: --columns: command and time both read column 1 ('t'); each quantity "
                   "needs its own column"},
        BadColumns{"QuantityTwice", "time=t,command=command,joint_angle=joint_angle,time=spool",
                   "--columns: time is given twice ('t' and 'spool'); give it once"},
        BadColumns{"NoPair", ",", "--columns: no quantity=column pair in ','"}),
    [](const ::testing::TestParamInfo<BadColumns>& param) { return param.param.name; });

// Without any sibling, at the reader: one column read as two quantities is refused too.
TEST(ColumnMap, OneColumnForTwoQuantitiesIsRefused) {
  const std::string path =
      ::testing::TempDir() + "/" + std::to_string(getpid()) + "_two_quantities.csv";
  std::ofstream(path) << "t,u,q\n0,0,0\n0.01,0.5,0.1\n0.02,0.5,0.2\n";
  try {
    ReadHydraulicLog(path, ParseColumnsSpec("time=t,command=u,joint_angle=u"), 3);
    FAIL() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(std::string(e.what()), path +
                                         ":1:1: --columns: command and joint_angle both read "
                                         "column 2 ('u'); each quantity needs its own column");
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace autoshovel::identification
