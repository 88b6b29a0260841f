// The published robustness check of a camera–LiDAR calibration (CalibAnything's protocol, as
// rig_files.h defines its perturbation and error): from the reference perturbed by ±R per
// rotation axis (all 8 sign patterns) and by ±R with ±T per translation axis (8 more), plus once
// from the reference itself, run the auto-calibration and compare each result with the
// reference. `calibrate camera-lidar --protocol` prints the table, so that a user can see how
// well a recording constrains the extrinsic before trusting a calibration on it.
#pragma once

#include <Eigen/Geometry>
#include <iosfwd>
#include <vector>

#include "identification/camera_lidar/auto_calibration.h"
#include "identification/camera_lidar/rig_files.h"

namespace autoshovel::identification {

struct ProtocolRun {
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();  ///< the perturbation [deg]
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();      ///< [m]
  ProtocolError start, final;
  Eigen::Vector3d final_xyz_optical = Eigen::Vector3d::Zero();  ///< of T_ref · T_est⁻¹ [m]
  bool translation_kept = true;
  double seconds = 0;
};

struct ProtocolSummary {
  std::vector<ProtocolRun> runs;  ///< the 16 perturbed starts
  ProtocolRun at_reference;       ///< started at the reference
  int improved = 0;               ///< runs ending closer in both rotation and translation
  double median_rotation = 0, median_translation = 0, worst_rotation = 0, worst_translation = 0;
};

/// `frames` without sky flags (each run flags at its own start, as a single run does).
ProtocolSummary RunPerturbationProtocol(const std::vector<ScoreFrame>& frames,
                                        const Eigen::Isometry3d& T_ref_lidar_camera,
                                        const AutoCalibrationOptions& options, double rotation_deg,
                                        double translation_m);

void PrintProtocol(const ProtocolSummary& summary, std::ostream& out);

}  // namespace autoshovel::identification
