#include "identification/camera_lidar/auto_calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlopt.hpp>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>

#include "identification/camera_lidar/depth_edges.h"

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

// MaskPreparationOptions: large masks keep a band inside their boundary.
void TrimToEdgeBands(MaskSet& set, const MaskPreparationOptions& options) {
  const double image_area = static_cast<double>(set.width) * set.height;
  for (cv::Mat& mask : set.masks) {
    const double area = cv::countNonZero(mask);
    if (area < options.edge_band_min_fraction * image_area || area <= 0) continue;
    const double margin = options.edge_band_base + image_area / area;
    cv::Mat distance;
    cv::distanceTransform(mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    mask.setTo(0, distance > margin);
  }
}

// Distance to the nearest boundary of any mask (ScoreFrame::boundary_distance) [px].
cv::Mat BoundaryDistance(const MaskSet& set) {
  cv::Mat boundary(set.height, set.width, CV_8U, cv::Scalar(0));
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  for (const cv::Mat& mask : set.masks) {
    cv::Mat gradient;
    cv::morphologyEx(mask, gradient, cv::MORPH_GRADIENT, kernel);
    boundary |= gradient;
  }
  cv::Mat distance;
  cv::distanceTransform(boundary == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance;
}

// Up to four masks per pixel, smallest first (ScoreFrame::mask_layers).
cv::Mat MaskLayers(const MaskSet& set) {
  cv::Mat layers(set.height, set.width, CV_32SC4, cv::Scalar(0, 0, 0, 0));
  std::vector<std::size_t> order(set.masks.size());
  std::vector<int> area(set.masks.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
    area[i] = cv::countNonZero(set.masks[i]);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return area[a] < area[b]; });
  for (const std::size_t k : order) {
    const cv::Mat& mask = set.masks[k];
    for (int v = 0; v < set.height; ++v) {
      const std::uint8_t* in = mask.ptr<std::uint8_t>(v);
      cv::Vec4i* out = layers.ptr<cv::Vec4i>(v);
      for (int u = 0; u < set.width; ++u) {
        if (in[u] == 0) continue;
        for (int c = 0; c < 4; ++c) {
          if (out[u][c] == 0) {
            out[u][c] = static_cast<int>(k) + 1;
            break;
          }
        }
      }
    }
  }
  return layers;
}

}  // namespace

ScoreFrame PrepareScoreFrame(const sensors::PointCloud& cloud, const MaskSet& masks,
                             const CameraIntrinsics& intrinsics,
                             const std::optional<Eigen::Vector3d>& up_lidar, std::size_t max_points,
                             const CloudFeatureOptions& feature_options,
                             const MaskPreparationOptions& mask_options) {
  ScoreFrame frame;
  frame.K = intrinsics.K.cast<float>();
  MaskSet undistorted = UndistortMasks(masks, intrinsics);
  frame.boundary_distance = BoundaryDistance(undistorted);
  if (mask_options.edge_band_min_fraction > 0) TrimToEdgeBands(undistorted, mask_options);
  frame.mask_layers = MaskLayers(undistorted);
  for (const cv::Mat& mask : undistorted.masks) {
    frame.mask_full_area.push_back(cv::countNonZero(mask));
  }
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
  {
    const DepthEdges edges = FindDepthEdges(frame.points);
    for (std::size_t i = 0; i < edges.weight.size(); ++i) {
      if (edges.weight[i] <= 0) continue;
      frame.edge_weight.push_back(edges.weight[i]);
      frame.edge_points.push_back(edges.silhouette[i]);
    }
  }
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

// AutoCalibrationOptions::coarse_samples: shrinking random search, from half ranges `rotation`
// [rad] and `translation` [m], for `rounds` rounds. The first round samples
// `coarse_first_round_factor` times as many poses around the start and keeps the best
// `coarse_candidates` (the start among them); each candidate is then refined on its own, and the
// best at the end wins: one sample landing on a spurious maximum in the first round can no
// longer pull the whole search away from a basin another sample found.
Eigen::Isometry3d CoarseSearch(const std::vector<ScoreFrame>& frames, const Eigen::Isometry3d& T0,
                               const AutoCalibrationOptions& options, double rotation,
                               double translation, int rounds, AutoCalibrationResult& result) {
  std::mt19937_64 rng(options.coarse_seed + static_cast<unsigned>(result.coarse_rounds));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const bool rotate = options.lock != Lock::kRotation;
  const bool translate = options.lock != Lock::kTranslation;
  auto sample = [&](const Eigen::Isometry3d& centre, double r, double t) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (rotate) w[i] = r * unit(rng);
      if (translate) v[i] = t * unit(rng);
    }
    return Perturb(centre, w, v);
  };
  auto score = [&](const Eigen::Isometry3d& T) {
    ++result.evaluations;
    return ConsistencyScore(frames, T, options.score).rho;
  };
  if (rounds <= 0) return T0;
  // Round 1: many samples, the best few kept.
  std::vector<std::pair<double, Eigen::Isometry3d>> pool{{score(T0), T0}};
  const int first = options.coarse_samples * std::max(1, options.coarse_first_round_factor);
  for (int k = 0; k < first; ++k) {
    const Eigen::Isometry3d T = sample(T0, rotation, translation);
    pool.emplace_back(score(T), T);
  }
  const std::size_t keep =
      std::min(pool.size(), static_cast<std::size_t>(std::max(1, options.coarse_candidates)));
  std::partial_sort(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(keep), pool.end(),
                    [](const auto& a, const auto& b) { return a.first > b.first; });
  pool.resize(keep);
  ++result.coarse_rounds;
  // Later rounds: each candidate refined around itself.
  for (int round = 1; round < rounds; ++round) {
    rotation *= options.coarse_shrink;
    translation *= options.coarse_shrink;
    for (auto& [best_value, best] : pool) {
      const Eigen::Isometry3d centre = best;
      for (int k = 0; k < options.coarse_samples; ++k) {
        const Eigen::Isometry3d T = sample(centre, rotation, translation);
        const double value = score(T);
        if (value > best_value) {
          best_value = value;
          best = T;
        }
      }
    }
    ++result.coarse_rounds;
  }
  return std::max_element(pool.begin(), pool.end(),
                          [](const auto& a, const auto& b) { return a.first < b.first; })
      ->second;
}

// Rounds from coarse_rotation down to coarse_min_rotation.
int CoarseRounds(const AutoCalibrationOptions& options) {
  if (options.coarse_samples <= 0 || !(options.coarse_shrink > 0 && options.coarse_shrink < 1) ||
      !(options.coarse_rotation >= options.coarse_min_rotation)) {
    return 0;
  }
  return 1 + static_cast<int>(
                 std::floor(std::log(options.coarse_min_rotation / options.coarse_rotation) /
                            std::log(options.coarse_shrink)));
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
  const int rounds = CoarseRounds(options);
  if (options.staged && options.lock == Lock::kNone) {
    // (1) Rotation, translation held.
    AutoCalibrationOptions rotation = options;
    rotation.lock = Lock::kTranslation;
    T = CoarseSearch(frames, T, rotation, options.coarse_rotation, 0.0, rounds, result);
    T = Optimise(frames, T, Lock::kTranslation, 1.0, rotation, result);
    result.T_rotation_stage = T;
    result.after_coarse = ConsistencyScore(frames, T, options.score);
    // (2) All six from there: translation over its whole range, rotation only finely.
    Eigen::Isometry3d T_full = CoarseSearch(frames, T, options, 2 * options.coarse_min_rotation,
                                            options.coarse_translation, rounds, result);
    T_full = Optimise(frames, T_full, Lock::kNone, options.second_stage_scale, options, result);
    // (3) Kept only where the scene carries the gain.
    result.translation_gain =
        CompareScores(result.after_coarse, ConsistencyScore(frames, T_full, options.score));
    result.translation_kept =
        result.translation_gain.gain >
        options.translation_significance * result.translation_gain.standard_error;
    // Not carried: a local refinement of all six from the rotation stage instead (the seed's
    // Nelder–Mead simplex, 1° and 4 cm), so translation moves only as far as its own basin.
    result.T_lidar_camera =
        result.translation_kept
            ? T_full
            : Optimise(frames, T, Lock::kNone, options.second_stage_scale, options, result);
    result.final = ConsistencyScore(frames, result.T_lidar_camera, options.score);
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  }
  if (rounds > 0) {
    T = CoarseSearch(frames, T0, options, options.coarse_rotation, options.coarse_translation,
                     rounds, result);
  }
  result.after_coarse = ConsistencyScore(frames, T, options.score);
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
      const ScoreBreakdown b = ConsistencyScore(frames, Perturb(T, w, t), options);
      slice.rho.push_back(b.rho);
      slice.reflectivity.push_back(b.reflectivity);
      slice.normal.push_back(b.normal);
      slice.segmentation.push_back(b.segmentation);
      slice.size.push_back(b.size);
    }
    slices.push_back(slice);
  }
  return slices;
}

}  // namespace autoshovel::identification
