// `autoshovel compare audit`: where a scoop's energy goes (issue 41, item 1). Runs the main job's
// cycle with the plant's energy audit (plant/energy_audit.h) for a gravel scoop ("Just in & out"
// on the mixing station's bin_1, big gravel) and a sand scoop (auto-selection on bin_4, river
// sand), seeds 1..trials, and prints per material a table of every term over the seed's phase
// (bucket contact to the end of the scooping motion: our crowd + scoop phases; travel motor plus
// hydraulic motor, wheel-loader seed Tables 6–7), beside crowd, scoop and the whole cycle; and
// "Just in & out" on the sand, the seed's 82.4 % row. With an output folder it also writes, for
// seed 1, a stacked plot of the energy since contact and of the power by group
// (audit_<material>_<strategy>.png) and every term per tick (.csv).
#pragma once

#include <filesystem>
#include <iosfwd>

#include "runtime/app/compare_command.h"

namespace autoshovel::app {

/// Returns 0 when every cycle completed, 1 when some did not (their figures are left out of the
/// means), 2 on bad input.
int RunEnergyAudit(const CompareOptions& options, const std::filesystem::path& output_dir,
                   std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
