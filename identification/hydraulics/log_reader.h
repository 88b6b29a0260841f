// Reading valve step and chirp logs for hydraulic identification.
//
// Real logs come from data loggers with their own headers, column names and units. A log is a
// delimited text file (comma, semicolon or tab): some header lines (free text, `#` comments,
// a row of column names, perhaps a row of units), then one row per sample; or a dSPACE
// ControlDesk CSV export (controldesk_header.h: `trace_names` and `path` rows name the columns,
// samples from the `trace_values` row on, each after a marker cell). What each column means is
// given by a column map from the command line (`--columns time=t_s,command=cmd_pct`) or a small
// YAML file (ReadLogFormatYaml). A quantity is read from one column, named by its header text
// (ControlDesk: its trace name, its path or the path's last part; the time column also `time`)
// or by its 1-based number in the file, or from an expression over columns such as
// `command=Boom_up_duty - Boom_dn_duty` or `joint_angle=-Boom_ang + 90` (column_expression.h).
// A name that answers for more than one column is refused, listing them. Without a map, the
// names written by `autoshovel plant step` are used:
//   t,command,spool,pressure,joint_angle,joint_rate   (SI units, command in [-1, 1])
//
// Quantities (keys of the map):
//   time            required, strictly increasing             s | ms
//   command         required, valve duty                      unit ([-1, 1]) | percent
//   joint_angle     required, the joint the actuator drives   rad | deg
//   spool           optional, valve spool feedback            unit | percent
//   pilot_pressure  optional, pilot pressure (plotted only)   Pa | bar | MPa
//   pressure_a      optional, cap-side cylinder pressure      Pa | bar | MPa
//   pressure_b      optional, rod-side cylinder pressure      Pa | bar | MPa
// Everything is converted to SI (and the command and spool to [-1, 1]) on reading; units apply
// to an expression's result. Any NaN, infinity, empty or non-numeric cell a quantity reads, a
// wrong number of cells, a repeated or decreasing time and a command outside its range is refused
// as `file:row:column: message` (core::InputError, the row being the 1-based line of the file,
// the column the 1-based character where the cell starts): nothing non-finite ever reaches the
// solver.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace autoshovel::identification {

enum class CommandUnits { kUnit, kPercent };
enum class AngleUnits { kRadians, kDegrees };
enum class PressureUnits { kPascal, kBar, kMegapascal };
enum class TimeUnits { kSeconds, kMilliseconds };

/// How to read one log.
struct LogFormat {
  /// Quantity key → column name, 1-based column number or expression over columns
  /// (column_expression.h). Empty: the plant-step names.
  std::map<std::string, std::string> columns;
  CommandUnits command_units = CommandUnits::kUnit;
  CommandUnits spool_units = CommandUnits::kUnit;
  AngleUnits angle_units = AngleUnits::kRadians;
  PressureUnits pressure_units = PressureUnits::kPascal;
  TimeUnits time_units = TimeUnits::kSeconds;
  /// Lines before the first sample row; -1: detected (the first row whose cells are all numbers).
  int header_lines = -1;
  /// Actuator (name or joint) the log excites; empty: from the log's `# ... actuator NAME` line.
  std::string actuator;
  /// Where the format came from, for messages ("--columns", a YAML file); empty: defaults.
  std::string source;
  /// Where each entry of `columns` came from ("--columns", "--column-map FILE", a sibling
  /// `.columns.yaml`): an explicit map is checked against the log and its errors name it.
  std::map<std::string, std::string> column_sources;
};

/// The quantity keys, in the order above.
const std::vector<std::string>& LogQuantityKeys();

/// Parses `time=t_s,command=cmd_pct,...` into `format.columns` (other fields kept); a value may
/// be an expression (`command=Boom_up_duty - Boom_dn_duty`; a comma inside quotes does not end
/// it). Throws core::InputError naming `--columns` on an unknown key, a malformed pair or
/// expression (with the character where it goes wrong), a quantity given twice, or a spec with
/// no pair at all.
LogFormat ParseColumnsSpec(const std::string& spec, LogFormat format = {});

/// Reads a column-map YAML file:
///   columns: {time: t_s, command: cmd_pct, spool: spool_pct, joint_angle: -boom_deg + 90}
///   units: {time: s, command: percent, spool: percent, angle: deg, pressure: bar}  # optional
///   header_lines: 3                                                                 # optional
///   actuator: boom_cylinders                                                        # optional
/// Errors (a malformed expression too) are located `file:line:column: key: message`
/// (core::InputError).
LogFormat ReadLogFormatYaml(const std::string& path);

/// Parses a unit name as given on the command line or in YAML; throws std::invalid_argument
/// with the accepted names otherwise.
CommandUnits ParseCommandUnits(const std::string& name);
AngleUnits ParseAngleUnits(const std::string& name);
PressureUnits ParsePressureUnits(const std::string& name);
TimeUnits ParseTimeUnits(const std::string& name);

/// One log in SI units. Optional channels are empty when the log has no such column.
struct HydraulicLog {
  std::string file;
  std::string actuator;                ///< from the format, else the log's header comment, else ""
  std::vector<int> row;                ///< 1-based line of the file of each sample
  std::vector<double> time;            ///< [s], strictly increasing
  std::vector<double> command;         ///< [-1, 1]
  std::vector<double> joint_angle;     ///< [rad]
  std::vector<double> spool;           ///< [-1, 1]
  std::vector<double> pilot_pressure;  ///< [Pa]
  std::vector<double> pressure_a;      ///< [Pa]
  std::vector<double> pressure_b;      ///< [Pa]
  /// What each quantity read was computed from, for messages: quantity → the value of the
  /// column map as given (`Boom_up_duty - Boom_dn_duty`, `2`, the default name) and the 1-based
  /// columns of the file it read, in the order of the expression's terms.
  struct Source {
    std::string expression;
    std::vector<int> columns;
  };
  std::map<std::string, Source> sources;

  std::size_t size() const { return time.size(); }
  bool has_spool() const { return !spool.empty(); }
};

/// Reads and checks one log. Throws core::InputError (`file:row: message`) on bad input, and
/// when the log has fewer than `min_samples` rows. An explicit column map is checked against
/// the log: a name not in the header, a name that answers for several columns, a number beyond
/// the row's cells, one column read twice in an expression and one column read as two
/// quantities (each read from that column alone) are refused, naming where the map came from
/// (`--columns: ...`).
HydraulicLog ReadHydraulicLog(const std::string& path, const LogFormat& format,
                              std::size_t min_samples = 20);

/// Throws core::InputError `file:row:1: message` at the row of `sample` (the last row if past it).
[[noreturn]] void FailAtSample(const HydraulicLog& log, std::size_t sample,
                               const std::string& message);

/// Refuses a log whose command never leaves ±1 % (core::InputError at its first row): neither
/// model can learn anything from it.
void RequireExcitation(const HydraulicLog& log);

}  // namespace autoshovel::identification
