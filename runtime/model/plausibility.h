// Plausibility of a description's values: each number against the range that real loaders and
// excavators (1 t to 1,000 t) span, naming the likely unit mistake when the value fits the
// range once converted (a bore of 180 "m" is 0.180 m given in mm; an operating mass of 16.8
// "kg" is 16.8 t; a relief pressure of 28 "bar" is 28 MPa).
//
// Severity (docs/spec_sheet.md, "Plausibility"): a value outside its plausible range
// but within a factor of 10 of it is a warning, and the description loads (an unusual machine
// may be real); a value more than 10 times outside the range, or an operating mass below the
// mass of the arm's own links, is impossible for any earthmover and refuses the file, since
// every figure computed from it (a lift capacity of millions of tonnes) would be nonsense.
#pragma once

#include <vector>

#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"

namespace autoshovel::model {

/// One rule: a key's plausible range, in the file's unit.
struct PlausibleRange {
  double low = 0;   ///< 0: no lower bound
  double high = 0;  ///< [unit]
  const char* unit = "";
  const char* what = "";  ///< "a cylinder bore"
};

/// Refusal factor beyond the plausible range (see above).
inline constexpr double kImpossibleFactor = 10.0;

struct PlausibilityFindings {
  std::vector<core::Diagnostic> warnings;  ///< severity kWarning
  std::vector<core::Diagnostic> errors;    ///< impossible values: the file is refused
};

/// Checks every ranged value of a parsed description. Locations come from `machine.locations`.
PlausibilityFindings CheckPlausibility(const MachineDescription& machine);

/// The message for one value (empty if plausible), for tests and the rules above:
/// "bore 180 m is implausible for a cylinder bore (0.02–0.6 m): given in mm? 0.18 m".
/// `impossible` is set when the value is beyond kImpossibleFactor of the range.
std::string PlausibilityMessage(const std::string& key, double value, const PlausibleRange& range,
                                bool& impossible);

}  // namespace autoshovel::model
