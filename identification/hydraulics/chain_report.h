// What `identify hydraulics` prints and draws for a valve-chain fit (valve_chain_fit.h): per
// actuator and direction, the parameters with their bootstrap intervals and flags, the delay
// per duty level and stage, the validation, and per log the fit's figures; and a PNG of the
// measured and fitted angle and pilot pressure of every log, stalls marked.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "identification/hydraulics/valve_chain_fit.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {

struct NamedChain {
  std::string actuator;
  ChainIdentification chain;
  /// The plant's flow at full spool opening [l/min]; 0: none. Each direction needs its own
  /// flow at full opening to move the joint at its identified full-opening rate through the
  /// description's cylinder (cap area extending, annulus retracting) at its logs' centre angle;
  /// the rated flow is the larger, and the other direction's opening curve is scaled down by
  /// its share (`opening_scale`, one per chain.directions entry).
  double rated_flow_lpm = 0;
  std::string rated_flow_note;  ///< how it was found, for the overlay's comment
  std::vector<double> opening_scale;
};

/// The plant's flow for `result` (rated_flow_lpm, opening_scale, the note) through actuator
/// `actuator` of the description: each direction needs the flow that moves the description's
/// cylinder (cap area extending, annulus retracting) so that the joint turns at that direction's
/// full-opening rate at its logs' centre angle (docs/hydraulic_identification.md, "Into the
/// plant"). The rated flow is the larger; the other direction's opening is scaled by its share.
/// One flow for both, as before, ran a retraction faster by the area ratio: the real boom-down
/// logs replayed 1.6 times too fast.
void AssignPlantFlow(NamedChain& result, const model::MachineDescription& machine,
                     const generated::MachineFunctions& functions, int actuator);

/// A direction's joint rate at full duty [rad/s]: its flow characteristic at duty 1, extended
/// beyond the highest level logged along its last secant (not held flat, which would claim a
/// saturation nobody saw).
double FullOpeningRate(const DirectionFit& direction);

void PrintChainTable(const NamedChain& result, std::ostream& out);

void WriteChainPlot(const std::vector<NamedChain>& results, const std::string& path);

/// The description overlay of the identified chains (keys of docs/simulation.md "Valve
/// chain"): pilot_delay, pilot_time_constant, transport_delay, spool_time_constant (the mean of
/// the directions identified, each direction's value in a comment), and an opening curve per
/// direction identified (positive commands: opening_curve_extend), sampled from the flow
/// characteristic every 5 % and normalised to its value at full duty times the direction's
/// opening_scale; dead_zone 0 when both are given. What the plant has no key for (late supply,
/// angle gain, load coefficient) is listed in comments. `header` is
/// identification::OverlayHeader's.
std::string ChainOverlayText(const std::string& header, const std::vector<NamedChain>& results);

}  // namespace autoshovel::identification
