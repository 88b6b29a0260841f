#include "runtime/planning/dig/dig_region.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace autoshovel::planning {

void Validate(const DigSector& sector, const std::string& what) {
  auto fail = [&](const std::string& field, const std::string& rule, double value) {
    throw std::invalid_argument(what + "." + field + ": " + rule + ", got " +
                                std::to_string(value));
  };
  constexpr double kPi = std::numbers::pi;
  if (!(std::isfinite(sector.swing_min) && sector.swing_min >= -kPi && sector.swing_min <= kPi)) {
    fail("swing_min", "must be finite and in [-pi, pi] rad", sector.swing_min);
  }
  // A sector crossing ψ = ±π (behind the machine) is not supported: the cells' swing is
  // atan2(y, x) in (-π, π] and the sector is one interval of it.
  if (!(std::isfinite(sector.swing_max) && sector.swing_max > sector.swing_min &&
        sector.swing_max <= kPi)) {
    fail("swing_max", "must be finite, > swing_min and <= pi rad", sector.swing_max);
  }
  if (!(std::isfinite(sector.radius_min) && sector.radius_min > 0)) {
    fail("radius_min", "must be finite and > 0 m", sector.radius_min);
  }
  if (!(std::isfinite(sector.radius_max) && sector.radius_max > sector.radius_min)) {
    fail("radius_max", "must be finite and > radius_min", sector.radius_max);
  }
  if (!std::isfinite(sector.floor_height)) {
    fail("floor_height", "must be finite", sector.floor_height);
  }
}

}  // namespace autoshovel::planning
