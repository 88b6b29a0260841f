// Reading valve step and chirp logs for hydraulic identification.
//
// Real logs come from data loggers with their own headers, column names and units. A log is a
// delimited text file (comma, semicolon or tab): some header lines (free text, `#` comments,
// a row of column names, perhaps a row of units), then one row per sample. What each column
// means is given by a column map from the command line (`--columns time=t_s,command=cmd_pct`)
// or a small YAML file (ReadLogFormatYaml); a column is named by its header text or by its
// 1-based position. Without a map, the names written by `autoshovel plant step` are used:
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
// Everything is converted to SI (and the command and spool to [-1, 1]) on reading. Any NaN,
// infinity, empty or non-numeric cell, a wrong number of cells, a repeated or decreasing time
// and a command outside its range is refused as `file:row: message` (core::InputError, the row
// being the 1-based line of the file): nothing non-finite ever reaches the solver.
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
  /// Quantity key → column header text or 1-based column number. Empty: the plant-step names.
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

/// Parses `time=t_s,command=cmd_pct,...` into `format.columns` (other fields kept). Throws
/// core::InputError naming `--columns` on an unknown key, a malformed pair, a quantity given
/// twice, or a spec with no pair at all.
LogFormat ParseColumnsSpec(const std::string& spec, LogFormat format = {});

/// Reads a column-map YAML file:
///   columns: {time: t_s, command: cmd_pct, spool: spool_pct, joint_angle: boom_deg}
///   units: {time: s, command: percent, spool: percent, angle: deg, pressure: bar}  # optional
///   header_lines: 3                                                                 # optional
///   actuator: boom_cylinders                                                        # optional
/// Errors are located `file:line:column: key: message` (core::InputError).
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

  std::size_t size() const { return time.size(); }
  bool has_spool() const { return !spool.empty(); }
};

/// Reads and checks one log. Throws core::InputError (`file:row: message`) on bad input, and
/// when the log has fewer than `min_samples` rows. An explicit column map is checked against
/// the log: a name not in the header, a number beyond the row's cells and one column read as
/// two quantities are refused, naming where the map came from (`--columns: ...`).
HydraulicLog ReadHydraulicLog(const std::string& path, const LogFormat& format,
                              std::size_t min_samples = 20);

}  // namespace autoshovel::identification
