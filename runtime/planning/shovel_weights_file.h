// The Eq. (18) weights from a YAML file (`autoshovel train weights` writes one):
//   k_t: 0.29
//   k_s: 0.23
//   k_c: 0.13
//   k_e: 0.25
//   k_a: 0.10
// All five are required, non-negative and finite, at least one positive; any other key is
// refused. Problems are thrown as core::InputError with `file:line:column` (yaml_reader.h).
#pragma once

#include <string>

#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::planning {

/// Sets config.k_t … k_a from `path`; leaves `config` untouched when the file is refused.
void ReadShovelWeights(const std::string& path, ShovelPointConfig& config);

}  // namespace autoshovel::planning
