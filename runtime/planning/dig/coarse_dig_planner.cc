#include "runtime/planning/dig/coarse_dig_planner.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "runtime/planning/dig/region_material.h"

namespace autoshovel::planning {
namespace {

// Slack on the column count so that a sector exactly k widths wide gives k columns, not k + 1.
constexpr double kCountSlack = 1e-9;

}  // namespace

void Validate(const CoarseDigConfig& config) {
  const std::string what = "CoarseDigConfig";
  Validate(config.sector, what + ".sector");
  auto fail = [&](const std::string& field, const std::string& rule, double value) {
    throw std::invalid_argument(what + "." + field + ": " + rule + ", got " +
                                std::to_string(value));
  };
  if (!(std::isfinite(config.region_swing_width) && config.region_swing_width > 0)) {
    fail("region_swing_width", "must be finite and > 0 rad", config.region_swing_width);
  }
  if (!(std::isfinite(config.region_height) && config.region_height > 0)) {
    fail("region_height", "must be finite and > 0 m", config.region_height);
  }
  if (!(std::isfinite(config.min_material_thickness) && config.min_material_thickness >= 0 &&
        config.min_material_thickness < config.region_height)) {
    fail("min_material_thickness", "must be finite, >= 0 m and < region_height",
         config.min_material_thickness);
  }
  if (!(std::isfinite(config.min_region_volume) && config.min_region_volume >= 0)) {
    fail("min_region_volume", "must be finite and >= 0 m^3", config.min_region_volume);
  }
  if (config.order != DigRegionOrder::kTopDownThenLeftToRight &&
      config.order != DigRegionOrder::kLeftToRightThenTopDown) {
    fail("order", "must be a DigRegionOrder", static_cast<double>(config.order));
  }
}

CoarseDigPlanner::CoarseDigPlanner(const CoarseDigConfig& config) : config_(config) {
  Validate(config_);
  const double range = config_.sector.swing_max - config_.sector.swing_min;
  columns_ =
      std::max(1, static_cast<int>(std::ceil(range / config_.region_swing_width - kCountSlack)));
  column_width_ = range / columns_;
}

DigRegion CoarseDigPlanner::Region(int column, int band) const {
  if (column < 0 || column >= columns_ || band < 0) {
    throw std::invalid_argument("CoarseDigPlanner::Region: column must be in [0, " +
                                std::to_string(columns_) + ") and band >= 0, got " +
                                std::to_string(column) + ", " + std::to_string(band));
  }
  const DigSector& s = config_.sector;
  DigRegion region;
  region.column = column;
  region.band = band;
  // Column 0 is the leftmost: the largest swings, on the truck's side.
  region.swing_max = s.swing_max - column * column_width_;
  region.swing_min = column + 1 == columns_ ? s.swing_min : region.swing_max - column_width_;
  region.radius_min = s.radius_min;
  region.radius_max = s.radius_max;
  region.z_min = s.floor_height + band * config_.region_height;
  region.z_max = region.z_min + config_.region_height;
  return region;
}

int CoarseDigPlanner::BandCount(const control::HeightGrid& map_base) const {
  const DigSector& s = config_.sector;
  double top = s.floor_height;
  ForEachCellInPolarBox(map_base, s.swing_min, s.swing_max, s.radius_min, s.radius_max,
                        [&](int, int, double height) {
                          if (std::isfinite(height)) top = std::max(top, height);
                        });
  return static_cast<int>(std::ceil((top - s.floor_height) / config_.region_height));
}

std::vector<DigRegion> CoarseDigPlanner::RegionsWithMaterial(
    const control::HeightGrid& map_base) const {
  const int bands = BandCount(map_base);
  std::vector<DigRegion> out;
  auto consider = [&](int column, int band) {
    DigRegion region = Region(column, band);
    const RegionMaterial material =
        MeasureMaterial(map_base, region, config_.min_material_thickness);
    region.volume = material.volume;
    region.top_height = material.top_height;
    region.known_cells = material.known_cells;
    region.unknown_cells = material.unknown_cells;
    if (material.volume > 0 && material.volume >= config_.min_region_volume) {
      out.push_back(region);
    }
  };
  if (config_.order == DigRegionOrder::kTopDownThenLeftToRight) {
    for (int band = bands - 1; band >= 0; --band) {
      for (int column = 0; column < columns_; ++column) consider(column, band);
    }
  } else {
    for (int column = 0; column < columns_; ++column) {
      for (int band = bands - 1; band >= 0; --band) consider(column, band);
    }
  }
  return out;
}

std::optional<DigRegion> CoarseDigPlanner::NextRegion(const control::HeightGrid& map_base) const {
  for (const DigRegion& region : RegionsWithMaterial(map_base)) {
    if (!IsExhausted(region)) return region;
  }
  return std::nullopt;
}

void CoarseDigPlanner::MarkExhausted(const DigRegion& region) {
  if (!IsExhausted(region)) exhausted_.push_back(region);
}

bool CoarseDigPlanner::IsExhausted(const DigRegion& region) const {
  return std::any_of(exhausted_.begin(), exhausted_.end(),
                     [&](const DigRegion& r) { return SameRegion(r, region); });
}

}  // namespace autoshovel::planning
