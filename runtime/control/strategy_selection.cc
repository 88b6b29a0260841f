// Algorithm 3 (wheel-loader seed §6.2), lines 3–15.
#include "runtime/control/strategy_selection.h"

#include <cmath>

namespace autoshovel::control {

const char* ToString(ScoopDecision decision) {
  switch (decision) {
    case ScoopDecision::kKeepCrowding:
      return "keep_crowding";
    case ScoopDecision::kJustInOut:
      return "just_in_out";
    case ScoopDecision::kStairway:
      return "stairway";
  }
  return "?";
}

ScoopDecision SelectStrategy(const SelectionInputs& in) {
  if (!std::isfinite(in.v1) || !(in.v1 > 0)) return ScoopDecision::kKeepCrowding;  // line 3
  if (std::isfinite(in.v2) && in.v1 + in.v2 >= in.target_volume) {                 // line 7
    return in.difficult ? ScoopDecision::kStairway : ScoopDecision::kJustInOut;    // lines 8–12
  }
  if (in.stopped) return ScoopDecision::kStairway;  // lines 13–14 (V1 > 0 checked above)
  return ScoopDecision::kKeepCrowding;
}

}  // namespace autoshovel::control
