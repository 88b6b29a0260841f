// ControlDesk CSV exports and column expressions (issue 40, item 1): a tiny export written here
// (made-up channels in the layout of a dSPACE MicroAutoBox recording) is read by trace name,
// path, path part, number and expression, values checked exactly; duplicate names, malformed
// exports and malformed expressions are refused with a located message.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "identification/hydraulics/column_expression.h"
#include "identification/hydraulics/log_reader.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {
namespace {

// Columns of the file (1-based; column 1 holds the row markers):
//   2 time   3 Lift_Cap_P   4 Lift_Rod_P   5 Lift_up_duty   6 Lift_dn_duty
//   7 Lift_Up_pilot_P   8 Lift_Dn_pilot_P   9 Lift_ang
// Every trace but the duties is named `In1`; the two duties share one path.
constexpr const char* kHeader =
    "descriptions,General,User,tester\n"                             // 1
    ",General,Origin,\"Recorder 1.0, build 7\\nPlatform: bench\"\n"  // 2
    ",Measurement,Length,0.05\n"                                     // 3
    "\n"                                                             // 4
    "trace_size,6\n"                                                 // 5
    "trace_types,5,4,4,4,4,4,4,4\n"                                  // 6
    "trace_names,,In1,In1,Lift_up_duty,Lift_dn_duty,In1,In1,In1\n"   // 7
    "trace_units,,,,,,,,\n"                                          // 8
    "path,,Root/Pressures/Lift_Cap_P,Root/Pressures/Lift_Rod_P,Root/Valve signals,"
    "Root/Valve signals,Root/Pilot/Lift_Up_pilot_P,Root/Pilot/Lift_Dn_pilot_P,"
    "Root/Angles(03.24)/Lift_ang\n"  // 9
    "flags,,2,2,2,2,2,2,2\n";        // 10
constexpr const char* kSamples =
    "trace_values,0,10,20,0,0,1.5,0.5,30\n"  // 11
    ",0.01,11,21,40,0,2.5,0.5,31\n"          // 12
    ",0.02,12,22,0,25,0.5,3.5,32.5\n"        // 13
    ",0.03,13,23,100,0,3,0,33\n"             // 14
    ",0.04,14,24,0,100,0,3,34\n"             // 15
    ",0.05,15,25,0,0,0,0,35\n";              // 16

class ControlDeskLog : public ::testing::Test {
 protected:
  std::string Write(const std::string& text) {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    const std::string path =
        ::testing::TempDir() + "/" + std::to_string(getpid()) + "_" + test + ".csv";
    std::ofstream(path, std::ios::binary) << text;
    paths_.push_back(path);
    return path;
  }
  void TearDown() override {
    for (const std::string& path : paths_) std::filesystem::remove(path);
  }

  // The refusal of `path` read with `columns` (percent, deg, bar), `path` written `<log>`.
  static std::string Refusal(const std::string& path, const std::string& columns) {
    try {
      ReadHydraulicLog(path, Format(columns), 1);
    } catch (const core::InputError& e) {
      std::string message = e.what();
      if (message.starts_with(path)) message.replace(0, path.size(), "<log>");
      return message;
    }
    return "accepted";
  }

  static LogFormat Format(const std::string& columns) {
    LogFormat format = ParseColumnsSpec(columns);
    format.command_units = format.spool_units = CommandUnits::kPercent;
    format.angle_units = AngleUnits::kDegrees;
    format.pressure_units = PressureUnits::kBar;
    return format;
  }

  std::vector<std::string> paths_;
};

constexpr double kDeg = std::numbers::pi / 180;

TEST_F(ControlDeskLog, ReadsByNamePathNumberAndExpression) {
  const std::string path = Write(std::string(kHeader) + kSamples);
  const HydraulicLog log = ReadHydraulicLog(
      path,
      Format("time=time, command=Lift_up_duty - Lift_dn_duty, joint_angle=-Lift_ang + 90,"
             "pressure_a=0.1*Lift_Cap_P, pressure_b='Root/Pressures/Lift_Rod_P',"
             "pilot_pressure=Lift_Up_pilot_P + $8"),
      6);
  ASSERT_EQ(log.size(), 6u);
  EXPECT_EQ(log.row, (std::vector<int>{11, 12, 13, 14, 15, 16}));
  EXPECT_EQ(log.time, (std::vector<double>{0, 0.01, 0.02, 0.03, 0.04, 0.05}));
  // Two direction channels → one signed command in [-1, 1].
  EXPECT_EQ(log.command, (std::vector<double>{0, 0.4, -0.25, 1, -1, 0}));
  // Negation and offset: 90 - angle, then degrees → radians.
  for (std::size_t i = 0; i < log.size(); ++i) {
    SCOPED_TRACE(i);
    const double angle_deg = std::vector<double>{30, 31, 32.5, 33, 34, 35}[i];
    EXPECT_DOUBLE_EQ(log.joint_angle[i], (90 - angle_deg) * kDeg);
    EXPECT_DOUBLE_EQ(log.pressure_a[i], 0.1 * (10 + static_cast<double>(i)) * 1e5);
    EXPECT_DOUBLE_EQ(log.pressure_b[i], (20 + static_cast<double>(i)) * 1e5);
  }
  EXPECT_EQ(log.pilot_pressure, (std::vector<double>{2e5, 3e5, 4e5, 3e5, 3e5, 0}));
  EXPECT_TRUE(log.spool.empty());
  EXPECT_EQ(log.sources.at("command").expression, "Lift_up_duty - Lift_dn_duty");
  EXPECT_EQ(log.sources.at("command").columns, (std::vector<int>{5, 6}));
  EXPECT_EQ(log.sources.at("pilot_pressure").columns, (std::vector<int>{7, 8}));
  EXPECT_EQ(log.sources.at("time").columns, (std::vector<int>{2}));

  // The same columns by the file's numbers (the marker cell is column 1), and with the header
  // lines given: the same samples.
  LogFormat by_number = Format("time=2, command=$5 - $6, joint_angle=-$9 + 90");
  const HydraulicLog numbered = ReadHydraulicLog(path, by_number, 6);
  EXPECT_EQ(numbered.time, log.time);
  EXPECT_EQ(numbered.command, log.command);
  EXPECT_EQ(numbered.joint_angle, log.joint_angle);
  by_number.header_lines = 10;
  EXPECT_EQ(ReadHydraulicLog(path, by_number, 6).command, log.command);
  // The full path of a trace, the time column by its number.
  const HydraulicLog by_path = ReadHydraulicLog(
      path, Format("time=2,command=Lift_up_duty,joint_angle='Root/Angles(03.24)/Lift_ang'"), 6);
  EXPECT_DOUBLE_EQ(by_path.joint_angle[2], 32.5 * kDeg);
  EXPECT_EQ(by_path.command, (std::vector<double>{0, 0.4, 0, 1, 0, 0}));
}

TEST_F(ControlDeskLog, YamlMapTakesExpressions) {
  const std::string path = Write(std::string(kHeader) + kSamples);
  const std::string map = path + ".columns.yaml";
  paths_.push_back(map);
  std::ofstream(map) << "columns: {time: time, command: Lift_dn_duty - Lift_up_duty,\n"
                        "          joint_angle: 2*Lift_ang}\n"
                        "units: {command: percent, angle: deg}\n";
  const HydraulicLog log = ReadHydraulicLog(path, ReadLogFormatYaml(map), 6);
  EXPECT_EQ(log.command, (std::vector<double>{0, -0.4, 0.25, -1, 1, 0}));
  EXPECT_DOUBLE_EQ(log.joint_angle[2], 65 * kDeg);

  std::ofstream(map) << "columns: {time: time, command: Lift_up_duty -,\n"
                        "          joint_angle: Lift_ang}\n";
  try {
    ReadLogFormatYaml(map);
    FAIL() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(std::string(e.what()), map +
                                         ":1:32: columns.command: 'Lift_up_duty -' at "
                                         "character 15: expected a column name, $N or a number "
                                         "after '-'");
  }
}

TEST_F(ControlDeskLog, DuplicateNamesAreRefusedListingTheirColumns) {
  const std::string path = Write(std::string(kHeader) + kSamples);
  EXPECT_EQ(Refusal(path, "time=time,command=Lift_up_duty,joint_angle=In1"),
            "<log>:7:1: --columns: joint_angle: 'In1' names columns 3, 4, 7..9 (ControlDesk "
            "trace_names): give the column by number (3) or by its path name (e.g. "
            "'Lift_Cap_P')");
  // In an expression, the number is written $N.
  EXPECT_EQ(Refusal(path, "time=time,command=In1 - Lift_dn_duty,joint_angle=Lift_ang"),
            "<log>:7:1: --columns: command: 'In1' names columns 3, 4, 7..9 (ControlDesk "
            "trace_names): give the column by number ($3) or by its path name (e.g. "
            "'Lift_Cap_P')");
  // The duties share their path: by it, they are two columns.
  EXPECT_EQ(Refusal(path, "time=time,command='Valve signals',joint_angle=Lift_ang"),
            "<log>:7:1: --columns: command: 'Valve signals' names columns 5, 6 (ControlDesk "
            "path): give the column by number (5) or by another name (e.g. 'Lift_up_duty')");
}

TEST_F(ControlDeskLog, MalformedExportsAreLocated) {
  EXPECT_EQ(Refusal(Write(kHeader), "time=time,command=Lift_up_duty,joint_angle=Lift_ang"),
            "<log>:7:1: ControlDesk export: a trace_names row but no trace_values row after it "
            "(no samples)");
  // Row 13 lost its last cell.
  std::string text = std::string(kHeader) + kSamples;
  text.replace(text.find(",32.5\n"), 6, "\n");
  EXPECT_EQ(Refusal(Write(text), "time=time,command=Lift_up_duty,joint_angle=Lift_ang"),
            "<log>:13:1: 8 cells, expected 9 like the first sample row");
  // A NaN in a column the command reads: row 13, the cell of Lift_dn_duty.
  text = std::string(kHeader) + kSamples;
  text.replace(text.find(",0.02,12,22,0,25,"), 17, ",0.02,12,22,0,nan,");
  EXPECT_EQ(
      Refusal(Write(text), "time=time,command=Lift_up_duty - Lift_dn_duty,joint_angle=Lift_ang"),
      "<log>:13:15: command (column 'Lift_dn_duty') is not a finite number: 'nan'");
  // A NaN in a column nobody reads is no concern.
  EXPECT_EQ(Refusal(paths_.back(), "time=time,command=Lift_up_duty,joint_angle=Lift_ang"),
            "accepted");
  // A sample row after trace_values that opens with a cell of its own.
  text = std::string(kHeader) + kSamples;
  text.replace(text.find(",0.03,"), 6, "x,0.03,");
  EXPECT_EQ(Refusal(Write(text), "time=time,command=Lift_up_duty,joint_angle=Lift_ang"),
            "<log>:14:1: a ControlDesk sample row opens with an empty cell, got 'x'");
  // The names row does not match the samples.
  text = std::string(kHeader) + kSamples;
  text.replace(text.find(",In1\ntrace_units"), 5, "\n");
  EXPECT_EQ(Refusal(Write(text), "time=time,command=Lift_up_duty,joint_angle=Lift_ang"),
            "<log>:7:1: ControlDesk trace_names has 8 cells, the sample rows 9: its names cannot "
            "be matched to the columns");
}

TEST_F(ControlDeskLog, MalformedExpressionsNameTheSourceAndTheCharacter) {
  const auto spec_refusal = [](const std::string& command) -> std::string {
    try {
      ParseColumnsSpec("time=time,command=" + command + ",joint_angle=Lift_ang");
    } catch (const core::InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(spec_refusal("Lift_up_duty -"),
            "--columns: command: 'Lift_up_duty -' at character 15: expected a column name, $N or "
            "a number after '-'");
  EXPECT_EQ(spec_refusal("2*"),
            "--columns: command: '2*' at character 3: expected a column "
            "after '*'");
  EXPECT_EQ(spec_refusal("$0"),
            "--columns: command: '$0' at character 1: columns are numbered from 1, got $0");
  EXPECT_EQ(spec_refusal("-90"),
            "--columns: command: '-90' at character 1: no column in it (numbers alone are "
            "constants; name a column, or give its number as $N)");
  EXPECT_EQ(spec_refusal("Lift up - x"),
            "--columns: command: 'Lift up - x' at character 6: expected + or - before 'u' (a "
            "name with other characters than letters, digits, _ . / is quoted: 'like this')");
  EXPECT_EQ(spec_refusal("'Lift up - x"),
            "--columns: command: ''Lift up - x' at character 1: the quote ' is not closed");
  EXPECT_EQ(spec_refusal("Lift_ang*2"),
            "--columns: command: 'Lift_ang*2' at character 9: expected + or - before '*' (the "
            "factor comes first: 2*name)");

  // Checked against the log: an unknown name, a column beyond the rows, one column twice.
  const std::string path = Write(std::string(kHeader) + kSamples);
  EXPECT_EQ(Refusal(path, "time=time,command=Lift_up_duty - Lift_dn,joint_angle=Lift_ang"),
            "<log>:7:1: --columns: command: no column 'Lift_dn' (did you mean 'Lift_ang'?)");
  EXPECT_EQ(Refusal(path, "time=time,command=$99,joint_angle=Lift_ang"),
            "<log>:11:1: --columns: command: column 99 does not exist; the rows have 9 cells");
  EXPECT_EQ(Refusal(path, "time=time,command=Lift_up_duty - $5,joint_angle=Lift_ang"),
            "<log>:7:1: --columns: command: column 5 is read twice in 'Lift_up_duty - $5'; name "
            "each column once");
  // The marker cell is column 1: no number in it.
  EXPECT_EQ(Refusal(path, "time=1,command=Lift_up_duty,joint_angle=Lift_ang"),
            "<log>:11:1: time (column '1') is not a finite number: 'trace_values'");
}

// A command expression beyond full stroke is refused at the first column's cell, with its value.
TEST_F(ControlDeskLog, CommandExpressionOutOfRange) {
  std::string text = std::string(kHeader) + kSamples;
  text.replace(text.find(",0.03,13,23,100,0,"), 18, ",0.03,13,23,100,40,");
  EXPECT_EQ(
      Refusal(Write(text), "time=time,command=Lift_up_duty + Lift_dn_duty,joint_angle=Lift_ang"),
      "<log>:14:13: command 'Lift_up_duty + Lift_dn_duty' = 140 % is outside [-100, 100] %");
}

// Ordinary CSVs take expressions and quoted names too; a header name with an operator in it
// is still read as that column, and a name of two columns is refused.
TEST(ColumnExpressions, OrdinaryCsv) {
  const std::string path =
      ::testing::TempDir() + "/" + std::to_string(getpid()) + "_expressions.csv";
  std::ofstream(path) << "t,P-rod,cmd up,cmd dn,angle,angle\n"
                         "0,1,0.5,0,10,1\n"
                         "0.5,2,0,0.25,20,2\n";
  LogFormat format = ParseColumnsSpec(
      "time=t,pressure_b=P-rod,command=\"cmd up\" - 'cmd dn',joint_angle=$5 - 0.5*$6");
  const HydraulicLog log = ReadHydraulicLog(path, format, 2);
  EXPECT_EQ(log.pressure_b, (std::vector<double>{1, 2}));
  EXPECT_EQ(log.command, (std::vector<double>{0.5, -0.25}));
  EXPECT_EQ(log.joint_angle, (std::vector<double>{9.5, 19}));
  try {
    ReadHydraulicLog(path, ParseColumnsSpec("time=t,command='cmd up',joint_angle=angle"), 2);
    FAIL() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path +
                  ":1:1: --columns: joint_angle: 'angle' names columns 5, 6 (header line 1): "
                  "give the column by number (5)");
  }
  std::filesystem::remove(path);
}

TEST(ColumnExpressions, Grammar) {
  ColumnExpression e = ParseColumnExpression(" -Arm_ang + 90 ");
  EXPECT_EQ(e.text, "-Arm_ang + 90");
  ASSERT_EQ(e.terms.size(), 1u);
  EXPECT_EQ(e.terms[0].scale, -1);
  EXPECT_EQ(e.terms[0].column.name, "Arm_ang");
  EXPECT_EQ(e.offset, 90);
  EXPECT_FALSE(e.plain());

  e = ParseColumnExpression(".5*$3 - 2*-x.y/z - 1e-3 + 'a, b'");
  ASSERT_EQ(e.terms.size(), 3u);
  EXPECT_EQ(e.terms[0].scale, 0.5);
  EXPECT_TRUE(e.terms[0].column.by_number);
  EXPECT_EQ(e.terms[0].column.number, 3);
  EXPECT_EQ(e.terms[1].scale, 2);  // minus times minus
  EXPECT_EQ(e.terms[1].column.name, "x.y/z");
  EXPECT_EQ(e.terms[1].column.position, 12u);
  EXPECT_EQ(e.terms[2].column.name, "a, b");
  EXPECT_EQ(e.offset, -1e-3);

  // Back compatible: digits are a column number, a value without operators a name as written.
  e = ParseColumnExpression("12");
  EXPECT_TRUE(e.plain());
  EXPECT_TRUE(e.terms[0].column.by_number);
  EXPECT_EQ(e.terms[0].column.number, 12);
  e = ParseColumnExpression("Time (s)");
  EXPECT_TRUE(e.plain());
  EXPECT_EQ(e.terms[0].column.name, "Time (s)");
  EXPECT_THROW(ParseColumnExpression(""), ColumnExpressionError);
  EXPECT_THROW(ParseColumnExpression("1e999*x"), ColumnExpressionError);
  EXPECT_THROW(ParseColumnExpression("2x - y"), ColumnExpressionError);
  EXPECT_THROW(ParseColumnExpression("x + ''"), ColumnExpressionError);
  EXPECT_THROW(ParseColumnExpression("$"), ColumnExpressionError);
}

}  // namespace
}  // namespace autoshovel::identification
