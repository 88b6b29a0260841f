#include "runtime/perception/elevation_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace autoshovel::perception {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr char kElevation[] = "elevation";
constexpr char kVariance[] = "variance";
constexpr char kFilled[] = "filled";
constexpr char kObserved[] = "observed";
constexpr char kStamp[] = "stamp";
/// A cell's height is never known better than this: sub-cell relief and the surface moving
/// under the bucket keep some doubt, and it lets a few frames move an old cell [m²].
constexpr float kMinVariance = 0.02f * 0.02f;

// The footprint's two rectangles with their axes precomputed (two sines per frame instead of
// four per return).
struct FootprintTest {
  explicit FootprintTest(const MachineFootprint& f)
      : f_(f),
        front_(std::cos(f.heading_front), std::sin(f.heading_front)),
        rear_(std::cos(f.heading_front - f.articulation),
              std::sin(f.heading_front - f.articulation)) {}
  bool Contains(const Eigen::Vector3d& p) const {
    if (p.z() > f_.floor_height + f_.max_height) return false;
    const Eigen::Vector2d d = p.head<2>() - f_.hinge_xy;
    auto inside = [&](const Eigen::Vector2d& axis, double from, double to) {
      const double along = axis.dot(d), across = axis.x() * d.y() - axis.y() * d.x();
      return along >= from && along <= to && std::abs(across) <= f_.half_width;
    };
    return inside(front_, 0.0, f_.front_length) || inside(rear_, -f_.rear_length, 0.0);
  }
  MachineFootprint f_;
  Eigen::Vector2d front_, rear_;
};

}  // namespace

ElevationMap::ElevationMap(const ElevationMapConfig& config, const Eigen::Vector2d& center)
    : config_(config), map_(config.resolution, config.length, center) {
  map_.Add(kElevation, kNaN);
  map_.Add(kVariance, static_cast<float>(config.initial_variance));
  map_.Add(kFilled, 0.0f);
  map_.Add(kObserved, 0.0f);
  map_.Add(kStamp, kNaN);
  frame_height_ = Eigen::MatrixXf::Constant(map_.size().x(), map_.size().y(), kNaN);
  frame_variance_ = Eigen::MatrixXf::Zero(map_.size().x(), map_.size().y());
}

float ElevationMap::HeightAt(const Eigen::Vector2d& xy) const {
  Index index;
  return map_.IndexOf(xy, index) ? map_.at(kElevation, index) : kNaN;
}

MapUpdateStats ElevationMap::Update(const sensors::PointCloud& cloud,
                                    const Eigen::Isometry3d& T_world_sensor, double pose_stamp,
                                    const MachineFootprint* footprint) {
  MapUpdateStats stats;
  stats.points = static_cast<long>(cloud.points.size());
  if (cloud.points.empty()) {
    stats.refused = "empty frame";
    return stats;
  }
  if (!T_world_sensor.matrix().allFinite() || !std::isfinite(pose_stamp) ||
      !std::isfinite(cloud.stamp)) {
    stats.refused = "non-finite pose or stamp";
    return stats;
  }
  if (std::abs(cloud.stamp - pose_stamp) > config_.max_pose_age) {
    stats.refused = "pose is " + std::to_string(std::abs(cloud.stamp - pose_stamp)) +
                    " s from the frame (limit " + std::to_string(config_.max_pose_age) + " s)";
    return stats;
  }

  Eigen::MatrixXf& elevation = map_[kElevation];
  Eigen::MatrixXf& variance = map_[kVariance];
  Eigen::MatrixXf& filled = map_[kFilled];
  Eigen::MatrixXf& observed = map_[kObserved];
  Eigen::MatrixXf& stamp = map_[kStamp];
  if (frame_height_.rows() != map_.size().x() || frame_height_.cols() != map_.size().y()) {
    frame_height_ = Eigen::MatrixXf::Constant(map_.size().x(), map_.size().y(), kNaN);
    frame_variance_ = Eigen::MatrixXf::Zero(map_.size().x(), map_.size().y());
  }

  // The map keeps listening: variance grows with the time since the last frame.
  if (last_stamp_ > -1e299 && cloud.stamp > last_stamp_) {
    const float grow = static_cast<float>(config_.process_noise * (cloud.stamp - last_stamp_));
    variance.array() += grow * (observed.array() > 0).cast<float>();
  }
  last_stamp_ = std::max(last_stamp_, cloud.stamp);

  const Eigen::Matrix3f R = T_world_sensor.linear().cast<float>();
  const Eigen::Vector3f t = T_world_sensor.translation().cast<float>();
  const Eigen::Vector3d origin = T_world_sensor.translation();
  const double resolution = map_.resolution();
  const Eigen::Vector2d corner = map_.position() - 0.5 * map_.length();
  const float min_range2 = static_cast<float>(config_.min_ray_length * config_.min_ray_length);
  const float max_range2 = static_cast<float>(config_.max_ray_length * config_.max_ray_length);
  const FootprintTest on_machine(footprint ? *footprint : MachineFootprint{});
  touched_.clear();

  long n = 0;
  for (const sensors::LidarPoint& point : cloud.points) {
    const Eigen::Vector3f& p_sensor = point.p_sensor;
    if (!p_sensor.allFinite()) {
      ++stats.non_finite;
      continue;
    }
    const float range2 = p_sensor.squaredNorm();
    if (range2 < min_range2 || range2 > max_range2) {
      ++stats.out_of_range;
      continue;
    }
    const Eigen::Vector3d p_world = (R * p_sensor + t).cast<double>();
    if (footprint != nullptr && on_machine.Contains(p_world)) {
      ++stats.on_machine;
      continue;
    }
    const double fx = (p_world.x() - corner.x()) / resolution;
    const double fy = (p_world.y() - corner.y()) / resolution;
    if (!(fx >= 0 && fy >= 0 && fx < map_.size().x() && fy < map_.size().y())) {
      ++stats.out_of_range;
      continue;
    }
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float z = static_cast<float>(p_world.z());
    const float sigma_p2 = static_cast<float>(config_.alpha_d) * range2;  // σp² = α_d d²
    float& h = frame_height_(ix, iy);
    float& v = frame_variance_(ix, iy);
    if (std::isnan(h)) {
      h = z, v = sigma_p2;
      touched_.push_back(iy * map_.size().x() + ix);
    } else {  // Eq. (8) among the returns of this frame
      h = (sigma_p2 * h + v * z) / (v + sigma_p2);
      v = v * sigma_p2 / (v + sigma_p2);
    }
    ++stats.fused;

    // Ray clearing: the cells the ray crosses on its way to this return, where the ray runs
    // below the lower confidence bound h − σ, held something that is no longer there.
    if (config_.clearing_stride > 0 && (n++ % config_.clearing_stride) == 0) {
      const Eigen::Vector2d o((origin.x() - corner.x()) / resolution,
                              (origin.y() - corner.y()) / resolution);
      const Eigen::Vector2d e(fx, fy);
      const Eigen::Vector2d dir = e - o;
      const double len2 = dir.squaredNorm();
      if (len2 < 4.0) continue;
      // Amanatides–Woo traversal from the sensor's cell to the return's cell (excluded).
      int cx = static_cast<int>(std::floor(o.x())), cy = static_cast<int>(std::floor(o.y()));
      const int step_x = dir.x() > 0 ? 1 : -1, step_y = dir.y() > 0 ? 1 : -1;
      const double inv_x = dir.x() != 0 ? 1.0 / std::abs(dir.x()) : 1e30;
      const double inv_y = dir.y() != 0 ? 1.0 / std::abs(dir.y()) : 1e30;
      double t_max_x = (dir.x() > 0 ? (cx + 1 - o.x()) : (o.x() - cx)) * inv_x;
      double t_max_y = (dir.y() > 0 ? (cy + 1 - o.y()) : (o.y() - cy)) * inv_y;
      const double dz = p_world.z() - origin.z();
      while (true) {
        double t_cell;
        if (t_max_x < t_max_y) {
          t_cell = t_max_x, t_max_x += inv_x, cx += step_x;
        } else {
          t_cell = t_max_y, t_max_y += inv_y, cy += step_y;
        }
        if (cx == ix && cy == iy) break;
        if (t_cell >= 1.0) break;
        if (cx < 0 || cy < 0 || cx >= map_.size().x() || cy >= map_.size().y()) continue;
        const float hc = elevation(cx, cy);
        if (std::isnan(hc) || filled(cx, cy) > 0) continue;
        // Height of the ray where it leaves the cell (its lowest there when descending).
        const double z_ray = origin.z() + std::min(1.0, t_cell + std::min(inv_x, inv_y)) * dz;
        if (z_ray < hc - std::sqrt(variance(cx, cy)) - config_.clearing_margin) {
          elevation(cx, cy) = kNaN;
          variance(cx, cy) = static_cast<float>(config_.initial_variance);
          observed(cx, cy) = 0;
          ++stats.cells_cleared;
        }
      }
    }
  }

  // Fuse each cell's frame estimate into the map: gate, then Eq. (8) or re-initialisation.
  const float roughness2 = static_cast<float>(config_.roughness * config_.roughness);
  const float gate2 = static_cast<float>(config_.change_gate * config_.change_gate);
  for (const int flat : touched_) {
    const int ix = flat % map_.size().x(), iy = flat / map_.size().x();
    float& hf = frame_height_(ix, iy);
    const float vf = frame_variance_(ix, iy);
    float& h = elevation(ix, iy);
    float& v = variance(ix, iy);
    const float innovation = hf - h;
    if (std::isnan(h) || observed(ix, iy) == 0 ||
        innovation * innovation > gate2 * (v + vf + roughness2)) {
      if (!std::isnan(h) && observed(ix, iy) > 0) ++stats.cells_reset;
      h = hf, v = std::max(vf, kMinVariance);
    } else {
      h = (vf * h + v * hf) / (v + vf);  // Eq. (8), the frame's estimate as the measurement
      v = std::max(v * vf / (v + vf), kMinVariance);
      ++stats.cells_fused;
    }
    filled(ix, iy) = 0;
    observed(ix, iy) += 1;
    stamp(ix, iy) = static_cast<float>(cloud.stamp);
    hf = kNaN;
  }
  stats.applied = true;
  return stats;
}

long ElevationMap::FillHoles() {
  Eigen::MatrixXf& elevation = map_[kElevation];
  Eigen::MatrixXf& filled = map_[kFilled];
  const Eigen::MatrixXf& observed = map_[kObserved];
  const int nx = map_.size().x(), ny = map_.size().y();
  // Eq. (9) by OpenCV's exact Euclidean distance transform, whose labels name each cell's
  // nearest observed cell: the nearest-neighbour search of the seed in one linear pass.
  cv::Mat unknown(ny, nx, CV_8U);
  bool any = false;
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const bool known = observed(ix, iy) > 0 && !std::isnan(elevation(ix, iy));
      unknown.at<std::uint8_t>(iy, ix) = known ? 0 : 255;
      any |= known;
    }
  }
  if (!any) return 0;
  cv::Mat distance, labels;
  cv::distanceTransform(unknown, distance, labels, cv::DIST_L2, cv::DIST_MASK_PRECISE,
                        cv::DIST_LABEL_PIXEL);
  std::vector<Index> source(static_cast<std::size_t>(nx) * ny + 1, Index(-1, -1));
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      if (unknown.at<std::uint8_t>(iy, ix) == 0) source[labels.at<int>(iy, ix)] = Index(ix, iy);
    }
  }
  const float max_cells = static_cast<float>(config_.max_fill_distance / map_.resolution());
  long count = 0;
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      if (unknown.at<std::uint8_t>(iy, ix) == 0) continue;
      if (distance.at<float>(iy, ix) > max_cells) {
        if (filled(ix, iy) > 0) elevation(ix, iy) = kNaN, filled(ix, iy) = 0;
        continue;
      }
      const Index& from = source[labels.at<int>(iy, ix)];
      elevation(ix, iy) = elevation(from.x(), from.y());
      for (const std::string& layer : fill_also_) {
        Eigen::MatrixXf& values = map_[layer];
        values(ix, iy) = values(from.x(), from.y());
      }
      filled(ix, iy) = 1;
      ++count;
    }
  }
  return count;
}

}  // namespace autoshovel::perception
