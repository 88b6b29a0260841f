#include "runtime/planning/dig/swept_volume.h"

#include <algorithm>
#include <cmath>

namespace autoshovel::planning {

double SweptVolumeEstimate(const control::HeightGrid& map_base, const DigAction& action,
                           double bucket_width, double step) {
  if (!(action.drag_length > 0) || !(step > 0)) return 0.0;
  const int n = std::max(1, static_cast<int>(std::ceil(action.drag_length / step)));
  const double h = action.drag_length / n;
  const double c = std::cos(action.swing), s = std::sin(action.swing);
  const double z_cut = action.entry_height - action.depth;
  double area = 0;
  for (int k = 0; k < n; ++k) {
    const double rho = action.radius - (k + 0.5) * h;
    const double surface = map_base.HeightAt(rho * c, rho * s);
    if (std::isfinite(surface)) area += std::max(0.0, surface - z_cut) * h;
  }
  return bucket_width * area;
}

}  // namespace autoshovel::planning
