#include "runtime/recording/csv_rows.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "runtime/core/diagnostics.h"
#include "runtime/core/input_file.h"

namespace autoshovel::recording {
namespace {

std::vector<Field> SplitCsvLine(const std::string& line) {
  std::vector<Field> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string::npos ? line.size() : comma;
    fields.push_back({line.substr(start, end - start), static_cast<int>(start) + 1});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

}  // namespace

void Refuse(const std::string& source, int line, int column, const std::string& what) {
  core::RefuseInput({source, line, column}, what);
}

// The rows of a CSV whose first line must be `header`, split into fields; each row with the
// header's number of fields. A trailing CR (a file from Windows) is dropped.
std::vector<CsvRow> CsvRows(const std::string& text, const std::string& source,
                            const std::string& header) {
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  const std::size_t columns = SplitCsvLine(header).size();
  std::vector<CsvRow> rows;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_no == 1) {
      if (line != header) {
        Refuse(source, 1, 1,
               "expected the header '" + header + "', got '" + line.substr(0, 200) + "'");
      }
      continue;
    }
    if (line.empty()) continue;
    if (line.find('\0') != std::string::npos) Refuse(source, line_no, 1, "a NUL byte in the row");
    std::vector<Field> fields = SplitCsvLine(line);
    if (fields.size() != columns) {
      Refuse(source, line_no, 1,
             "expected " + std::to_string(columns) + " fields (" + header + "), got " +
                 std::to_string(fields.size()));
    }
    rows.emplace_back(line_no, std::move(fields));
  }
  if (line_no == 0) Refuse(source, 0, 0, "empty: expected the header '" + header + "'");
  return rows;
}

std::string ReadTableFile(const std::filesystem::path& path) {
  const std::string why = core::NotARegularFile(path);
  if (!why.empty()) Refuse(path.string(), 0, 0, why);
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) > kMaxCsvBytes) {
    Refuse(path.string(), 0, 0, "larger than 1 GiB");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) Refuse(path.string(), 0, 0, "cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

double Finite(const std::string& source, int line, const Field& f, const char* name) {
  char* stop = nullptr;
  errno = 0;
  const double v = std::strtod(f.text.c_str(), &stop);
  if (f.text.empty() || stop != f.text.c_str() + f.text.size() || errno == ERANGE ||
      !std::isfinite(v)) {
    Refuse(source, line, f.column,
           std::string(name) + ": expected a finite number, got '" + f.text.substr(0, 40) + "'");
  }
  return v;
}

long Integer(const std::string& source, int line, const Field& f, const char* name, long min,
             long max) {
  char* stop = nullptr;
  errno = 0;
  const long v = std::strtol(f.text.c_str(), &stop, 10);
  if (f.text.empty() || stop != f.text.c_str() + f.text.size() || errno == ERANGE || v < min ||
      v > max) {
    Refuse(source, line, f.column,
           std::string(name) + ": expected an integer in [" + std::to_string(min) + ", " +
               std::to_string(max) + "], got '" + f.text.substr(0, 40) + "'");
  }
  return v;
}

bool Flag(const std::string& source, int line, const Field& f, const char* name) {
  if (f.text == "0") return false;
  if (f.text == "1") return true;
  Refuse(source, line, f.column,
         std::string(name) + ": expected 0 or 1, got '" + f.text.substr(0, 40) + "'");
}

}  // namespace autoshovel::recording
