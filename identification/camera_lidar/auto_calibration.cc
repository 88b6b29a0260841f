#include "identification/camera_lidar/auto_calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlopt.hpp>
#include <numbers>
#include <random>

namespace autoshovel::identification {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

struct Problem {
  const std::vector<ScoreFrame>* frames;
  Eigen::Isometry3d T0;
  const AutoCalibrationOptions* options;
  int evaluations = 0;

  Eigen::Isometry3d Pose(const std::vector<double>& x) const {
    Eigen::Vector3d w = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
    switch (options->lock) {
      case Lock::kNone:
        w << x[0], x[1], x[2];
        t << x[3], x[4], x[5];
        break;
      case Lock::kRotation:
        t << x[0], x[1], x[2];
        break;
      case Lock::kTranslation:
        w << x[0], x[1], x[2];
        break;
    }
    return Perturb(T0, w, t);
  }
};

}  // namespace

ScoreFrame PrepareScoreFrame(const sensors::PointCloud& cloud, const MaskSet& masks,
                             const CameraIntrinsics& intrinsics, const Eigen::Vector3d& up_lidar,
                             std::size_t max_points, const CloudFeatureOptions& feature_options) {
  ScoreFrame frame;
  frame.K = intrinsics.K.cast<float>();
  const MaskSet undistorted = UndistortMasks(masks, intrinsics);
  frame.mask_labels = MaskLabelImage(undistorted);
  frame.num_masks = static_cast<int>(undistorted.masks.size());
  frame.mask_area.assign(frame.num_masks, 0.0);
  for (int v = 0; v < frame.mask_labels.rows; ++v) {
    for (int u = 0; u < frame.mask_labels.cols; ++u) {
      const int label = frame.mask_labels.at<int>(v, u);
      if (label > 0) frame.mask_area[label - 1] += 1;
    }
  }
  std::vector<std::size_t> keep(cloud.points.size());
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = i;
  if (max_points > 0 && keep.size() > max_points) {
    std::mt19937_64 rng(7);
    std::shuffle(keep.begin(), keep.end(), rng);
    keep.resize(max_points);
    std::sort(keep.begin(), keep.end());
  }
  double sum = 0, sum2 = 0;
  for (const std::size_t i : keep) {
    frame.points.push_back(cloud.points[i].p_sensor);
    frame.reflectivity.push_back(cloud.points[i].intensity);
    sum += cloud.points[i].intensity;
    sum2 += static_cast<double>(cloud.points[i].intensity) * cloud.points[i].intensity;
  }
  const double n = std::max<double>(1, static_cast<double>(keep.size()));
  frame.reflectivity_variance = std::max(1e-12, sum2 / n - (sum / n) * (sum / n));
  const CloudFeatures features = ComputeCloudFeatures(frame.points, up_lidar, feature_options);
  frame.normals = features.normals;
  frame.segment = features.segment;
  frame.num_segments = features.num_segments;
  frame.ground_noise = features.ground_noise;
  frame.ground_smoothing_neighbours = features.ground_smoothing_neighbours;
  return frame;
}

namespace {

// Nelder–Mead from T0 with `lock`, restarted with a fresh simplex (scaled by restart_scale)
// until a restart no longer improves ρ; returns the best pose, adds to the counters.
Eigen::Isometry3d Optimise(const std::vector<ScoreFrame>& frames, const Eigen::Isometry3d& T0,
                           Lock lock, double step_scale, const AutoCalibrationOptions& options,
                           AutoCalibrationResult& result) {
  AutoCalibrationOptions local = options;
  local.lock = lock;
  Problem problem{&frames, T0, &local};
  const unsigned dimension = lock == Lock::kNone ? 6 : 3;
  std::vector<double> x(dimension, 0.0), steps(dimension);
  for (unsigned k = 0; k < dimension; ++k) {
    const bool rotation = lock == Lock::kTranslation || (lock == Lock::kNone && k < 3);
    steps[k] = step_scale * (rotation ? options.rotation_step : options.translation_step);
  }
  auto objective = [](const std::vector<double>& v, std::vector<double>&, void* data) {
    auto* p = static_cast<Problem*>(data);
    ++p->evaluations;
    return ConsistencyScore(*p->frames, p->Pose(v), p->options->score).rho;
  };
  double best = ConsistencyScore(frames, T0, options.score).rho;
  ++problem.evaluations;
  for (int run = 0; run <= options.max_restarts; ++run) {
    nlopt::opt opt(nlopt::LN_NELDERMEAD, dimension);
    opt.set_max_objective(objective, &problem);
    opt.set_initial_step(steps);
    opt.set_ftol_abs(options.ftol_abs);
    opt.set_xtol_abs(options.xtol_abs);
    opt.set_maxeval(options.max_evaluations);
    std::vector<double> trial = x;
    double value = best;
    try {
      opt.optimize(trial, value);
    } catch (const std::exception&) {
      // nlopt::roundoff_limited and friends: optimize() has already stored its best point in
      // `trial` and `value` before throwing.
    }
    ++result.runs;
    const bool improved = value > best + std::max(options.ftol_abs, options.restart_min_gain);
    if (value > best) {
      best = value;
      x = trial;
    }
    if (!improved && run > 0) break;
    for (double& s : steps) s *= options.restart_scale;
  }
  result.evaluations += problem.evaluations;
  return problem.Pose(x);
}

}  // namespace

AutoCalibrationResult AutoCalibrate(const std::vector<ScoreFrame>& input_frames,
                                    const Eigen::Isometry3d& T0,
                                    const AutoCalibrationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  AutoCalibrationResult result;
  // The sky term (consistency_score.h): masks without LiDAR support are flagged at T0, once, so
  // that ρ stays one function of x during the search; frames already flagged are kept as given.
  std::vector<ScoreFrame> marked;
  bool flagged = false;
  for (const ScoreFrame& f : input_frames) flagged = flagged || !f.unsupported.empty();
  if (options.unsupported_density > 0 && !flagged) {
    marked = input_frames;
    MarkUnsupportedMasks(marked, T0, options.unsupported_density);
  }
  const std::vector<ScoreFrame>& frames = marked.empty() ? input_frames : marked;
  result.initial = ConsistencyScore(frames, T0, options.score);
  Eigen::Isometry3d T = T0;
  if (options.rotation_first && options.lock == Lock::kNone) {
    T = Optimise(frames, T, Lock::kTranslation, 1.0, options, result);
    T = Optimise(frames, T, Lock::kNone, options.second_stage_scale, options, result);
  } else {
    T = Optimise(frames, T, options.lock, 1.0, options, result);
  }
  result.T_lidar_camera = T;
  result.final = ConsistencyScore(frames, result.T_lidar_camera, options.score);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<ScoreSlice> ScoreSurface(const std::vector<ScoreFrame>& frames,
                                     const Eigen::Isometry3d& T, const ScoreOptions& options,
                                     double rotation_half_range_deg, double translation_half_range,
                                     int steps) {
  const char* names[6] = {"rot_x", "rot_y", "rot_z", "x", "y", "z"};
  std::vector<ScoreSlice> slices;
  for (int k = 0; k < 6; ++k) {
    ScoreSlice slice;
    slice.parameter = names[k];
    const double half = k < 3 ? rotation_half_range_deg : translation_half_range;
    for (int i = 0; i < steps; ++i) {
      const double offset = -half + 2.0 * half * i / std::max(1, steps - 1);
      Eigen::Vector3d w = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
      if (k < 3) {
        w[k] = offset * kDeg;
      } else {
        t[k - 3] = offset;
      }
      slice.offsets.push_back(offset);
      slice.rho.push_back(ConsistencyScore(frames, Perturb(T, w, t), options).rho);
    }
    slices.push_back(slice);
  }
  return slices;
}

}  // namespace autoshovel::identification
