// `autoshovel report production DB`: the wheel-loader seed's production statistics (§7.5) from
// a campaign database (campaign_command.h):
//
// - Table 6 layout: per week, the adaptive policy's cycles by the strategy it ran ("Just in &
//   out", "Stairway #N" with N its atomic actions), counted per material, with the mean
//   scooping time and energy of each;
// - Table 7 layout: per material, how often each strategy ran, mean time and energy;
// - the comparison the seed draws: the adaptive policy against the fixed "Stairway #3" on the
//   same shifts, scooping time and energy, fill rate and completed cycles;
// - Fig. 22: box plots of scooping time and energy per strategy, as a PNG.
//
// Scooping time and energy are the seed's: from the bucket's contact with the material to the
// end of the scooping motion, i.e. our crowd and scoop phases together.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct ProductionReportOptions {
  std::filesystem::path database;
  std::filesystem::path png;  ///< empty: <database folder>/production_fig22.png
  std::string adaptive_policy = "auto";
  std::string baseline_policy = "stairway_fixed";
};

/// 0 on success, 2 when the database cannot be read or holds no campaign (named on `err`).
int RunProductionReport(const ProductionReportOptions& options, std::ostream& out,
                        std::ostream& err);

}  // namespace autoshovel::app
