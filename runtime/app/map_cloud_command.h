// `autoshovel map --cloud FILE…`: a user's own scans (PCD in any encoding and with any extra
// fields, KITTI .bin) into the elevation map, the floor found from the data, the heaps on it
// and their volumes with an uncertainty, as a table, a CSV and pictures (issue 43;
// runtime/perception/scan/scan_map.h).
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

namespace autoshovel::app {

struct MapCloudOptions {
  std::vector<std::string> clouds;
  /// Per cloud, optionally: x y z [m] roll pitch yaw [deg] of the scanner in the first cloud's
  /// frame, R = Rz(yaw) Ry(pitch) Rx(roll); all clouds or none (6 values each).
  std::vector<double> poses;
  std::string poses_file;  ///< or a poses file (scan_poses.h): a line per cloud, by file name
  /// Scans of the same place empty, in the first cloud's frame (the scanner not moved) or, with
  /// `register_reference`, registered onto the scans: heaps are measured above them instead of
  /// above the floor plane.
  std::vector<std::string> references;
  bool register_reference = false;
  /// The floor a x + b y + c z = d in the first cloud's frame (4 values), when the scan does not
  /// show it.
  std::vector<double> floor;
  double cell = 0;                  ///< [m]; 0: from the data
  std::vector<double> up;           ///< gravity up in the first cloud's frame (3 values), if known
  double alpha_d = 4e-6;            ///< σp² = α_d d²
  double min_heap_height = 0;       ///< [m]; 0: from the floor's noise
  std::string output = "scan_map";  ///< folder for heaps.csv and the PNGs
  std::size_t max_points = 20'000'000;
};

int RunMapCloud(const MapCloudOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
