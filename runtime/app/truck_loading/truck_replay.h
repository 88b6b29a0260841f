// `autoshovel replay DIR` on a truck-loading recording (docs/recording_format.md, "Truck
// loading"): truck recognition (excavator seed §4.1) on the recorded recognition scan, then the
// dump planner's bed map (§4.3) built scan by scan as the machine built it, no plant. The run
// folder gets the recognised truck and the bed map after every scan in the form of the
// recording's reference/, the final bed map's picture, and the log.
#pragma once

#include <ostream>
#include <string>

namespace autoshovel::app {

/// Returns 0 on success, 1 when `check` is set and the replay differs from the recording's
/// reference, 2 on bad input. `out_dir`: the run folder (empty: runs/<UTC timestamp>).
int RunTruckReplay(const std::string& recording_dir, const std::string& out_dir, bool check,
                   std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
