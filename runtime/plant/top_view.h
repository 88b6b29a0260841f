// A top-view picture of a world, for looking at scenarios: hillshaded heights coloured by
// material (bare floor grey), obstacles as outlined boxes coloured by semantic class, a scale bar,
// a material legend, and optionally the loader's start pose as an arrow. North is up.
#pragma once

#include <optional>
#include <string>

#include "runtime/plant/scenario.h"
#include "runtime/plant/world.h"

namespace autoshovel::plant {

struct TopViewOptions {
  double metres_per_pixel = 0.1;   ///< image size = yard size / this (rounded up)
  std::optional<StartPose> start;  ///< drawn as an arrow when given
};

/// Writes a PNG to `png_path`. Throws std::runtime_error if the file cannot be written.
void WriteTopView(const World& world, const std::string& png_path,
                  const TopViewOptions& options = {});

}  // namespace autoshovel::plant
