// The dump planner's bed height map as a picture (top view, colour from the floor to the rim).
#pragma once

#include <filesystem>

#include "runtime/planning/dump/bed_height_map.h"

namespace autoshovel::app {

/// Top view of `map`, 24 px per cell, the cab end at the top: colour from the floor (blue) to
/// `rim` above it (red), grey where the map has no data; the title gives the fill's mean and
/// spread. Throws core::OutputError when the file cannot be written.
void WriteBedHeightPng(const planning::BedHeightMap& map, double rim,
                       const std::filesystem::path& path);

}  // namespace autoshovel::app
