// What a quantity of a hydraulic log is read from (issue 40): one column, or a signed, scaled
// sum of columns plus an offset, as written in `--columns` or a YAML column map:
//   command=Boom_up_duty - Boom_dn_duty     two valve directions → one signed command
//   joint_angle=-Boom_ang                   a sensor mounted the other way round
//   pressure_a=0.1*Boom_UpH_Cyl_P           a gain
//   joint_angle=Arm_ang + 90                an offset
//   pilot_pressure=$25 + $26                columns by 1-based number
//
// A value is read in one of three ways:
//   - digits only: a 1-based column number (`time=2`);
//   - no `+`, `-`, `*`, `$` or quote in it: a column name exactly as written, spaces and other
//     characters included (`spool=Spool pos`, `time=Time (s)`), as before expressions existed;
//   - otherwise an expression:
//       expression = term { ("+" | "-") term }          a leading "-" or "+" is allowed
//       term       = [number "*"] ["-"] reference | number
//       reference  = name | 'quoted name' | "quoted name" | "$" digits
//       name       = a letter, "_", "." or "/", then letters, digits, "_", "." or "/"
//     Numbers are constants (`90`, `0.1`, `1e-3`); a name with other characters (a ControlDesk
//     path such as `Model Root/Cylinder pressure(22.03.23)/Arm_InH_Cyl_P`) is quoted. At least
//     one column is needed. When the whole value happens to be a column's name (a header `P-rod`)
//     the reader takes that column (log_reader.cc).
// Units (--command-units ...) apply to the result.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace autoshovel::identification {

/// One column in an expression: by name or by 1-based number.
struct ColumnReference {
  bool by_number = false;
  std::string name;      ///< the name, unquoted, when by name
  long number = 0;       ///< the 1-based number when by number; 0 also for one too large to hold
  std::string text;      ///< as written (`Boom_ang`, `'a b'`, `$3`, `3`), for messages
  std::size_t position;  ///< 1-based character of `text` in the value
};

/// `scale * column` [the column's own units].
struct ColumnTerm {
  double scale = 1;
  ColumnReference column;
};

/// sum of `terms` + `offset`, in the log's units (converted to SI by the reader afterwards).
struct ColumnExpression {
  std::string text;               ///< the value as given, blanks trimmed
  std::vector<ColumnTerm> terms;  ///< at least one
  double offset = 0;

  /// One column read as it is (no sign, scale or offset): messages quote its cell as written.
  bool plain() const { return terms.size() == 1 && terms[0].scale == 1 && offset == 0; }
};

/// A malformed value: `what()` says what was expected, `position` (1-based character of the
/// value) where.
class ColumnExpressionError : public std::invalid_argument {
 public:
  ColumnExpressionError(std::size_t at, const std::string& message)
      : std::invalid_argument(message), position(at) {}
  std::size_t position;
};

/// Reads a column value (see above). Throws ColumnExpressionError.
ColumnExpression ParseColumnExpression(const std::string& value);

}  // namespace autoshovel::identification
