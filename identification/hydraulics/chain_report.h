// What `identify hydraulics` prints and draws for a valve-chain fit (valve_chain_fit.h): per
// actuator and direction, the parameters with their bootstrap intervals and flags, the delay
// per duty level and stage, the validation, and per log the fit's figures; and a PNG of the
// measured and fitted angle and pilot pressure of every log, stalls marked.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "identification/hydraulics/valve_chain_fit.h"

namespace autoshovel::identification {

struct NamedChain {
  std::string actuator;
  ChainIdentification chain;
  /// The flow that gives the highest logged level's joint rate through the description's
  /// cylinder at the logs' centre angle, the first direction identified [l/min]; 0: none.
  double rated_flow_lpm = 0;
  std::string rated_flow_note;  ///< how it was found, for the overlay's comment
};

void PrintChainTable(const NamedChain& result, std::ostream& out);

void WriteChainPlot(const std::vector<NamedChain>& results, const std::string& path);

/// The description overlay of the identified chains (keys of docs/simulation.md "Valve
/// chain"): pilot_delay, pilot_time_constant, transport_delay, spool_time_constant (the mean of
/// the directions identified, each direction's value in a comment), and an opening curve per
/// direction identified (positive commands: opening_curve_extend), sampled from the flow
/// characteristic every 5 % and normalised to its largest value; dead_zone 0 when both are
/// given. What the plant has no key for (late supply, angle gain, load coefficient) is listed
/// in comments. `header` is identification::OverlayHeader's.
std::string ChainOverlayText(const std::string& header, const std::vector<NamedChain>& results);

}  // namespace autoshovel::identification
