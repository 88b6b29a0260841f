// Cells of one line of a delimited text log (comma, semicolon or tab), for the hydraulic log
// reader (log_reader.h) and the ControlDesk header it recognises (controldesk_header.h).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace autoshovel::identification {

/// One cell of a line: its text without surrounding blanks and quotes, and where it starts.
struct Cell {
  std::string text;
  int column = 1;  ///< 1-based character column of the cell's start, for `file:row:column`
};

/// Blanks, CR/LF and quotes trimmed from both ends.
std::string TrimCell(const std::string& text);

/// The cells of `line`. A cell that starts with `"` runs to its closing quote (`""` is a quote
/// inside it), so a quoted delimiter does not split it (ControlDesk writes such free text in its
/// header); an unclosed quote is taken as plain text.
std::vector<Cell> SplitCells(const std::string& line, char delimiter);

/// The delimiter of a line: the most frequent of tab, semicolon and comma (comma on a tie).
char DetectDelimiter(const std::string& line);

/// A finite number spelled in full, or nothing ("nan", "inf", "", "1.2x" are not numbers here).
std::optional<double> ParseFinite(const std::string& text);

}  // namespace autoshovel::identification
