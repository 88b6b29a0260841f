#include "runtime/planning/dig/candidate_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "runtime/planning/dig/dig_geometry.h"

namespace autoshovel::planning {
namespace {

// Depths closer than this are the same cut [m].
constexpr double kSameDepth = 1e-9;

double Sample(double lo, double hi, int count, int k) {
  return count > 1 ? lo + (hi - lo) * k / (count - 1) : lo;
}

double SliceCentre(double lo, double hi, int count, int k) {
  return lo + (hi - lo) * (k + 0.5) / count;
}

}  // namespace

void Validate(const DigGridConfig& config, const std::string& what) {
  auto require = [&](bool ok, const std::string& field, const std::string& rule, double value) {
    if (!ok) {
      throw std::invalid_argument(what + "." + field + ": " + rule + ", got " +
                                  std::to_string(value));
    }
  };
  require(config.swing_samples >= 1, "swing_samples", "must be >= 1", config.swing_samples);
  require(std::isfinite(config.radius_step) && config.radius_step > 0, "radius_step",
          "must be finite and > 0 m", config.radius_step);
  require(std::isfinite(config.depth_min) && config.depth_min > 0, "depth_min",
          "must be finite and > 0 m", config.depth_min);
  require(std::isfinite(config.depth_max) && config.depth_max >= config.depth_min, "depth_max",
          "must be finite and >= depth_min", config.depth_max);
  require(config.depth_samples >= 1, "depth_samples", "must be >= 1", config.depth_samples);
  require(std::isfinite(config.drag_min) && config.drag_min > 0, "drag_min",
          "must be finite and > 0 m", config.drag_min);
  require(std::isfinite(config.drag_max) && config.drag_max >= config.drag_min, "drag_max",
          "must be finite and >= drag_min", config.drag_max);
  require(config.drag_samples >= 1, "drag_samples", "must be >= 1", config.drag_samples);
  require(std::isfinite(config.min_cut_depth) && config.min_cut_depth >= 0, "min_cut_depth",
          "must be finite and >= 0 m", config.min_cut_depth);
}

std::array<int, 4> DigGridExtent(const DigGridConfig& config, const DigRegion& region) {
  const int radii =
      1 + std::max(1, static_cast<int>(std::ceil(
                          (region.radius_max - region.radius_min) / config.radius_step - 1e-9)));
  return {config.swing_samples, radii, config.depth_samples, config.drag_samples};
}

std::vector<DigGridPoint> EnumerateDigGrid(const DigGridConfig& config, const DigRegion& region,
                                           const control::HeightGrid& map_base) {
  const std::array<int, 4> extent = DigGridExtent(config, region);
  std::vector<DigGridPoint> out;
  out.reserve(static_cast<std::size_t>(extent[0]) * extent[1] * extent[2] * extent[3]);
  for (int is = 0; is < extent[0]; ++is) {
    const double swing = SliceCentre(region.swing_min, region.swing_max, extent[0], is);
    for (int ir = 0; ir < extent[1]; ++ir) {
      const double radius = Sample(region.radius_min, region.radius_max, extent[1], ir);
      const Eigen::Vector3d p_base_entry = TipInBase(swing, radius, 0.0);
      const double surface = map_base.HeightAt(p_base_entry.x(), p_base_entry.y());
      const double deepest = surface - region.z_min;  // the cut may reach the band bottom
      double previous_depth = -1.0;
      for (int id = 0; id < extent[2]; ++id) {
        const double sample = Sample(config.depth_min, config.depth_max, extent[2], id);
        const double depth = std::min(sample, deepest);
        for (int il = 0; il < extent[3]; ++il) {
          DigGridPoint point;
          point.index = {is, ir, id, il};
          point.action.swing = swing;
          point.action.radius = radius;
          point.action.entry_height = surface;
          point.action.depth = depth;
          point.action.drag_length = Sample(config.drag_min, config.drag_max, extent[3], il);
          if (!std::isfinite(surface)) {
            point.rejection = DigGridRejection::kUnknownSurface;
            point.why = "unknown surface at the entry point";
          } else if (!(deepest > config.min_cut_depth)) {
            point.rejection = DigGridRejection::kNoMaterial;
            point.why = "surface " + std::to_string(surface) + " m is not " +
                        std::to_string(config.min_cut_depth) + " m above the band bottom " +
                        std::to_string(region.z_min) + " m";
          } else if (depth < config.min_cut_depth) {
            point.rejection = DigGridRejection::kNoMaterial;
            point.why = "cut " + std::to_string(depth) + " m is shallower than min_cut_depth";
          } else if (std::abs(depth - previous_depth) <= kSameDepth) {
            point.rejection = DigGridRejection::kRepeatedCut;
            point.why = "depth sample " + std::to_string(sample) +
                        " m clipped to the band bottom repeats a shallower sample";
          }
          out.push_back(std::move(point));
        }
        previous_depth = depth;
      }
    }
  }
  return out;
}

}  // namespace autoshovel::planning
