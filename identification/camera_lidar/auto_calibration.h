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
#include <optional>
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
  /// A start 3° off lies outside the basin Nelder–Mead's 1° simplex can see (the score is
  /// flat or multimodal there on real scenes), so a coarse search comes first: rounds of
  /// `coarse_samples` random poses (a fixed seed: runs repeat) within ±range of the best so far,
  /// the range shrinking by `coarse_shrink` per round from `coarse_rotation` / `coarse_translation`
  /// until the rotation range is below `coarse_min_rotation`; the start is always a candidate, so
  /// the search never ends worse than it began, and the sampling is symmetric about the current
  /// best, so the result does not depend on the sign of the start's error. 0 samples: off (the
  /// seed's plain Nelder–Mead). CalibAnything searches the same way, without the simplex after.
  int coarse_samples = 100;
  double coarse_rotation = 0.07;       ///< first round's half range [rad] (4°)
  double coarse_translation = 0.12;    ///< [m]
  double coarse_shrink = 0.6;          ///< range factor per round [-]
  double coarse_min_rotation = 0.005;  ///< last round's half range [rad] (0.3°)
  unsigned coarse_seed = 1;
  int coarse_first_round_factor = 4;  ///< the first round samples this many times more [-]
  int coarse_candidates = 3;          ///< poses kept after the first round and refined [-]
  /// Rotation before translation, and translation only where the scene supports it (our
  /// departure, docs/camera_lidar_calibration.md). On real scenes most structure is far: a
  /// rotation moves every point by f·δθ, a translation only near ones by f·δt/Z, so ρ is sharp
  /// in rotation and nearly flat in translation, and a free 6-DOF search drifts along the flat
  /// directions (tens of centimetres on the CalibAnything scenes). With `staged`: (1) coarse
  /// search and Nelder–Mead over rotation, translation held; (2) the same over all six, from
  /// there; (3) the result of (2) is kept only when its gain over (1) is at least
  /// `translation_significance` standard errors over the masks (CompareScores); else a local
  /// Nelder–Mead over all six from (1) (half the seed's simplex) is the result, so that
  /// translation moves only within its own basin, not across a flat score.
  bool staged = true;
  double translation_significance = 2.0;
};

struct AutoCalibrationResult {
  Eigen::Isometry3d T_lidar_camera = Eigen::Isometry3d::Identity();
  ScoreBreakdown initial, final;
  int evaluations = 0;
  int runs = 0;                 ///< Nelder–Mead runs (1 + restarts)
  int coarse_rounds = 0;        ///< rounds of the coarse search
  ScoreBreakdown after_coarse;  ///< the score where the coarse search ended
  /// `staged`: the rotation stage's result, and the translation stage's gain over it.
  Eigen::Isometry3d T_rotation_stage = Eigen::Isometry3d::Identity();
  ScoreGain translation_gain;
  bool translation_kept = true;
  double seconds = 0;
};

/// How masks are prepared for the score (our departures, docs/camera_lidar_calibration.md).
struct MaskPreparationOptions {
  /// Masks covering at least this share of the image keep only a band inside their boundary,
  /// `edge_band_base` + W·H/area px wide (the rule of CalibAnything's mask preprocessing): the
  /// interior of a large mask (road, sky, a wall) holds most of its points but moves with no
  /// small pose change, so it only dilutes the score's sensitivity to the edges. 0: off.
  double edge_band_min_fraction = 0;
  double edge_band_base = 30;  ///< [px]
};

/// Prepares one frame: undistorts the masks, computes normals and segment classes (PCL),
/// the cloud's reflectivity variance. `up_lidar`: gravity up in the LiDAR frame (nominal), when
/// known (a machine's description); without it the cloud is segmented without an up axis.
/// `max_points` > 0 subsamples the cloud first (deterministic), bounding memory and time.
ScoreFrame PrepareScoreFrame(const sensors::PointCloud& cloud, const MaskSet& masks,
                             const CameraIntrinsics& intrinsics,
                             const std::optional<Eigen::Vector3d>& up_lidar,
                             std::size_t max_points = 0, const CloudFeatureOptions& features = {},
                             const MaskPreparationOptions& mask_options = {});

AutoCalibrationResult AutoCalibrate(const std::vector<ScoreFrame>& frames,
                                    const Eigen::Isometry3d& T0,
                                    const AutoCalibrationOptions& options = {});

/// ρ along each parameter around T (the others held): the convergence basin (cf. seed Fig. 11).
struct ScoreSlice {
  std::string parameter;  ///< "rot_x" … "rot_z" [deg], "x" … "z" [m]
  std::vector<double> offsets;
  std::vector<double> rho;
  /// The terms at each offset (ScoreBreakdown's ω_i-weighted means): reflectivity F_R, normals
  /// F_N, classes F_S and the size factor f(|P_i|).
  std::vector<double> reflectivity, normal, segmentation, size;
};
std::vector<ScoreSlice> ScoreSurface(const std::vector<ScoreFrame>& frames,
                                     const Eigen::Isometry3d& T, const ScoreOptions& options,
                                     double rotation_half_range_deg = 3.0,
                                     double translation_half_range = 0.10, int steps = 13);

}  // namespace autoshovel::identification
