// The names each column of a hydraulic log answers to, and the row of the file that gave them:
// the header row of an ordinary CSV, or a ControlDesk export's trace names and signal paths
// (controldesk_header.h). A name may answer for several columns (ControlDesk names most traces
// `In1`): Find returns them all and the reader refuses the name, pointing at UniqueName.
#pragma once

#include <string>
#include <vector>

namespace autoshovel::identification {

class ColumnNames {
 public:
  /// `cell` (0-based) answers to `name`, read from `row` ("header line 3", "ControlDesk path").
  void Add(int cell, const std::string& name, const std::string& row);

  /// The 0-based cells answering to `name`, ascending, each once.
  std::vector<int> Find(const std::string& name) const;
  /// The rows that gave `name` to any of `cells`, joined by ", ".
  std::string RowsNaming(const std::string& name, const std::vector<int>& cells) const;
  /// The shortest name of `cell` that names no other cell, and the row it came from; "" if none.
  std::pair<std::string, std::string> UniqueName(int cell) const;
  /// The first name of `cell`, "" if it has none: what messages call the column.
  std::string FirstName(int cell) const;
  /// Every distinct name, for "did you mean".
  std::vector<std::string> All() const;
  bool empty() const { return entries_.empty(); }

 private:
  struct Entry {
    int cell;
    std::string name, row;
  };
  std::vector<Entry> entries_;
};

/// 1-based column numbers of 0-based `cells`, runs of three or more as `a..b`: "3..8, 15, 17".
std::string ColumnRanges(const std::vector<int>& cells);

}  // namespace autoshovel::identification
