// A cheap estimate of what a dig takes, from the terrain map alone, for screening candidates
// before the forward model is asked (excavator seed §4.2: the forward model is the expensive part
// of the refined planner, Fig. 13). The bucket drags its full width through the material above
// the cut height, from the entry radius back to the drag's end:
//   V̂ = w · ∫_{r−L}^{r} max(0, s(ρ) − z_cut) dρ,   z_cut = entry_height − depth
// with s the map's surface along the arm plane (unknown cells count as empty), the integral by the
// midpoint rule at no more than `step`. It ignores what the forward model knows (fill factor,
// spill, the curl's own sweep), so it orders candidates; it never decides.
#pragma once

#include "runtime/control/excavator/height_grid.h"
#include "runtime/planning/dig/dig_action.h"

namespace autoshovel::planning {

/// V̂ [m^3] for `action` on `map_base` (base frame) with a bucket `bucket_width` wide [m].
double SweptVolumeEstimate(const control::HeightGrid& map_base, const DigAction& action,
                           double bucket_width, double step);

}  // namespace autoshovel::planning
