// A per-cell flag over a truck-bed grid (excavator seed §4.3): which cells of the bed terrain map
// were seen by the scanner. Rows run along the bed (bed x), columns across it (bed y), the same
// layout as every height matrix of the dump planner.
#pragma once

#include <Eigen/Core>

namespace autoshovel::planning {

using CellMask = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;

}  // namespace autoshovel::planning
