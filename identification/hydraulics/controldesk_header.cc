#include "identification/hydraulics/controldesk_header.h"

#include "identification/hydraulics/delimited_text.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {

namespace {

constexpr const char* kTraceNames = "trace_names";
constexpr const char* kTraceValues = "trace_values";
constexpr const char* kPath = "path";

bool Skipped(const std::string& line) {
  return line.find_first_not_of(" \t\r\n") == std::string::npos || line[0] == '#';
}

std::string FirstCell(const std::string& line) {
  return SplitCells(line, DetectDelimiter(line)).front().text;
}

}  // namespace

LogLayout FindLogLayout(const std::vector<std::string>& lines, int header_lines) {
  LogLayout layout;
  const bool given = header_lines >= 0;
  const std::size_t end =
      given ? std::min(lines.size(), static_cast<std::size_t>(header_lines)) : lines.size();
  layout.first_data = given ? static_cast<std::size_t>(header_lines) : lines.size();
  for (std::size_t i = 0; i < end; ++i) {
    if (Skipped(lines[i])) continue;
    const std::vector<Cell> cells = SplitCells(lines[i], DetectDelimiter(lines[i]));
    const std::string& first = cells.front().text;
    if (first == kTraceNames && layout.names_line < 0) {
      layout.names_line = static_cast<int>(i);
      layout.controldesk = true;
    } else if (first == kPath && layout.names_line >= 0 && layout.paths_line < 0) {
      layout.paths_line = static_cast<int>(i);
    } else if (!given && first == kTraceValues) {
      layout.first_data = i;
      layout.controldesk = true;
      break;
    } else if (!given && layout.names_line < 0 && cells.size() > 1 &&
               ParseFinite(first).has_value()) {
      // A sample row: its first cell is a number (the rest is checked cell by cell later, so a
      // NaN in a data row is reported as such rather than taken for a header line).
      layout.first_data = i;
      break;
    }
  }
  if (given && layout.first_data < lines.size() &&
      FirstCell(lines[layout.first_data]) == kTraceValues) {
    layout.controldesk = true;
  }
  return layout;
}

bool IsControlDeskSampleMarker(const std::string& first_cell, bool first_row) {
  // The first row read may be a later one (`--header-lines` past the `trace_values` row).
  return first_cell.empty() || (first_row && first_cell == kTraceValues);
}

ColumnNames ControlDeskNames(const std::string& path, const std::vector<std::string>& lines,
                             const LogLayout& layout, char delimiter, std::size_t num_cells) {
  ColumnNames names;
  if (num_cells > 1) names.Add(1, "time", "ControlDesk time column");
  const auto row = [&](int line, const char* what) {
    std::vector<Cell> cells = SplitCells(lines[line], delimiter);
    if (cells.size() != num_cells) {
      core::DiagnosticSink sink;
      sink.Add({path, line + 1, 1}, "",
               std::string("ControlDesk ") + what + " has " + std::to_string(cells.size()) +
                   " cells, the sample rows " + std::to_string(num_cells) +
                   ": its names cannot be matched to the columns");
      sink.ThrowIfAny();
    }
    return cells;
  };
  if (layout.names_line >= 0) {
    const std::vector<Cell> cells = row(layout.names_line, kTraceNames);
    for (std::size_t c = 1; c < cells.size(); ++c) {
      names.Add(static_cast<int>(c), cells[c].text, "ControlDesk trace_names");
    }
  }
  if (layout.paths_line >= 0) {
    const std::vector<Cell> cells = row(layout.paths_line, kPath);
    for (std::size_t c = 1; c < cells.size(); ++c) {
      const std::string& full = cells[c].text;
      names.Add(static_cast<int>(c), full, "ControlDesk path");
      const std::size_t slash = full.rfind('/');
      if (slash != std::string::npos && slash + 1 < full.size()) {
        names.Add(static_cast<int>(c), full.substr(slash + 1), "ControlDesk path");
      }
    }
  }
  return names;
}

}  // namespace autoshovel::identification
