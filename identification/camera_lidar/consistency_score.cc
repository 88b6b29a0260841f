// Seed Eq. (6)–(7): ρ = Σ_i ω_i (ω_R F_R + ω_N F_N + ω_S F_S) f(|P_i|), ω_i = |P_i| / Σ_j |P_j|.
#include "identification/camera_lidar/consistency_score.h"

#include <algorithm>
#include <cmath>

#include "identification/camera_lidar/camera_model.h"

namespace autoshovel::identification {

ScoreBreakdown ConsistencyScore(const std::vector<ScoreFrame>& frames,
                                const Eigen::Isometry3d& T_lidar_camera,
                                const ScoreOptions& options) {
  struct Mask {
    long n = 0;
    double r = 0, r2 = 0;
    Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
    double f_r = 0, f_n = 0, f_s = 0, epsilon = 0;
  };
  const Eigen::Isometry3d T_optical_lidar = OpticalFromLidar(T_lidar_camera);
  const Eigen::Matrix3f R = T_optical_lidar.linear().cast<float>();
  const Eigen::Vector3f t = T_optical_lidar.translation().cast<float>();
  std::vector<Mask> all;
  std::vector<int> histogram;
  for (const ScoreFrame& frame : frames) {
    std::vector<Mask> masks(frame.num_masks);
    histogram.assign(static_cast<std::size_t>(frame.num_masks) * frame.num_segments, 0);
    const float fx = frame.K(0, 0), fy = frame.K(1, 1), cx = frame.K(0, 2), cy = frame.K(1, 2);
    const int width = frame.mask_labels.cols, height = frame.mask_labels.rows;
    for (std::size_t i = 0; i < frame.points.size(); ++i) {
      const Eigen::Vector3f p = R * frame.points[i] + t;  // Eq. (5)
      if (p.z() < 0.1f) continue;
      const int u = static_cast<int>(std::lround(fx * p.x() / p.z() + cx));
      const int v = static_cast<int>(std::lround(fy * p.y() / p.z() + cy));
      if (u < 0 || v < 0 || u >= width || v >= height) continue;
      const int label = frame.mask_labels.at<int>(v, u);
      if (label <= 0) continue;
      Mask& m = masks[label - 1];
      ++m.n;
      const double r = frame.reflectivity[i];
      m.r += r;
      m.r2 += r * r;
      m.normal_sum += frame.normals[i].cast<double>();
      ++histogram[static_cast<std::size_t>(label - 1) * frame.num_segments + frame.segment[i]];
    }
    const double log_classes = std::log(std::max(2, frame.num_segments));
    for (int k = 0; k < frame.num_masks; ++k) {
      Mask& m = masks[k];
      if (m.n < options.min_points) continue;  // Algorithm 1 line 16
      const double n = static_cast<double>(m.n);
      const double variance = std::max(0.0, m.r2 / n - (m.r / n) * (m.r / n));
      m.f_r = std::max(0.0, 1.0 - variance / std::max(frame.reflectivity_variance, 1e-12));
      m.f_n = (m.normal_sum.squaredNorm() - n) / (n * (n - 1.0));
      double entropy = 0;
      for (int c = 0; c < frame.num_segments; ++c) {
        const int count = histogram[static_cast<std::size_t>(k) * frame.num_segments + c];
        if (count > 0) entropy -= count / n * std::log(count / n);
      }
      m.f_s = 1.0 - entropy / log_classes;
      m.epsilon = (options.weight_reflectivity * m.f_r + options.weight_normal * m.f_n +
                   options.weight_segmentation * m.f_s) *
                  (n / (n + options.size_scale));  // Eq. (6)
      all.push_back(m);
    }
  }
  ScoreBreakdown out;
  for (const Mask& m : all) out.points_in_masks += m.n;
  if (out.points_in_masks == 0) return out;
  const double total = static_cast<double>(out.points_in_masks);
  for (const Mask& m : all) {
    const double w = m.n / total;  // Eq. (7)
    out.rho += w * m.epsilon;
    out.reflectivity += w * m.f_r;
    out.normal += w * m.f_n;
    out.segmentation += w * m.f_s;
  }
  out.masks_used = static_cast<int>(all.size());
  return out;
}

}  // namespace autoshovel::identification
