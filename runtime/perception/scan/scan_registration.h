// Registering a scan of the empty place onto a scan of the heap (issue 43, `map --cloud …
// --reference EMPTY`): the two are usually taken on different days, from a tripod set up again,
// so their frames differ by a few centimetres and degrees, which on a 30 m² bin floor is a
// volume error of cubic metres.
//
// Generalized ICP (Segal, Haehnel, Thrun, "Generalized-ICP", RSS 2009; PCL's implementation)
// aligns the reference (source) to the scan (target), both thinned on a voxel grid. The heap is
// in one scan and not the other: its points must not pull the reference up onto it. GICP is run
// in stages with a shrinking correspondence distance, from a coarse one that catches a tripod
// set up again down to a few voxels, so in the last stages only what both scans share (floor
// around the heap, walls, rim, surroundings) holds correspondences; the heap's points, farther
// than that from anything in the empty scan, are not matched.
//
// The result says how well the two agree: the share of the reference's points that have a scan
// point within the final distance (overlap) and their RMS distance. A reference that is not of
// the same place, or too far off to be caught, shows as a low overlap and is refused by the
// caller rather than differenced.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace autoshovel::perception {

struct ScanRegistrationOptions {
  double voxel = 0;           ///< thinning voxel edge [m]; 0: 0.4 % of the scene's extent, ≥ 2 mm
  double start_distance = 0;  ///< first correspondence distance [m]; 0: 8 % of the extent
  double final_distance = 0;  ///< last correspondence distance [m]; 0: 3 voxels
  int stages = 5;             ///< distances spaced geometrically from start to final
  int iterations_per_stage = 40;
};

struct ScanRegistration {
  /// Maps the source (reference) into the target (scan) frame: p_target = T · p_source.
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  double overlap = 0;  ///< share of source points within final_distance of the target [-]
  double rms = 0;      ///< RMS distance of those points [m]
  double final_distance = 0;
  double voxel = 0;
  /// How far the registration moved the source: rotation [rad] and translation [m].
  double rotation = 0, translation = 0;
};

/// `initial` places the source roughly (identity: the same scanner pose).
ScanRegistration RegisterScans(const std::vector<Eigen::Vector3d>& source,
                               const std::vector<Eigen::Vector3d>& target,
                               const Eigen::Isometry3d& initial = Eigen::Isometry3d::Identity(),
                               const ScanRegistrationOptions& options = {});

}  // namespace autoshovel::perception
