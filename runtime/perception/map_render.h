// Pictures of the semantic elevation map: the six layers of the wheel-loader seed's Fig. 5
// (elevation, variance, ground, pile and obstacle confidence, fused class) side by side in one
// PNG, north up, with the pile boundaries drawn on the class layer.
#pragma once

#include <string>
#include <vector>

#include "runtime/perception/grid_map.h"
#include "runtime/perception/pile_extraction.h"

namespace autoshovel::perception {

/// Writes the six layers (3 × 2 panels, `pixels_per_cell` each) to `png_path`. Throws
/// std::runtime_error if the file cannot be written.
void WriteSemanticMapPng(const GridMap& map, const std::vector<ExtractedPile>& piles,
                         const std::string& png_path, int pixels_per_cell = 3);

}  // namespace autoshovel::perception
