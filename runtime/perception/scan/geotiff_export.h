// The map of a scan as a float GeoTIFF (issue 43), for QGIS and other GIS tools: band 1 the
// height above the floor (or above the reference scan) [m], band 2 its standard deviation [m],
// band 3 1 where Eq. (9) filled the cell; NaN where nothing is known (the nodata value). The
// coordinates are the floor frame's (metres, x east-like, y north-like as `map --cloud` draws
// them) with a local engineering CRS: a scan carries no geographic position.
#pragma once

#include <string>

#include "runtime/perception/grid_map.h"

namespace autoshovel::perception {

/// Throws core::OutputError naming the path when GDAL cannot create or write the file.
void WriteGeoTiff(const std::string& path, const GridMap& map);

}  // namespace autoshovel::perception
