#include "runtime/planning/dig/dig_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace autoshovel::planning {
namespace {

double Unfilled(double volume, const DigCostConfig& config) {
  const double capacity = config.bucket_capacity;
  return config.weight_volume * (1.0 - std::min(volume, capacity) / capacity);
}

double Overflow(double volume, const DigCostConfig& config) {
  const double capacity = config.bucket_capacity;
  return config.weight_overflow * std::max(0.0, volume - capacity) / capacity;
}

}  // namespace

void Validate(const DigCostConfig& config, const std::string& what) {
  auto require = [&](bool ok, const std::string& field, const std::string& rule, double value) {
    if (!ok) {
      throw std::invalid_argument(what + "." + field + ": " + rule + ", got " +
                                  std::to_string(value));
    }
  };
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  require(positive(config.bucket_capacity), "bucket_capacity", "must be finite and > 0 m^3",
          config.bucket_capacity);
  require(non_negative(config.weight_volume), "weight_volume", "must be finite and >= 0",
          config.weight_volume);
  require(non_negative(config.weight_energy), "weight_energy", "must be finite and >= 0",
          config.weight_energy);
  require(non_negative(config.weight_time), "weight_time", "must be finite and >= 0",
          config.weight_time);
  require(non_negative(config.weight_overflow), "weight_overflow", "must be finite and >= 0",
          config.weight_overflow);
  require(positive(config.energy_reference), "energy_reference", "must be finite and > 0 J",
          config.energy_reference);
  require(positive(config.time_reference), "time_reference", "must be finite and > 0 s",
          config.time_reference);
}

DigCostTerms DigCost(const DigPrediction& prediction, const DigCostConfig& config) {
  std::string why;
  if (!IsUsable(prediction, why)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan, nan, nan};
  }
  DigCostTerms terms;
  terms.unfilled = Unfilled(prediction.volume, config);
  terms.energy = config.weight_energy * prediction.energy / config.energy_reference;
  terms.time = config.weight_time * prediction.duration / config.time_reference;
  terms.overflow = Overflow(prediction.volume, config);
  terms.total = terms.unfilled + terms.energy + terms.time + terms.overflow;
  return terms;
}

double VolumeCost(double volume, const DigCostConfig& config) {
  return Unfilled(volume, config) + Overflow(volume, config);
}

}  // namespace autoshovel::planning
