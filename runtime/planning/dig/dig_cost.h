// The refined planner's evaluation function (excavator seed §4.2, Fig. 13: "an evaluation
// function scores the trajectory resulting from each action, and the action that meets all
// constraints and optimizes the cost function is chosen"; the seed names volume, energy and time
// as what the cost may weigh). Lower is better:
//
//   J = w_v · (1 − min(V, V_cap) / V_cap)      unfilled share of the bucket
//     + w_e · E / E_ref                         hydraulic energy, normalised
//     + w_t · t / t_ref                         dig duration, normalised
//     + w_o · max(0, V − V_cap) / V_cap         overflow past the heaped capacity (spills)
//
// V [m^3], E [J], t [s] are the forward model's prediction; V_cap is the bucket's heaped rated
// capacity (SAE J742, model::Bucket::rated_capacity). Each term is dimensionless and about 1 for
// a typical dig, so the weights read as exchange rates: with the defaults, filling a further 10 %
// of the bucket is worth 0.1 · E_ref / 0.25 = 200 kJ or 0.1 · t_ref / 0.25 = 2.4 s.
#pragma once

#include <string>

#include "runtime/planning/dig/dig_action.h"

namespace autoshovel::planning {

struct DigCostConfig {
  double bucket_capacity = 1.2;  ///< V_cap, heaped [m^3] (> 0)
  double weight_volume = 1.0;    ///< w_v (>= 0)
  double weight_energy = 0.25;   ///< w_e (>= 0)
  double weight_time = 0.25;     ///< w_t (>= 0)
  double weight_overflow = 2.0;  ///< w_o (>= 0)
  /// E_ref [J] (> 0): the order of a 25 t excavator's dig, ~100 kW of pump power for ~5 s.
  double energy_reference = 5.0e5;
  double time_reference = 6.0;  ///< t_ref [s] (> 0): the dig part of a ~18 s loading cycle
};

/// Throws std::invalid_argument naming the field (prefixed with `what`).
void Validate(const DigCostConfig& config, const std::string& what);

struct DigCostTerms {
  double unfilled = 0;  ///< w_v · (1 − min(V, V_cap) / V_cap)
  double energy = 0;    ///< w_e · E / E_ref
  double time = 0;      ///< w_t · t / t_ref
  double overflow = 0;  ///< w_o · max(0, V − V_cap) / V_cap
  double total = 0;     ///< J, the sum
};

/// J and its terms for a usable prediction (IsUsable); for any other every term is NaN.
DigCostTerms DigCost(const DigPrediction& prediction, const DigCostConfig& config);

/// The volume terms of J alone, w_v · (1 − min(V, V_cap) / V_cap) + w_o · max(0, V − V_cap) /
/// V_cap, for a volume estimated without the forward model (the refined planner's screening).
double VolumeCost(double volume, const DigCostConfig& config);

}  // namespace autoshovel::planning
