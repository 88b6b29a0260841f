// Seed Eq. (6)–(7): ρ = Σ_i ω_i (ω_R F_R + ω_N F_N + ω_S F_S) f(|P_i|), ω_i = |P_i| / Σ_j |P_j|.
#include "identification/camera_lidar/consistency_score.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "identification/camera_lidar/camera_model.h"

namespace autoshovel::identification {

ScoreBreakdown ConsistencyScore(const std::vector<ScoreFrame>& frames,
                                const Eigen::Isometry3d& T_lidar_camera,
                                const ScoreOptions& options) {
  struct Mask {
    int frame = 0, index = 0;
    double n = 0, w2 = 0;  // Σ w, Σ w² (w = 1 per point with the nearest-pixel lookup)
    double r = 0, r2 = 0;
    Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d normal_scatter = Eigen::Matrix3d::Zero();  // Σ w n nᵀ
    double f_r = 0, f_n = 0, f_s = 0, epsilon = 0;
  };
  const Eigen::Isometry3d T_optical_lidar = OpticalFromLidar(T_lidar_camera);
  const Eigen::Matrix3f R = T_optical_lidar.linear().cast<float>();
  const Eigen::Vector3f t = T_optical_lidar.translation().cast<float>();
  std::vector<Mask> all;
  std::vector<double> histogram;
  double skipped = 0, misplaced = 0;
  double edge_sum = 0, edge_total = 0;
  const double inv_two_sigma2 = 1.0 / (2.0 * options.edge_sigma_px * options.edge_sigma_px);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const ScoreFrame& frame = frames[f];
    std::vector<Mask> masks(frame.num_masks);
    histogram.assign(static_cast<std::size_t>(frame.num_masks) * frame.num_segments, 0);
    const float fx = frame.K(0, 0), fy = frame.K(1, 1), cx = frame.K(0, 2), cy = frame.K(1, 2);
    const int width = frame.mask_labels.cols, height = frame.mask_labels.rows;
    if (options.weight_edges != 0 && !frame.boundary_distance.empty()) {
      // The edge term: E at each silhouette point, bilinear in the distance map, so that it is
      // continuous in the pose.
      for (std::size_t i = 0; i < frame.edge_points.size(); ++i) {
        const Eigen::Vector3f p = R * frame.edge_points[i] + t;
        if (p.z() < 0.1f) continue;
        const float su = fx * p.x() / p.z() + cx, sv = fy * p.y() / p.z() + cy;
        if (!(su >= 0 && sv >= 0 && su < width - 1 && sv < height - 1)) continue;
        const int x0 = static_cast<int>(su), y0 = static_cast<int>(sv);
        const float a = su - x0, b = sv - y0;
        const float* r0 = frame.boundary_distance.ptr<float>(y0) + x0;
        const float* r1 = frame.boundary_distance.ptr<float>(y0 + 1) + x0;
        const double d =
            (1 - a) * (1 - b) * r0[0] + a * (1 - b) * r0[1] + (1 - a) * b * r1[0] + a * b * r1[1];
        edge_sum += frame.edge_weight[i] * std::exp(-d * d * inv_two_sigma2);
        edge_total += frame.edge_weight[i];
      }
    }
    const int radius = options.zbuffer_block;
    std::vector<int> pixel(frame.points.size(), -1);
    std::vector<float> depth(frame.points.size(), 0.f);
    std::vector<Eigen::Vector2f> image_uv(options.subpixel ? frame.points.size() : 0);
    std::vector<float> nearest(radius > 0 ? static_cast<std::size_t>(width) * height : 0,
                               std::numeric_limits<float>::infinity());
    for (std::size_t i = 0; i < frame.points.size(); ++i) {
      const Eigen::Vector3f p = R * frame.points[i] + t;  // Eq. (5)
      if (p.z() < 0.1f) continue;
      const float su = fx * p.x() / p.z() + cx, sv = fy * p.y() / p.z() + cy;
      if (!(su > -0.5f && sv > -0.5f && su < width - 0.5f && sv < height - 0.5f)) continue;
      const int u = static_cast<int>(su + 0.5f);  // ≥ 0 here: truncation = rounding
      const int v = static_cast<int>(sv + 0.5f);
      if (u < 0 || v < 0 || u >= width || v >= height) continue;
      pixel[i] = v * width + u;
      if (options.subpixel) image_uv[i] = Eigen::Vector2f(su, sv);
      if (radius > 0) {
        for (int y = std::max(0, v - radius); y <= std::min(height - 1, v + radius); ++y) {
          float* row = &nearest[static_cast<std::size_t>(y) * width];
          for (int x = std::max(0, u - radius); x <= std::min(width - 1, u + radius); ++x) {
            row[x] = std::min(row[x], p.z());
          }
        }
      }
    }
    // Adds point i to mask `label` with weight w (1 for the nearest-pixel lookup).
    auto accumulate = [&](std::size_t i, int label, double w) {
      Mask& m = masks[label - 1];
      m.n += w;
      m.w2 += w * w;
      const double r = frame.reflectivity[i];
      m.r += w * r;
      m.r2 += w * r * r;
      const Eigen::Vector3d normal = frame.normals[i].cast<double>();
      m.normal_sum += w * normal;
      if (options.unoriented_normals) m.normal_scatter += w * normal * normal.transpose();
      if (frame.segment[i] >= 0) {
        histogram[static_cast<std::size_t>(label - 1) * frame.num_segments + frame.segment[i]] += w;
      }
    };
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
      const bool layered = options.overlapping_masks && !frame.mask_layers.empty();
      // The masks at pixel (x, y): the smallest only, or all of its layers.
      auto labels_at = [&](int x, int y, int* out) {
        if (layered) {
          const cv::Vec4i& l = frame.mask_layers.at<cv::Vec4i>(y, x);
          for (int c = 0; c < 4; ++c) out[c] = l[c];
        } else {
          out[0] = frame.mask_labels.at<int>(y, x);
          out[1] = out[2] = out[3] = 0;
        }
      };
      if (!options.subpixel) {
        int labels[4];
        labels_at(u, v, labels);
        for (const int label : labels) {
          if (label > 0) accumulate(i, label, 1.0);
        }
        continue;
      }
      // Area lookup: the point's footprint is a 1 px square centred on its projection; it
      // belongs to each of the (up to) four pixels it overlaps in proportion to the overlap,
      // i.e. bilinear weights. Pixels outside the image take their share with them.
      const float su = image_uv[i].x(), sv = image_uv[i].y();
      const int u0 = static_cast<int>(std::floor(su)), v0 = static_cast<int>(std::floor(sv));
      if (!layered && u0 >= 0 && v0 >= 0 && u0 + 1 < width && v0 + 1 < height) {
        const int* row0 = frame.mask_labels.ptr<int>(v0) + u0;
        const int* row1 = frame.mask_labels.ptr<int>(v0 + 1) + u0;
        if (row0[0] == row0[1] && row0[0] == row1[0] && row0[0] == row1[1]) {
          if (row0[0] > 0) accumulate(i, row0[0], 1.0);  // inside one mask: most points
          continue;
        }
      }
      const double a = su - u0, b = sv - v0;
      const double corner_weight[4] = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
      // Up to 4 corners × 4 layers; one entry per distinct label with the summed weight.
      int labels[16];
      double weights[16];
      int count = 0;
      for (int c = 0; c < 4; ++c) {
        const int x = u0 + (c & 1), y = v0 + (c >> 1);
        if (x < 0 || y < 0 || x >= width || y >= height || corner_weight[c] <= 0) continue;
        int at[4];
        labels_at(x, y, at);
        for (const int label : at) {
          if (label <= 0) continue;
          int k = 0;
          while (k < count && labels[k] != label) ++k;
          if (k == count) {
            labels[count] = label;
            weights[count++] = 0;
          }
          weights[k] += corner_weight[c];
        }
      }
      for (int k = 0; k < count; ++k) accumulate(i, labels[k], weights[k]);
    }
    const double log_classes = std::log(std::max(2, frame.num_segments));
    long in_image = 0;
    for (const int px : pixel) in_image += px >= 0 ? 1 : 0;
    const double density = static_cast<double>(in_image) / (static_cast<double>(width) * height);
    for (int k = 0; k < frame.num_masks; ++k) {
      Mask& m = masks[k];
      const std::vector<double>& areas = options.overlapping_masks && !frame.mask_layers.empty()
                                             ? frame.mask_full_area
                                             : frame.mask_area;
      const double area = k < static_cast<int>(areas.size()) ? areas[k] : 0.0;
      const double threshold =
          std::max<double>(options.min_points, options.min_density_fraction * area * density);
      if (k < static_cast<int>(frame.unsupported.size()) && frame.unsupported[k]) {
        misplaced += m.n;  // our extension, see consistency_score.h
        continue;
      }
      if (m.n < threshold) {  // Algorithm 1 line 16
        skipped += m.n;
        continue;
      }
      const double n = m.n;
      const double variance = std::max(0.0, m.r2 / n - (m.r / n) * (m.r / n));
      m.f_r = std::max(0.0, 1.0 - variance / std::max(frame.reflectivity_variance, 1e-12));
      // Weighted mean over pairs p ≠ p' (weights w_p w_p'); = the unweighted formula for w = 1.
      m.f_n = options.unoriented_normals
                  ? (m.normal_scatter.squaredNorm() - m.w2) / std::max(1e-12, n * n - m.w2)
                  : (m.normal_sum.squaredNorm() - m.w2) / std::max(1e-12, n * n - m.w2);
      double classified = 0;
      for (int c = 0; c < frame.num_segments; ++c) {
        classified += histogram[static_cast<std::size_t>(k) * frame.num_segments + c];
      }
      double entropy = 0, purity = 0;
      for (int c = 0; c < frame.num_segments; ++c) {
        const double count = histogram[static_cast<std::size_t>(k) * frame.num_segments + c];
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
  double in_masks = 0;
  for (const Mask& m : all) in_masks += m.n;
  out.points_in_masks = std::lround(in_masks);
  if (in_masks <= 0) return out;
  const double total = in_masks + (options.count_skipped ? skipped : 0) + misplaced;
  out.total_points = total;
  for (const Mask& m : all) {
    const double w = m.n / total;  // Eq. (7)
    out.rho += w * m.epsilon;
    out.reflectivity += w * m.f_r;
    out.normal += w * m.f_n;
    out.segmentation += w * m.f_s;
    out.size += w * m.n / (m.n + options.size_scale);
    out.masks.push_back({m.frame, m.index, std::lround(m.n), m.f_r, m.f_n, m.f_s, m.epsilon});
  }
  out.masks_used = static_cast<int>(all.size());
  out.consistency = out.rho;
  if (edge_total > 0) {
    out.edges = edge_sum / edge_total;
    out.rho += options.weight_edges * out.edges;
  }
  return out;
}

ScoreGain CompareScores(const ScoreBreakdown& a, const ScoreBreakdown& b) {
  std::map<std::pair<int, int>, double> delta;
  for (const MaskScore& m : a.masks) {
    delta[{m.frame, m.mask}] -= static_cast<double>(m.n) * m.epsilon / a.total_points;
  }
  for (const MaskScore& m : b.masks) {
    delta[{m.frame, m.mask}] += static_cast<double>(m.n) * m.epsilon / b.total_points;
  }
  ScoreGain out;
  out.masks = static_cast<int>(delta.size());
  if (delta.empty()) return out;
  for (const auto& [key, d] : delta) out.gain += d;
  const double mean = out.gain / out.masks;
  double spread = 0;
  for (const auto& [key, d] : delta) spread += (d - mean) * (d - mean);
  if (out.masks > 1) {
    out.standard_error = std::sqrt(spread * out.masks / (out.masks - 1.0));
  }
  return out;
}

void MarkUnsupportedMasks(std::vector<ScoreFrame>& frames, const Eigen::Isometry3d& T_lidar_camera,
                          double fraction) {
  ScoreOptions options;
  options.min_points = 0;
  for (ScoreFrame& frame : frames) {
    frame.unsupported.assign(frame.num_masks, 0);
    std::vector<ScoreFrame> one{frame};
    std::vector<double> count(frame.num_masks, 0.0);
    const ScoreBreakdown b = ConsistencyScore(one, T_lidar_camera, options);
    double total = 0, area = 0;
    for (const MaskScore& m : b.masks) {
      count[m.mask] = static_cast<double>(m.n);
      total += static_cast<double>(m.n);
    }
    for (const double a : frame.mask_area) area += a;
    const double density = total / std::max(1.0, area);
    for (int k = 0; k < frame.num_masks; ++k) {
      frame.unsupported[k] = count[k] < fraction * density * frame.mask_area[k] ? 1 : 0;
    }
  }
}

}  // namespace autoshovel::identification
