// The rows of the recording's CSV tables (docs/recording_format.md): split into fields that know
// their column, each checked as it is read, the first problem refusing the file at
// `file:line:column` (core::InputError). Only core: the fuzz targets compile this with the table
// readers alone.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace autoshovel::recording {

struct Field {
  std::string text;
  int column = 1;  ///< 1-based character position
};

using CsvRow = std::pair<int, std::vector<Field>>;  ///< line number, fields

[[noreturn]] void Refuse(const std::string& source, int line, int column, const std::string& what);

/// The rows of a CSV whose first line must be `header`, split into fields; each row with the
/// header's number of fields. A trailing CR (a file from Windows) is dropped, empty lines are
/// skipped, a NUL byte is refused.
std::vector<CsvRow> CsvRows(const std::string& text, const std::string& source,
                            const std::string& header);

/// The largest table read: 1 GiB (about five million LiDAR frames, or 20 million scan points).
inline constexpr std::uintmax_t kMaxCsvBytes = std::uintmax_t{1} << 30;

/// A table's text. Refuses (at `path:0:0`) what is not a regular file, is larger than
/// kMaxCsvBytes, or cannot be opened.
std::string ReadTableFile(const std::filesystem::path& path);

/// A finite number.
double Finite(const std::string& source, int line, const Field& f, const char* name);
/// An integer in [min, max].
long Integer(const std::string& source, int line, const Field& f, const char* name, long min,
             long max);
/// 0 or 1.
bool Flag(const std::string& source, int line, const Field& f, const char* name);

}  // namespace autoshovel::recording
