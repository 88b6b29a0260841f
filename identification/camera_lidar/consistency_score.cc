// Seed Eq. (6)–(7): ρ = Σ_i ω_i (ω_R F_R + ω_N F_N + ω_S F_S) f(|P_i|), ω_i = |P_i| / Σ_j |P_j|.
#include "identification/camera_lidar/consistency_score.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "identification/camera_lidar/camera_model.h"

namespace autoshovel::identification {

ScoreBreakdown ConsistencyScore(const std::vector<ScoreFrame>& frames,
                                const Eigen::Isometry3d& T_lidar_camera,
                                const ScoreOptions& options) {
  struct Mask {
    int frame = 0, index = 0;
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
  long skipped = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const ScoreFrame& frame = frames[f];
    std::vector<Mask> masks(frame.num_masks);
    histogram.assign(static_cast<std::size_t>(frame.num_masks) * frame.num_segments, 0);
    const float fx = frame.K(0, 0), fy = frame.K(1, 1), cx = frame.K(0, 2), cy = frame.K(1, 2);
    const int width = frame.mask_labels.cols, height = frame.mask_labels.rows;
    const int radius = options.zbuffer_block;
    std::vector<int> pixel(frame.points.size(), -1);
    std::vector<float> depth(frame.points.size(), 0.f);
    std::vector<float> nearest(radius > 0 ? static_cast<std::size_t>(width) * height : 0,
                               std::numeric_limits<float>::infinity());
    for (std::size_t i = 0; i < frame.points.size(); ++i) {
      const Eigen::Vector3f p = R * frame.points[i] + t;  // Eq. (5)
      if (p.z() < 0.1f) continue;
      const int u = static_cast<int>(std::lround(fx * p.x() / p.z() + cx));
      const int v = static_cast<int>(std::lround(fy * p.y() / p.z() + cy));
      if (u < 0 || v < 0 || u >= width || v >= height) continue;
      pixel[i] = v * width + u;
      depth[i] = p.z();
      if (radius > 0) {
        for (int y = std::max(0, v - radius); y <= std::min(height - 1, v + radius); ++y) {
          float* row = &nearest[static_cast<std::size_t>(y) * width];
          for (int x = std::max(0, u - radius); x <= std::min(width - 1, u + radius); ++x) {
            row[x] = std::min(row[x], p.z());
          }
        }
      }
    }
    for (std::size_t i = 0; i < frame.points.size(); ++i) {
      if (pixel[i] < 0) continue;
      const int u = pixel[i] % width, v = pixel[i] / width;
      if (radius > 0) {
        const float z = nearest[static_cast<std::size_t>(pixel[i])];
        if (depth[i] > z * (1.0f + static_cast<float>(options.zbuffer_relative)) +
                           static_cast<float>(options.zbuffer_margin)) {
          continue;
        }
      }
      const int label = frame.mask_labels.at<int>(v, u);
      if (label <= 0) continue;
      Mask& m = masks[label - 1];
      ++m.n;
      const double r = frame.reflectivity[i];
      m.r += r;
      m.r2 += r * r;
      m.normal_sum += frame.normals[i].cast<double>();
      if (frame.segment[i] >= 0) {
        ++histogram[static_cast<std::size_t>(label - 1) * frame.num_segments + frame.segment[i]];
      }
    }
    const double log_classes = std::log(std::max(2, frame.num_segments));
    long in_image = 0;
    for (const int px : pixel) in_image += px >= 0 ? 1 : 0;
    const double density = static_cast<double>(in_image) / (static_cast<double>(width) * height);
    for (int k = 0; k < frame.num_masks; ++k) {
      Mask& m = masks[k];
      const double area = k < static_cast<int>(frame.mask_area.size()) ? frame.mask_area[k] : 0.0;
      const double threshold =
          std::max<double>(options.min_points, options.min_density_fraction * area * density);
      if (m.n < threshold) {  // Algorithm 1 line 16
        skipped += m.n;
        continue;
      }
      const double n = static_cast<double>(m.n);
      const double variance = std::max(0.0, m.r2 / n - (m.r / n) * (m.r / n));
      m.f_r = std::max(0.0, 1.0 - variance / std::max(frame.reflectivity_variance, 1e-12));
      m.f_n = (m.normal_sum.squaredNorm() - n) / (n * (n - 1.0));
      double classified = 0;
      for (int c = 0; c < frame.num_segments; ++c) {
        classified += histogram[static_cast<std::size_t>(k) * frame.num_segments + c];
      }
      double entropy = 0, purity = 0;
      for (int c = 0; c < frame.num_segments; ++c) {
        const int count = histogram[static_cast<std::size_t>(k) * frame.num_segments + c];
        if (count > 0) entropy -= count / classified * std::log(count / classified);
        purity += (count / classified) * (count / classified);
      }
      if (classified == 0) purity = 1;
      m.f_s = options.segmentation_entropy ? 1.0 - entropy / log_classes : purity;
      m.epsilon = (options.weight_reflectivity * m.f_r + options.weight_normal * m.f_n +
                   options.weight_segmentation * m.f_s) *
                  (n / (n + options.size_scale));  // Eq. (6)
      m.frame = static_cast<int>(f);
      m.index = k;
      all.push_back(m);
    }
  }
  ScoreBreakdown out;
  for (const Mask& m : all) out.points_in_masks += m.n;
  if (out.points_in_masks == 0) return out;
  const double total =
      static_cast<double>(out.points_in_masks + (options.count_skipped ? skipped : 0));
  for (const Mask& m : all) {
    const double w = m.n / total;  // Eq. (7)
    out.rho += w * m.epsilon;
    out.reflectivity += w * m.f_r;
    out.normal += w * m.f_n;
    out.segmentation += w * m.f_s;
    out.masks.push_back({m.frame, m.index, m.n, m.f_r, m.f_n, m.f_s, m.epsilon});
  }
  out.masks_used = static_cast<int>(all.size());
  return out;
}

}  // namespace autoshovel::identification
