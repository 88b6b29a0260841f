#include "identification/hydraulics/log_reader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "runtime/core/diagnostics.h"
#include "runtime/core/input_file.h"
#include "runtime/core/strings.h"
#include "runtime/core/yaml_reader.h"

namespace autoshovel::identification {

namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void Fail(const std::string& file, int line, int column, const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add({file, line, column}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n\"'");
  if (begin == std::string::npos) return "";
  const auto end = text.find_last_not_of(" \t\r\n\"'");
  return text.substr(begin, end - begin + 1);
}

struct Cell {
  std::string text;
  int column = 1;  ///< 1-based character column of the cell's start
};

std::vector<Cell> Split(const std::string& line, char delimiter) {
  std::vector<Cell> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(delimiter, start);
    const std::string raw = line.substr(start, end == std::string::npos ? end : end - start);
    cells.push_back({Trim(raw), static_cast<int>(start) + 1});
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return cells;
}

// A finite number spelled in full, or nothing ("nan", "inf", "", "1.2x" are not numbers here).
std::optional<double> ParseFinite(const std::string& text) {
  if (text.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

bool AllNumbers(const std::vector<Cell>& cells) {
  return std::all_of(cells.begin(), cells.end(),
                     [](const Cell& c) { return ParseFinite(c.text).has_value(); });
}

// A sample row: its first cell parses as a number (the rest is checked cell by cell later, so a
// NaN in a data row is reported as such rather than taken for a header line).
bool LooksLikeData(const std::vector<Cell>& cells) {
  return cells.size() > 1 && ParseFinite(cells.front().text).has_value();
}

char DetectDelimiter(const std::string& line) {
  const std::size_t commas = std::count(line.begin(), line.end(), ',');
  const std::size_t semicolons = std::count(line.begin(), line.end(), ';');
  const std::size_t tabs = std::count(line.begin(), line.end(), '\t');
  if (tabs > commas && tabs > semicolons) return '\t';
  if (semicolons > commas) return ';';
  return ',';
}

const std::map<std::string, std::vector<std::string>>& DefaultNames() {
  static const std::map<std::string, std::vector<std::string>> names = {
      {"time", {"t", "time"}},
      {"command", {"command"}},
      {"joint_angle", {"joint_angle"}},
      {"spool", {"spool"}},
      {"pilot_pressure", {"pilot_pressure"}},
      {"pressure_a", {"pressure_a", "pressure"}},
      {"pressure_b", {"pressure_b"}},
  };
  return names;
}

bool IsRequired(const std::string& key) {
  return key == "time" || key == "command" || key == "joint_angle";
}

void CheckKey(const std::string& key, const std::string& where) {
  const auto& keys = LogQuantityKeys();
  if (std::find(keys.begin(), keys.end(), key) != keys.end()) return;
  std::string message = "unknown quantity '" + key + "'";
  const std::string near = core::NearestWord(key, keys);
  if (!near.empty()) message += " (did you mean '" + near + "'?)";
  message += "; known: time, command, joint_angle, spool, pilot_pressure, pressure_a, pressure_b";
  Fail(where, 0, 0, message);
}

bool IsColumnNumber(const std::string& text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string UnitSuffix(const std::string& key, const LogFormat& f) {
  if (key == "time") return f.time_units == TimeUnits::kSeconds ? " s" : " ms";
  if (key == "command" || key == "spool") {
    const CommandUnits u = key == "command" ? f.command_units : f.spool_units;
    return u == CommandUnits::kPercent ? " %" : "";
  }
  if (key == "joint_angle") return f.angle_units == AngleUnits::kDegrees ? " deg" : " rad";
  switch (f.pressure_units) {
    case PressureUnits::kPascal:
      return " Pa";
    case PressureUnits::kBar:
      return " bar";
    case PressureUnits::kMegapascal:
      return " MPa";
  }
  return "";
}

double ToSi(const std::string& key, double value, const LogFormat& f) {
  if (key == "time") return f.time_units == TimeUnits::kMilliseconds ? value * 1e-3 : value;
  if (key == "command") return f.command_units == CommandUnits::kPercent ? value / 100 : value;
  if (key == "spool") return f.spool_units == CommandUnits::kPercent ? value / 100 : value;
  if (key == "joint_angle")
    return f.angle_units == AngleUnits::kDegrees ? value * kPi / 180 : value;
  switch (f.pressure_units) {
    case PressureUnits::kPascal:
      return value;
    case PressureUnits::kBar:
      return value * 1e5;
    case PressureUnits::kMegapascal:
      return value * 1e6;
  }
  return value;
}

std::vector<double>* Channel(HydraulicLog& log, const std::string& key) {
  if (key == "time") return &log.time;
  if (key == "command") return &log.command;
  if (key == "joint_angle") return &log.joint_angle;
  if (key == "spool") return &log.spool;
  if (key == "pilot_pressure") return &log.pilot_pressure;
  if (key == "pressure_a") return &log.pressure_a;
  return &log.pressure_b;
}

// `# autoshovel plant step: machine m, actuator boom, ...` names the actuator.
std::string ActuatorFromComment(const std::string& line) {
  const std::string tag = "actuator ";
  const std::size_t at = line.find(tag);
  if (line.empty() || line[0] != '#' || at == std::string::npos) return "";
  std::size_t end = line.find_first_of(", \t\r", at + tag.size());
  return line.substr(at + tag.size(),
                     end == std::string::npos ? std::string::npos : end - at - tag.size());
}

// One column read as two quantities (`command=Time` with time in Time too) would fit a model
// to nonsense without a word: refused, naming both quantities and the column.
template <typename Origin>
void CheckDistinctColumns(const std::string& path, const std::map<std::string, int>& column_of,
                          const std::vector<std::string>& header_names, const Origin& origin,
                          int line) {
  std::map<int, std::string> quantity_of;  // cell index → the first quantity reading it
  for (const auto& [key, c] : column_of) {
    const auto [it, inserted] = quantity_of.emplace(c, key);
    if (inserted) continue;
    const std::string column =
        std::to_string(c + 1) +
        (c < static_cast<int>(header_names.size()) ? " ('" + header_names[c] + "')" : "");
    Fail(path, line, 1,
         origin(key) + it->second + " and " + key + " both read column " + column +
             "; each quantity needs its own column");
  }
}

}  // namespace

const std::vector<std::string>& LogQuantityKeys() {
  static const std::vector<std::string> keys = {
      "time", "command", "joint_angle", "spool", "pilot_pressure", "pressure_a", "pressure_b"};
  return keys;
}

CommandUnits ParseCommandUnits(const std::string& name) {
  if (name == "unit") return CommandUnits::kUnit;
  if (name == "percent") return CommandUnits::kPercent;
  throw std::invalid_argument("command units must be one of unit | percent, got '" + name + "'");
}

AngleUnits ParseAngleUnits(const std::string& name) {
  if (name == "rad") return AngleUnits::kRadians;
  if (name == "deg") return AngleUnits::kDegrees;
  throw std::invalid_argument("angle units must be one of rad | deg, got '" + name + "'");
}

PressureUnits ParsePressureUnits(const std::string& name) {
  if (name == "Pa" || name == "pa") return PressureUnits::kPascal;
  if (name == "bar") return PressureUnits::kBar;
  if (name == "MPa" || name == "mpa") return PressureUnits::kMegapascal;
  throw std::invalid_argument("pressure units must be one of Pa | bar | MPa, got '" + name + "'");
}

TimeUnits ParseTimeUnits(const std::string& name) {
  if (name == "s") return TimeUnits::kSeconds;
  if (name == "ms") return TimeUnits::kMilliseconds;
  throw std::invalid_argument("time units must be one of s | ms, got '" + name + "'");
}

LogFormat ParseColumnsSpec(const std::string& spec, LogFormat format) {
  format.source = "--columns";
  std::stringstream stream(spec);
  std::string pair;
  std::map<std::string, std::string> given;  // in this spec (a --column-map may come before)
  while (std::getline(stream, pair, ',')) {
    pair = Trim(pair);
    if (pair.empty()) continue;
    const std::size_t eq = pair.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == pair.size()) {
      Fail("--columns", 0, 0, "expected quantity=column, got '" + pair + "'");
    }
    const std::string key = Trim(pair.substr(0, eq));
    const std::string column = Trim(pair.substr(eq + 1));
    CheckKey(key, "--columns");
    // The last of two would silently win: the user meant one of them.
    if (given.count(key)) {
      Fail("--columns", 0, 0,
           key + " is given twice ('" + given[key] + "' and '" + column + "'); give it once");
    }
    given[key] = column;
    format.columns[key] = column;
    format.column_sources[key] = "--columns";
  }
  if (given.empty()) Fail("--columns", 0, 0, "no quantity=column pair in '" + spec + "'");
  return format;
}

LogFormat ReadLogFormatYaml(const std::string& path) {
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  LogFormat format;
  format.source = path;
  if (file.ok()) {
    core::MapReader root = core::MapReader::Root(file, nullptr);
    core::MapReader columns = root.Map("columns");
    for (const std::string& key : LogQuantityKeys()) {
      if (IsRequired(key) || columns.Has(key)) {
        format.columns[key] = columns.String(key);
        format.column_sources[key] = path;
      }
    }
    columns.Finish();
    if (auto units = root.OptionalMap("units")) {
      auto read = [&](const char* key, const std::vector<std::string>& options, auto parse,
                      auto& target) {
        if (!units->Has(key)) return;
        const std::string value = units->Enum(key, options);
        if (!value.empty()) target = parse(value);
      };
      read("time", {"s", "ms"}, ParseTimeUnits, format.time_units);
      read("command", {"unit", "percent"}, ParseCommandUnits, format.command_units);
      format.spool_units = format.command_units;
      read("spool", {"unit", "percent"}, ParseCommandUnits, format.spool_units);
      read("angle", {"rad", "deg"}, ParseAngleUnits, format.angle_units);
      read("pressure", {"Pa", "bar", "MPa"}, ParsePressureUnits, format.pressure_units);
      units->Finish();
    }
    if (root.Has("header_lines")) format.header_lines = root.Integer("header_lines", 0, 100000);
    if (auto actuator = root.OptionalString("actuator")) format.actuator = *actuator;
    root.Finish();
  }
  sink.ThrowIfAny();
  return format;
}

HydraulicLog ReadHydraulicLog(const std::string& path, const LogFormat& format,
                              std::size_t min_samples) {
  // Checked before opening: a named pipe would block the open, a folder would read as empty.
  if (const std::string why = core::NotARegularFile(path); !why.empty()) {
    Fail(path, 0, 0, "cannot open the log: " + why);
  }
  std::ifstream in(path);
  if (!in) Fail(path, 0, 0, "cannot open the log");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }

  HydraulicLog log;
  log.file = path;
  log.actuator = format.actuator;

  // Where the samples start.
  std::size_t first_data = lines.size();
  if (format.header_lines >= 0) {
    first_data = static_cast<std::size_t>(format.header_lines);
  } else {
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (Trim(lines[i]).empty() || lines[i][0] == '#') continue;
      if (LooksLikeData(Split(lines[i], DetectDelimiter(lines[i])))) {
        first_data = i;
        break;
      }
    }
  }
  if (first_data >= lines.size()) {
    Fail(path, 0, 0,
         "no sample rows (rows whose cells are all numbers) after " + std::to_string(lines.size()) +
             " lines");
  }
  const char delimiter = DetectDelimiter(lines[first_data]);
  const std::size_t num_cells = Split(lines[first_data], delimiter).size();
  for (std::size_t i = 0; i < first_data && log.actuator.empty(); ++i) {
    log.actuator = ActuatorFromComment(lines[i]);
  }

  // Columns: by number, or by name in the header line that names them all.
  std::map<std::string, std::string> wanted = format.columns;
  const bool defaults = wanted.empty();
  std::map<std::string, int> column_of;  // key → 0-based cell index
  // "--columns: " before a problem with an entry of an explicit map: the user sees which of
  // their options (or which sibling file) to correct.
  const auto origin = [&](const std::string& key) {
    const auto it = format.column_sources.find(key);
    const std::string& source = it != format.column_sources.end() ? it->second : format.source;
    return source.empty() ? std::string() : source + ": ";
  };
  for (const auto& [key, name] : wanted) {
    CheckKey(key, format.source.empty() ? path : format.source);
    if (IsColumnNumber(name)) {
      // Digits only, so the one failure left is overflow: a number that large is out of range.
      const long number = name.size() > 9 ? 0 : std::stol(name);
      if (number < 1 || number > static_cast<long>(num_cells)) {
        Fail(path, static_cast<int>(first_data) + 1, 1,
             origin(key) + key + ": column " + name + " does not exist; the rows have " +
                 std::to_string(num_cells) + " cells");
      }
      column_of[key] = static_cast<int>(number) - 1;
    }
  }
  // The header line: the last line before the data that has as many cells as a data row and
  // is not a comment (data loggers may put a units row after it: that one has no known names).
  int header_line = -1;
  std::vector<Cell> header;
  for (int i = static_cast<int>(first_data) - 1; i >= 0; --i) {
    if (Trim(lines[i]).empty() || lines[i][0] == '#') continue;
    std::vector<Cell> cells = Split(lines[i], delimiter);
    if (cells.size() != num_cells || AllNumbers(cells)) continue;
    bool names_any = false;
    for (const Cell& cell : cells) {
      for (const auto& [key, name] : wanted) names_any |= cell.text == name;
      if (defaults) {
        for (const auto& [key, names] : DefaultNames()) {
          names_any |= std::find(names.begin(), names.end(), cell.text) != names.end();
        }
      }
    }
    if (names_any || header_line < 0) {
      header_line = i;
      header = std::move(cells);
      if (names_any) break;
    }
  }
  auto find_cell = [&](const std::string& name) {
    for (std::size_t c = 0; c < header.size(); ++c) {
      if (header[c].text == name) return static_cast<int>(c);
    }
    return -1;
  };
  std::vector<std::string> header_names;
  for (const Cell& cell : header) header_names.push_back(cell.text);
  if (defaults) {
    for (const auto& [key, names] : DefaultNames()) {
      for (const std::string& name : names) {
        const int c = find_cell(name);
        if (c >= 0 && !column_of.count(key)) column_of[key] = c, wanted[key] = name;
      }
    }
  } else {
    for (const auto& [key, name] : wanted) {
      if (column_of.count(key)) continue;
      const int c = find_cell(name);
      if (c < 0) {
        std::string message = origin(key) + key + ": no column '" + name + "'";
        if (header_line < 0) {
          message += " (no header line found before the first sample row)";
          Fail(path, static_cast<int>(first_data) + 1, 1, message);
        }
        const std::string near = core::NearestWord(name, header_names);
        if (!near.empty()) message += " (did you mean '" + near + "'?)";
        Fail(path, header_line + 1, 1, message);
      }
      column_of[key] = c;
    }
  }
  CheckDistinctColumns(path, column_of, header_names, origin,
                       header_line >= 0 ? header_line + 1 : static_cast<int>(first_data) + 1);
  for (const char* key : {"time", "command", "joint_angle"}) {
    if (column_of.count(key)) continue;
    const int line = header_line >= 0 ? header_line + 1 : static_cast<int>(first_data) + 1;
    Fail(path, line, 1,
         std::string("missing column for ") + key +
             (defaults ? " (expected one named " + DefaultNames().at(key).back() +
                             "; give a column map with --columns or --column-map)"
                       : " (add it to the column map)"));
  }

  // Samples.
  for (std::size_t i = first_data; i < lines.size(); ++i) {
    if (Trim(lines[i]).empty() || lines[i][0] == '#') continue;
    const int line = static_cast<int>(i) + 1;
    const std::vector<Cell> cells = Split(lines[i], delimiter);
    if (cells.size() != num_cells) {
      Fail(path, line, 1,
           std::to_string(cells.size()) + " cells, expected " + std::to_string(num_cells) +
               " like the first sample row");
    }
    for (const auto& [key, c] : column_of) {
      const Cell& cell = cells[c];
      const std::optional<double> value = ParseFinite(cell.text);
      if (!value) {
        Fail(path, line, cell.column,
             key + " (column '" + wanted[key] + "') is not a finite number: '" + cell.text + "'");
      }
      const double si = ToSi(key, *value, format);
      // Spool feedback may overshoot full stroke a little (sensor noise, overtravel).
      const double limit = key == "command" ? 1.0 + 1e-9 : 1.2;
      if ((key == "command" || key == "spool") && std::abs(si) > limit) {
        const bool percent = (key == "command" ? format.command_units : format.spool_units) ==
                             CommandUnits::kPercent;
        Fail(path, line, cell.column,
             key + " " + cell.text + UnitSuffix(key, format) + " is outside " +
                 (key == "spool" ? (percent ? "[-120, 120] %" : "[-1.2, 1.2]")
                                 : (percent ? "[-100, 100] %" : "[-1, 1]")) +
                 (percent ? "" : " (is it in percent? use --" + key + "-units percent)"));
      }
      Channel(log, key)->push_back(si);
    }
    const std::size_t n = log.time.size();
    if (n >= 2 && !(log.time[n - 1] > log.time[n - 2])) {
      const Cell& cell = cells[column_of["time"]];
      Fail(path, line, cell.column,
           log.time[n - 1] == log.time[n - 2]
               ? "time " + cell.text + UnitSuffix("time", format) +
                     " repeats the previous sample's (duplicate timestamp)"
               : "time " + cell.text + UnitSuffix("time", format) +
                     " is before the previous sample's " +
                     core::FormatNumber(
                         log.time[n - 2] /
                         (format.time_units == TimeUnits::kMilliseconds ? 1e-3 : 1.0)) +
                     UnitSuffix("time", format) + " (time must increase)");
    }
    log.row.push_back(line);
  }
  if (log.size() < min_samples) {
    Fail(path, log.row.empty() ? static_cast<int>(lines.size()) : log.row.back(), 1,
         "only " + std::to_string(log.size()) + " sample rows; at least " +
             std::to_string(min_samples) + " are needed");
  }
  return log;
}

}  // namespace autoshovel::identification
