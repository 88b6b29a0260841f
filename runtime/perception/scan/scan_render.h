// Pictures of a scan's map a person can read (issue 43): one layer of the grid per PNG, cells
// drawn as squares (the picture at least `min_pixels` wide), x to the right and y up as seen
// from above, a colour bar with its values and unit, and a scale bar of a round length.
#pragma once

#include <string>

#include "runtime/perception/grid_map.h"

namespace autoshovel::perception {

struct LayerPicture {
  std::string layer;   ///< the grid layer drawn
  std::string title;   ///< above the map
  std::string unit;    ///< of the colour bar
  double scale = 1.0;  ///< values are multiplied by this before drawing (e.g. √ of a variance)
  bool square_root = false;  ///< draw √value (a variance as a standard deviation)
  bool categorical = false;  ///< integer labels (1, 2, …) in distinct colours, NaN blank
  int min_pixels = 800;
};

/// Throws core::OutputError when the file cannot be written.
void WriteLayerPng(const std::string& path, const GridMap& map, const LayerPicture& picture);

}  // namespace autoshovel::perception
