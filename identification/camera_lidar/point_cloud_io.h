// Point clouds as recorded LiDAR data comes: PCD (PCL's format, DATA ascii, binary or
// binary_compressed, fields x y z and optionally intensity) and KITTI-style .bin (float32
// x, y, z, intensity per point, 16 bytes, no header).
//
// Malformed files throw core::InputError naming the file and, for PCD, the line:
//   cloud.pcd:3:1: SIZE: has 3 values for 4 FIELDS (x y z intensity)
//   cloud.pcd:12:1: expected 4 values (x y z intensity), got 3
//   cloud.pcd:11:1: DATA: truncated: the header promises 100 points (1600 bytes), 1000 follow
//   cloud.bin: size 1234 bytes is not a multiple of 16 (float32 x, y, z, intensity per point)
//   cloud.bin: byte 36 (point 2, y): 1e+30 m is no LiDAR return (|y| > 10000 m): ...
// The header is checked here, line by line; the data is then decoded by pcl::io (PCDReader),
// which also handles binary_compressed (LZF). Points with a non-finite coordinate (an
// organised cloud's "no return") are dropped.
//
// Intensity is kept as the file gives it (Livox and Ouster drivers: 0–255; this project's
// simulator: 0–1). The consistency score is invariant to its scale (consistency_score.h).
#pragma once

#include <cstddef>
#include <string>

#include "runtime/sensors/sensor_data.h"

namespace autoshovel::identification {

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

/// The most points a cloud file may hold: 20 million, 76 frames of a 128-beam spinning LiDAR
/// (2048 x 128 points). pcl::io decodes a whole PCD before it can be sampled, at about 70 bytes
/// a point (1.4 GB here), so a PCD's POINTS (or WIDTH x HEIGHT) and a .bin's size / 16 are
/// checked against it before anything is decoded (docs/camera_lidar_calibration.md).
inline constexpr std::size_t kMaxCloudPoints = 20'000'000;

/// What a read found in the file, before sampling.
struct PointCloudReadStats {
  std::size_t points_in_file = 0;  ///< every point the file holds
  std::size_t non_finite = 0;      ///< dropped: a NaN or infinite x, y or z ("no return")
  std::size_t finite() const { return points_in_file - non_finite; }
};

/// Reads a .pcd or .bin (by extension). `max_points` > 0 bounds memory: a .bin is sampled while
/// it is read (reservoir sampling, fixed seed: deterministic), a PCD after decoding. Points with
/// a non-finite coordinate are dropped and counted in `stats`.
sensors::PointCloud ReadPointCloud(const std::string& path, std::size_t max_points = 0,
                                   PointCloudReadStats* stats = nullptr);

/// Writes x y z intensity (float32); throws std::runtime_error naming the path on failure.
void WritePcd(const std::string& path, const sensors::PointCloud& cloud, PcdEncoding encoding);
void WriteKittiBin(const std::string& path, const sensors::PointCloud& cloud);

}  // namespace autoshovel::identification
