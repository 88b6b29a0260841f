// `autoshovel compare table4 | table5`: the wheel-loader seed's Tables 4 and 5 rerun in the
// simulated yard, printed beside the seed's figures (docs/results.md holds a committed output).
//
//  table4 — shovel point selection, ours vs Chen et al. (2024), on three yards standing in for
//           the seed's scenarios a, b and c: an irregular heap (irregular_pile), sand against a
//           wall (pile_against_wall), a pile behind a parked loader (pile_behind_loader); the
//           seed's protocol: "perception-triggered Stairway" (our V1 + V2 trigger, adaptive
//           Stairway) for every cycle. A cycle that breaks the safety rule counts as 0 % fill,
//           as the seed counts Chen's scenario c ("unsuitable for practical shoveling").
//  table5 — trigger × scooping strategy on gravel (mixing_station bin_1, big gravel) and sand
//           (bin_4, river sand): pressure-triggered Stairway #3, and the V1 + V2 trigger with
//           Stairway #3, adaptive Stairway, Just in & out and Algorithm 3; plus perception
//           without prediction (V1 only) with Algorithm 3, the second baseline.
// Each cell: `trials` single-cycle runs with seeds 1..trials (sensor noise, hence map, selection
// and contact differ). Simulator labels stand in for the segmentation network unless `network`.
#pragma once

#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct CompareOptions {
  std::string table;  ///< "table4" or "table5"
  std::string models_dir;
  int trials = 5;
  bool network = false;
  double pressure_threshold = 150e5;  ///< [Pa]
  double scoop_deceleration = 0.6;    ///< ShovelRunOptions::scoop_deceleration [m/s²]
  double attack_speed = 1.5;          ///< ShovelRunOptions::attack_speed [m/s]
  double target_fill = 1.0;           ///< ShovelRunOptions::target_fill [-]
  bool attitude_feed_forward = true;  ///< ShovelRunOptions::attitude_feed_forward
  std::string predictor;              ///< SVR model prefix; empty: the shipped one
  /// Name or path of a wheel-loader description to run instead of the scenario's (the
  /// predictor warns when it was trained on another machine); empty: the scenario's.
  std::string machine;
  /// Table 5: beside every row, the optimal scoop (runtime/optimal) from each trial's contact on
  /// the same pile at the strategy's fill and within its time.
  bool optimum = true;
};

/// Prints the table; returns 0, or 2 on bad input.
int RunCompare(const CompareOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
