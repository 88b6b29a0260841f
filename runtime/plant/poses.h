// Named arm poses of a machine, computed from its description rather than written as numbers.
#pragma once

#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::plant {

/// Joint positions [q_boom, q_bucket] that put a two-link loader arm's bucket on the floor: the
/// floor of the bucket (the profile's first edge, from the tip) level and the tip `tip_height`
/// above the ground (Eq. 2 solved for the boom). Throws std::invalid_argument for an arm that is
/// not two links or cannot reach that low.
std::vector<double> BucketOnFloor(const model::MachineDescription& machine,
                                  double tip_height = 0.05);

}  // namespace autoshovel::plant
