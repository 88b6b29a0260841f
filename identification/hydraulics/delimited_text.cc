#include "identification/hydraulics/delimited_text.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace autoshovel::identification {

std::string TrimCell(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n\"'");
  if (begin == std::string::npos) return "";
  const auto end = text.find_last_not_of(" \t\r\n\"'");
  return text.substr(begin, end - begin + 1);
}

std::vector<Cell> SplitCells(const std::string& line, char delimiter) {
  std::vector<Cell> cells;
  std::size_t start = 0;
  while (true) {
    std::size_t end = line.find(delimiter, start);
    const std::size_t first = line.find_first_not_of(" \t", start);
    if (first != std::string::npos && line[first] == '"' &&
        (end == std::string::npos || first < end)) {
      // A quoted cell: the delimiter that ends it is the first one after the closing quote.
      std::size_t at = first + 1;
      while (at < line.size()) {
        if (line[at] == '"' && at + 1 < line.size() && line[at + 1] == '"') {
          at += 2;
        } else if (line[at] == '"') {
          break;
        } else {
          ++at;
        }
      }
      if (at < line.size()) {
        end = line.find(delimiter, at + 1);
        std::string text = line.substr(first + 1, at - first - 1);
        for (std::size_t q = text.find("\"\""); q != std::string::npos;
             q = text.find("\"\"", q + 1)) {
          text.erase(q, 1);
        }
        // Anything between the closing quote and the delimiter stays part of the cell.
        text += line.substr(at + 1, end == std::string::npos ? end : end - at - 1);
        cells.push_back({TrimCell(text), static_cast<int>(start) + 1});
        if (end == std::string::npos) break;
        start = end + 1;
        continue;
      }
    }
    const std::string raw = line.substr(start, end == std::string::npos ? end : end - start);
    cells.push_back({TrimCell(raw), static_cast<int>(start) + 1});
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return cells;
}

char DetectDelimiter(const std::string& line) {
  const std::size_t commas = std::count(line.begin(), line.end(), ',');
  const std::size_t semicolons = std::count(line.begin(), line.end(), ';');
  const std::size_t tabs = std::count(line.begin(), line.end(), '\t');
  if (tabs > commas && tabs > semicolons) return '\t';
  if (semicolons > commas) return ';';
  return ',';
}

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

}  // namespace autoshovel::identification
