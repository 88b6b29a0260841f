// Axis tick arithmetic shared by the plots' .cc files (internal: not part of the plot API).
// "Nice" steps are 1, 2 or 5 times a power of ten, as in Heckbert, "Nice numbers for graph
// labels", Graphics Gems (1990) (the rounding thresholds here are line_plot.cc's own: 1.5, 3.5,
// 7.5); labels carry as many decimals as the step needs.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace autoshovel::plot::internal {

/// 1, 2 or 5 times a power of ten, near span / 5 (span > 0).
inline double NiceStep(double span) {
  const double raw = span / 5.0;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double fraction = raw / power;
  const double nice = fraction < 1.5 ? 1.0 : fraction < 3.5 ? 2.0 : fraction < 7.5 ? 5.0 : 10.0;
  return nice * power;
}

/// `value` with the decimals that `step` needs ("0.25" for step 0.05), "%.3g" when that would
/// be longer than 8 characters; never "-0".
inline std::string TickLabel(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(value) < step * 1e-6) value = 0.0;  // no "-0"
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  if (std::strlen(buffer) > 8) std::snprintf(buffer, sizeof(buffer), "%.3g", value);  // fits
  return buffer;
}

}  // namespace autoshovel::plot::internal
