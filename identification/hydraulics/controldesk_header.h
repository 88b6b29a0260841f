// Where the samples of a hydraulic log start, and the column names of a dSPACE ControlDesk CSV
// export (e.g. a MicroAutoBox recording at 100 Hz, issue 40). Such an export has some 28 header
// rows, each opening with a key cell:
//   descriptions,General,User,...          free text, then rows opening with an empty cell
//   trace_names,,In1,In1,...,Boom_up_duty  one name per trace; the first (time) has none, and
//                                          many traces share the name `In1`
//   path,,Model Root/.../Boom_UpH_Cyl_P    the model path of each trace
//   ...                                    trace_units, raster, min, max, ...
//   trace_values,0,62.78,...               the first sample row; later rows open with an empty
//   ,0.01,62.79,...                        cell. Time is the first value (column 2 of the file)
// The marker cell stays column 1, so 1-based column numbers are those of the file.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "identification/hydraulics/column_names.h"

namespace autoshovel::identification {

struct LogLayout {
  /// 0-based line of the first sample row; the number of lines when there is none.
  std::size_t first_data = 0;
  /// A ControlDesk export: a `trace_names` row, or a first sample row opening with `trace_values`.
  bool controldesk = false;
  int names_line = -1;  ///< 0-based line of `trace_names`; -1: none
  int paths_line = -1;  ///< 0-based line of `path` (after `trace_names`); -1: none
};

/// Finds the first sample row: line `header_lines` when that is >= 0, else the `trace_values` row
/// of a ControlDesk export, else the first row (not blank, not a `#` comment) whose first cell is
/// a number. ControlDesk's `trace_names` and `path` rows are looked for before it either way.
LogLayout FindLogLayout(const std::vector<std::string>& lines, int header_lines);

/// Whether a row's first cell opens a ControlDesk sample row: an empty cell, or `trace_values`
/// on the first sample row.
bool IsControlDeskSampleMarker(const std::string& first_cell, bool first_row);

/// The names of a ControlDesk export's columns: the trace name, the full path and the path's
/// last `/` part of each trace; the time column (the first after the marker) also answers to
/// `time`. Throws core::InputError (`path:line:1`) when the `trace_names` or `path` row does not
/// have `num_cells` cells like the sample rows.
ColumnNames ControlDeskNames(const std::string& path, const std::vector<std::string>& lines,
                             const LogLayout& layout, char delimiter, std::size_t num_cells);

}  // namespace autoshovel::identification
