// PLY point clouds (Stanford Triangle Format; what CloudCompare, Open3D and MeshLab export), as
// a user's own scans come (issue 43): `format ascii`, `binary_little_endian` or
// `binary_big_endian` 1.0; the first element must be `vertex`, with x, y, z of any numeric type
// (char … double, or int8 … float64) and any other scalar properties, of which `intensity`,
// `scalar_intensity` or `reflectivity` is kept as the intensity; list properties are refused in
// the vertex element; elements after it (faces) are ignored.
//
// Refusals are core::InputError naming the file and the header or ASCII line, or the byte
// offset in binary data, e.g.
//   scan.ply:3:1: element vertex: count 'many' is not a number
//   scan.ply: binary data: the header promises 1000 vertices (12000 bytes), 8000 follow
// A header promising more than kMaxCloudPoints vertices is refused before anything is read.
#pragma once

#include <cstddef>
#include <string>

#include "identification/camera_lidar/point_cloud_io.h"

namespace autoshovel::identification {

/// Reads a .ply; non-finite points are dropped and counted in `stats` (as ReadPointCloud).
sensors::PointCloud ReadPly(const std::string& path, PointCloudReadStats& stats);

/// Writes x y z intensity as binary little-endian float32 (the map's cell centres, for
/// CloudCompare). Throws core::OutputError.
void WritePly(const std::string& path, const sensors::PointCloud& cloud);

}  // namespace autoshovel::identification
