#include "identification/hydraulics/log_reader.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "identification/hydraulics/column_expression.h"
#include "identification/hydraulics/column_names.h"
#include "identification/hydraulics/controldesk_header.h"
#include "identification/hydraulics/delimited_text.h"
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

// Blanks and quotes trimmed (a spec's key, a pair).
std::string Trim(const std::string& text) { return TrimCell(text); }

// Blanks trimmed, quotes kept: they quote a name in an expression.
std::string TrimBlanks(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

bool AllNumbers(const std::vector<Cell>& cells) {
  return std::all_of(cells.begin(), cells.end(),
                     [](const Cell& c) { return ParseFinite(c.text).has_value(); });
}

// `--columns` pairs: split at commas outside quotes (a quoted name may hold one). With a quote
// left open, at every comma: the pair with the open quote is then refused on its own.
std::vector<std::string> SplitPairs(const std::string& spec) {
  for (const bool by_quotes : {true, false}) {
    std::vector<std::string> pairs(1);
    char quote = 0;
    for (const char c : spec) {
      if (quote != 0) {
        if (c == quote) quote = 0;
      } else if (by_quotes && (c == '\'' || c == '"')) {
        quote = c;
      } else if (c == ',') {
        pairs.emplace_back();
        continue;
      }
      pairs.back() += c;
    }
    if (quote == 0) return pairs;
  }
  return {};  // unreachable: without quotes nothing is left open
}

// "command: 'Boom_up_duty -' at character 15: expected ..." for a malformed value.
std::string ExpressionProblem(const std::string& key, const std::string& value,
                              const ColumnExpressionError& e) {
  return (key.empty() ? "" : key + ": ") + "'" + TrimBlanks(value) + "' at character " +
         std::to_string(e.position) + ": " + e.what();
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
  std::map<std::string, std::string> given;  // in this spec (a --column-map may come before)
  for (std::string pair : SplitPairs(spec)) {
    pair = TrimBlanks(pair);
    if (pair.empty()) continue;
    const std::size_t eq = pair.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == pair.size()) {
      Fail("--columns", 0, 0, "expected quantity=column, got '" + pair + "'");
    }
    const std::string key = Trim(pair.substr(0, eq));
    const std::string column = TrimBlanks(pair.substr(eq + 1));
    CheckKey(key, "--columns");
    try {
      ParseColumnExpression(column);
    } catch (const ColumnExpressionError& e) {
      Fail("--columns", 0, 0, ExpressionProblem(key, column, e));
    }
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
        if (!columns.Has(key)) continue;
        try {
          ParseColumnExpression(format.columns[key]);
        } catch (const ColumnExpressionError& e) {
          columns.Error(key, ExpressionProblem("", format.columns[key], e));
        }
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

namespace {

// One quantity as the reader reads it: its expression, and the 0-based cell of each term.
struct Quantity {
  std::string key;
  ColumnExpression expression;
  std::vector<int> cells;
  std::vector<double>* channel = nullptr;
};

// Columns by number, or by name in the names the log gives its columns; checked against the
// log with messages naming where the map came from.
class ColumnResolver {
 public:
  ColumnResolver(const std::string& path, const ColumnNames& names, std::size_t num_cells,
                 int names_line, int first_data_line, std::string no_names_note)
      : path_(path),
        names_(names),
        num_cells_(num_cells),
        names_line_(names_line),
        first_data_line_(first_data_line),
        no_names_note_(std::move(no_names_note)) {}

  // The cells of `expression`'s terms, in order. `origin` ("--columns: command: ") prefixes
  // every message.
  std::vector<int> Resolve(ColumnExpression& expression, const std::string& origin) const {
    // A header such as `P-rod` reads as an expression (P minus rod): the whole value naming a
    // column wins.
    if (!expression.plain()) {
      if (names_.Find(expression.text).size() == 1) {
        ColumnReference whole;
        whole.name = whole.text = expression.text;
        whole.position = 1;
        expression.terms = {{1, whole}};
        expression.offset = 0;
      }
    }
    std::vector<int> cells;
    for (const ColumnTerm& term : expression.terms) {
      const int cell = Cell(term.column, origin, !expression.plain());
      if (std::find(cells.begin(), cells.end(), cell) != cells.end()) {
        Fail(path_, Line(), 1,
             origin + "column " + std::to_string(cell + 1) + " is read twice in '" +
                 expression.text + "'; name each column once");
      }
      cells.push_back(cell);
    }
    return cells;
  }

  // The one cell answering to `name`, -1 if none; refuses a name of several columns.
  int FindUnique(const std::string& name, const std::string& origin, bool in_expression) const {
    const std::vector<int> cells = names_.Find(name);
    if (cells.size() > 1) {
      std::string message = origin + "'" + name + "' names columns " + ColumnRanges(cells) + " (" +
                            names_.RowsNaming(name, cells) + "): give the column by number (" +
                            (in_expression ? "$" : "") + std::to_string(cells.front() + 1);
      const auto [unique, row] = names_.UniqueName(cells.front());
      message += ")";
      if (!unique.empty()) {
        message += std::string(" or by ") +
                   (row.find("path") != std::string::npos ? "its path name" : "another name") +
                   " (e.g. '" + unique + "')";
      }
      Fail(path_, Line(), 1, message);
    }
    return cells.empty() ? -1 : cells.front();
  }

  int Line() const { return names_line_ >= 0 ? names_line_ + 1 : first_data_line_; }

 private:
  int Cell(const ColumnReference& column, const std::string& origin, bool in_expression) const {
    if (column.by_number) {
      if (column.number < 1 || column.number > static_cast<long>(num_cells_)) {
        Fail(path_, first_data_line_, 1,
             origin + "column " + (column.text[0] == '$' ? column.text.substr(1) : column.text) +
                 " does not exist; the rows have " + std::to_string(num_cells_) + " cells");
      }
      return static_cast<int>(column.number) - 1;
    }
    const int cell = FindUnique(column.name, origin, in_expression);
    if (cell >= 0) return cell;
    std::string message = origin + "no column '" + column.name + "'";
    if (names_line_ < 0) Fail(path_, Line(), 1, message + " (" + no_names_note_ + ")");
    const std::string near = core::NearestWord(column.name, names_.All());
    if (!near.empty()) message += " (did you mean '" + near + "'?)";
    Fail(path_, Line(), 1, message);
  }

  const std::string& path_;
  const ColumnNames& names_;
  std::size_t num_cells_;
  int names_line_;       // 0-based line of the names, -1: none
  int first_data_line_;  // 1-based
  std::string no_names_note_;
};

// The header row of an ordinary log: the last line before the data that has as many cells as a
// data row and is not a comment (data loggers may put a units row after it: that one has no
// known names). -1 when there is none.
int FindHeaderRow(const std::vector<std::string>& lines, std::size_t first_data, char delimiter,
                  std::size_t num_cells, const std::vector<std::string>& known_names,
                  std::vector<Cell>& header) {
  int header_line = -1;
  for (int i = static_cast<int>(first_data) - 1; i >= 0; --i) {
    if (TrimCell(lines[i]).empty() || lines[i][0] == '#') continue;
    std::vector<Cell> cells = SplitCells(lines[i], delimiter);
    if (cells.size() != num_cells || AllNumbers(cells)) continue;
    const bool names_any = std::any_of(cells.begin(), cells.end(), [&](const Cell& cell) {
      return std::find(known_names.begin(), known_names.end(), cell.text) != known_names.end();
    });
    if (names_any || header_line < 0) {
      header_line = i;
      header = std::move(cells);
      if (names_any) break;
    }
  }
  return header_line;
}

// "command 150 %" or, for an expression, "command 'a - b' = 150 %".
std::string Describe(const Quantity& q, const std::string& cell_text, double value,
                     const LogFormat& format) {
  if (q.expression.plain()) return q.key + " " + cell_text + UnitSuffix(q.key, format);
  return q.key + " '" + q.expression.text + "' = " + core::FormatNumber(value) +
         UnitSuffix(q.key, format);
}

}  // namespace

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
  const LogLayout layout = FindLogLayout(lines, format.header_lines);
  const std::size_t first_data = layout.first_data;
  if (first_data >= lines.size()) {
    if (layout.names_line >= 0 && format.header_lines < 0) {
      Fail(path, layout.names_line + 1, 1,
           "ControlDesk export: a trace_names row but no trace_values row after it (no samples)");
    }
    Fail(path, 0, 0,
         "no sample rows (rows whose cells are all numbers) after " + std::to_string(lines.size()) +
             " lines");
  }
  const int first_data_line = static_cast<int>(first_data) + 1;
  const char delimiter = DetectDelimiter(lines[first_data]);
  const std::size_t num_cells = SplitCells(lines[first_data], delimiter).size();
  for (std::size_t i = 0; i < first_data && log.actuator.empty(); ++i) {
    log.actuator = ActuatorFromComment(lines[i]);
  }

  // The map: explicit, or the plant-step names.
  const bool defaults = format.columns.empty();
  // "--columns: " before a problem with an entry of an explicit map: the user sees which of
  // their options (or which sibling file) to correct.
  const auto origin = [&](const std::string& key) {
    const auto it = format.column_sources.find(key);
    const std::string& source = it != format.column_sources.end() ? it->second : format.source;
    return source.empty() ? std::string() : source + ": ";
  };
  std::vector<Quantity> quantities;
  std::vector<std::string> referenced;  // every name the map uses, to recognise the header row
  for (const auto& [key, value] : format.columns) {
    CheckKey(key, format.source.empty() ? path : format.source);
    Quantity q{key, {}, {}, nullptr};
    try {
      q.expression = ParseColumnExpression(value);
    } catch (const ColumnExpressionError& e) {
      Fail(path, 0, 0, origin(key) + ExpressionProblem(key, value, e));
    }
    referenced.push_back(q.expression.text);
    for (const ColumnTerm& term : q.expression.terms) {
      if (!term.column.by_number) referenced.push_back(term.column.name);
    }
    quantities.push_back(std::move(q));
  }
  if (defaults) {
    for (const auto& [key, names] : DefaultNames()) {
      referenced.insert(referenced.end(), names.begin(), names.end());
    }
  }

  // The names of the columns.
  ColumnNames names;
  int names_line = -1;
  std::string no_names_note = "no header line found before the first sample row";
  if (layout.controldesk) {
    names = ControlDeskNames(path, lines, layout, delimiter, num_cells);
    names_line = layout.names_line;
    no_names_note = "no trace_names row before the trace_values row";
  } else {
    std::vector<Cell> header;
    names_line = FindHeaderRow(lines, first_data, delimiter, num_cells, referenced, header);
    for (std::size_t c = 0; c < header.size(); ++c) {
      names.Add(static_cast<int>(c), header[c].text,
                "header line " + std::to_string(names_line + 1));
    }
  }
  const ColumnResolver resolver(path, names, num_cells, names_line, first_data_line, no_names_note);

  if (defaults) {
    for (const auto& [key, candidates] : DefaultNames()) {
      for (const std::string& name : candidates) {
        const int cell = resolver.FindUnique(name, key + ": ", false);
        if (cell < 0) continue;
        ColumnReference reference;
        reference.name = reference.text = name;
        reference.position = 1;
        quantities.push_back({key, {name, {{1, reference}}, 0}, {cell}, nullptr});
        break;
      }
    }
  } else {
    for (Quantity& q : quantities) {
      q.cells = resolver.Resolve(q.expression, origin(q.key) + q.key + ": ");
    }
  }
  // One column read as two quantities (`command=Time` with time in Time too) would fit a model
  // to nonsense without a word: refused, naming both quantities and the column. Expressions of
  // several columns may share one (`joint_angle=Arm_ang - Boom_ang` beside another quantity).
  std::map<int, std::string> quantity_of;  // cell → the first quantity reading it alone
  for (const Quantity& q : quantities) {
    if (q.cells.size() != 1) continue;
    const auto [it, inserted] = quantity_of.emplace(q.cells[0], q.key);
    if (inserted) continue;
    const std::string name = names.FirstName(q.cells[0]);
    Fail(path, resolver.Line(), 1,
         origin(q.key) + it->second + " and " + q.key + " both read column " +
             std::to_string(q.cells[0] + 1) + (name.empty() ? "" : " ('" + name + "')") +
             "; each quantity needs its own column");
  }
  for (const char* key : {"time", "command", "joint_angle"}) {
    if (std::any_of(quantities.begin(), quantities.end(),
                    [&](const Quantity& q) { return q.key == key; })) {
      continue;
    }
    Fail(path, resolver.Line(), 1,
         std::string("missing column for ") + key +
             (defaults ? " (expected one named " + DefaultNames().at(key).back() +
                             "; give a column map with --columns or --column-map)"
                       : " (add it to the column map)"));
  }
  const auto by_key = [&](const std::string& key) -> const Quantity& {
    return *std::find_if(quantities.begin(), quantities.end(),
                         [&](const Quantity& q) { return q.key == key; });
  };
  for (Quantity& q : quantities) {
    q.channel = Channel(log, q.key);
    HydraulicLog::Source& source = log.sources[q.key];
    source.expression = q.expression.text;
    for (const int cell : q.cells) source.columns.push_back(cell + 1);
  }

  // Samples.
  for (std::size_t i = first_data; i < lines.size(); ++i) {
    if (TrimCell(lines[i]).empty() || lines[i][0] == '#') continue;
    const int line = static_cast<int>(i) + 1;
    const std::vector<Cell> cells = SplitCells(lines[i], delimiter);
    if (cells.size() != num_cells) {
      Fail(path, line, 1,
           std::to_string(cells.size()) + " cells, expected " + std::to_string(num_cells) +
               " like the first sample row");
    }
    if (layout.controldesk && !IsControlDeskSampleMarker(cells[0].text, i == first_data)) {
      Fail(path, line, 1,
           std::string("a ControlDesk sample row opens with ") +
               (i == first_data ? "'trace_values' or " : "") + "an empty cell, got '" +
               cells[0].text + "'");
    }
    for (const Quantity& q : quantities) {
      double value = q.expression.offset;
      for (std::size_t t = 0; t < q.cells.size(); ++t) {
        const Cell& cell = cells[q.cells[t]];
        const std::optional<double> number = ParseFinite(cell.text);
        if (!number) {
          Fail(path, line, cell.column,
               q.key + " (column '" + q.expression.terms[t].column.text +
                   "') is not a finite number: '" + cell.text + "'");
        }
        value += q.expression.terms[t].scale * *number;
      }
      const Cell& cell = cells[q.cells.front()];
      if (!std::isfinite(value)) {
        Fail(path, line, cell.column,
             q.key + " '" + q.expression.text + "' is not finite on this row (overflow)");
      }
      const double si = ToSi(q.key, value, format);
      // Spool feedback may overshoot full stroke a little (sensor noise, overtravel).
      const double limit = q.key == "command" ? 1.0 + 1e-9 : 1.2;
      if ((q.key == "command" || q.key == "spool") && std::abs(si) > limit) {
        const bool percent = (q.key == "command" ? format.command_units : format.spool_units) ==
                             CommandUnits::kPercent;
        Fail(path, line, cell.column,
             Describe(q, cell.text, value, format) + " is outside " +
                 (q.key == "spool" ? (percent ? "[-120, 120] %" : "[-1.2, 1.2]")
                                   : (percent ? "[-100, 100] %" : "[-1, 1]")) +
                 (percent ? "" : " (is it in percent? use --" + q.key + "-units percent)"));
      }
      q.channel->push_back(si);
    }
    const std::size_t n = log.time.size();
    if (n >= 2 && !(log.time[n - 1] > log.time[n - 2])) {
      const Quantity& time = by_key("time");
      const Cell& cell = cells[time.cells.front()];
      const double scale = format.time_units == TimeUnits::kMilliseconds ? 1e-3 : 1.0;
      const std::string now = Describe(time, cell.text, log.time[n - 1] / scale, format);
      Fail(path, line, cell.column,
           log.time[n - 1] == log.time[n - 2]
               ? now + " repeats the previous sample's (duplicate timestamp)"
               : now + " is before the previous sample's " +
                     core::FormatNumber(log.time[n - 2] / scale) + UnitSuffix("time", format) +
                     " (time must increase)");
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

void FailAtSample(const HydraulicLog& log, std::size_t sample, const std::string& message) {
  const int row = log.row.empty() ? 0 : log.row[std::min(sample, log.row.size() - 1)];
  core::DiagnosticSink sink;
  sink.Add({log.file, row, 1}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

void RequireExcitation(const HydraulicLog& log) {
  double largest = 0;
  for (double u : log.command) largest = std::max(largest, std::abs(u));
  if (largest > 0.01) return;
  core::DiagnosticSink sink;
  sink.Add({log.file, log.row.empty() ? 0 : log.row.front(), 1}, "",
           "no excitation: the command stays within +/-1 % over all " + std::to_string(log.size()) +
               " rows (a step or chirp log is expected)");
  sink.ThrowIfAny();
}

}  // namespace autoshovel::identification
