// Step 2 of Algorithm 1 (seed §3.2): the extrinsic that maximises the consistency score ρ of
// Eq. (7) (consistency_score.h), by Nelder–Mead from the board calibration's T0.
//
// Variables: x = (ω, t), T_lidar_camera(x) = Perturb(T0, ω, t): a rotation vector ω [rad] applied
// in the LiDAR frame and a translation t [m] added, 6 DOF or 3 when rotation or translation is
// locked. Initial simplex: `rotation_step` and `translation_step` along each axis.
//
// Stopping rule. The seed stops when the standard deviation of the simplex's values is below
// 1e-10 and its longest edge below 1e-8. NLopt's LN_NELDERMEAD stops at the *first* of its own
// criteria: ftol_abs (the spread max − min of the simplex values, ≥ their standard deviation)
// and xtol_abs (per coordinate, the distance of the simplex vertices), so ftol_abs = 1e-10 and
// xtol_abs = 1e-8 reproduce each condition. Because ρ is piecewise constant in x (a point
// changes masks at a pixel boundary), the f-spread criterion can fire while the simplex is still
// large, lying on one plateau; the optimisation is therefore restarted from its best point with a
// fresh simplex of half the previous size until a restart no longer improves ρ (or
// `max_restarts`), which approximates the seed's conjunction of both conditions.
// `max_evaluations` bounds each run. With the area lookup (consistency_score.h) ρ is continuous,
// so nearly every restart gains something: a restart gaining less than `restart_min_gain`
// (1e-5 of ρ ≈ 0.9; the seed's 1e-10 gave 4–7 runs and twice the evaluations for < 0.1 mm)
// ends the loop. `rotation_first` (3-DOF rotation run, then 6 DOF) is available, measured no
// better: every start already reaches the same maximum.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/cloud_features.h"
#include "identification/camera_lidar/consistency_score.h"
#include "identification/camera_lidar/mask_io.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::identification {

enum class Lock { kNone, kRotation, kTranslation };

struct AutoCalibrationOptions {
  ScoreOptions score;
  Lock lock = Lock::kNone;
  double rotation_step = 0.0175;   ///< initial simplex, per axis [rad] (1°)
  double translation_step = 0.04;  ///< [m]
  double ftol_abs = 1e-10;         ///< seed: std of simplex values < 1e-10
  double xtol_abs = 1e-8;          ///< seed: longest simplex edge < 1e-8
  int max_evaluations = 4000;      ///< per Nelder–Mead run
  int max_restarts = 6;
  double restart_scale = 0.5;        ///< simplex size of each restart against the previous
  double restart_min_gain = 1e-5;    ///< a restart gaining less than this ends the optimisation
  bool rotation_first = false;       ///< 3-DOF rotation run first, then 6 DOF
  double second_stage_scale = 0.5;   ///< simplex of the 6-DOF stage after rotation_first
  double unsupported_density = 0.1;  ///< > 0: MarkUnsupportedMasks at T0 with this fraction
};

struct AutoCalibrationResult {
  Eigen::Isometry3d T_lidar_camera = Eigen::Isometry3d::Identity();
  ScoreBreakdown initial, final;
  int evaluations = 0;
  int runs = 0;  ///< Nelder–Mead runs (1 + restarts)
  double seconds = 0;
};

/// Prepares one frame: undistorts the masks, computes normals and segment classes (PCL),
/// the cloud's reflectivity variance. `up_lidar`: gravity up in the LiDAR frame (nominal).
/// `max_points` > 0 subsamples the cloud first (deterministic), bounding memory and time.
ScoreFrame PrepareScoreFrame(const sensors::PointCloud& cloud, const MaskSet& masks,
                             const CameraIntrinsics& intrinsics, const Eigen::Vector3d& up_lidar,
                             std::size_t max_points = 0, const CloudFeatureOptions& features = {});

AutoCalibrationResult AutoCalibrate(const std::vector<ScoreFrame>& frames,
                                    const Eigen::Isometry3d& T0,
                                    const AutoCalibrationOptions& options = {});

/// ρ along each parameter around T (the others held): the convergence basin (cf. seed Fig. 11).
struct ScoreSlice {
  std::string parameter;  ///< "rot_x" … "rot_z" [deg], "x" … "z" [m]
  std::vector<double> offsets;
  std::vector<double> rho;
};
std::vector<ScoreSlice> ScoreSurface(const std::vector<ScoreFrame>& frames,
                                     const Eigen::Isometry3d& T, const ScoreOptions& options,
                                     double rotation_half_range_deg = 3.0,
                                     double translation_half_range = 0.10, int steps = 13);

}  // namespace autoshovel::identification
