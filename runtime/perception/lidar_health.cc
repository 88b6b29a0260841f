#include "runtime/perception/lidar_health.h"

#include <cmath>
#include <numbers>

namespace autoshovel::perception {

std::vector<AzimuthSector> BlindSectors(
    const std::vector<Eigen::Vector3d>& ray_directions_sensor, const sensors::PointCloud& cloud,
    const Eigen::Matrix3d& R_body_sensor, const Eigen::Matrix3d& R_world_sensor,
    const LidarHealthConfig& config,
    const std::function<bool(const Eigen::Vector3d&)>& ground_known) {
  const double pi = std::numbers::pi;
  const int bins = static_cast<int>(std::ceil(2 * pi / config.bin));
  auto bin_of = [&](const Eigen::Vector3d& d_body) {
    const double azimuth = std::atan2(d_body.y(), d_body.x());  // [−π, π]
    return std::min(bins - 1, static_cast<int>((azimuth + pi) / config.bin));
  };
  std::vector<int> expected(static_cast<std::size_t>(bins), 0);
  std::vector<int> returned(static_cast<std::size_t>(bins), 0);
  const double sin_depression = std::sin(config.min_depression);
  for (const Eigen::Vector3d& d : ray_directions_sensor) {
    const Eigen::Vector3d d_world = R_world_sensor * d;
    if (d_world.z() > -sin_depression) continue;
    if (ground_known && !ground_known(d_world)) continue;
    ++expected[bin_of(R_body_sensor * d)];
  }
  for (const sensors::LidarPoint& p : cloud.points) {
    const Eigen::Vector3d d = p.p_sensor.cast<double>();
    if (!d.allFinite() || d.squaredNorm() == 0) continue;
    ++returned[bin_of(R_body_sensor * d)];
  }
  std::vector<AzimuthSector> sectors;
  for (int b = 0; b < bins; ++b) {
    if (expected[b] < config.min_expected_rays || returned[b] > 0) continue;
    const double from = -pi + b * config.bin;
    const double to = std::min(pi, from + config.bin);
    if (!sectors.empty() && std::abs(sectors.back().to - from) < 1e-9) {
      sectors.back().to = to;
    } else {
      sectors.push_back({from, to});
    }
  }
  // A sector across ±π is one sector: join the last onto the first.
  if (sectors.size() > 1 && std::abs(sectors.front().from + pi) < 1e-9 &&
      std::abs(sectors.back().to - pi) < 1e-9) {
    sectors.front().from = sectors.back().from - 2 * pi;
    sectors.pop_back();
  }
  return sectors;
}

bool SectorFaces(const AzimuthSector& sector, double direction, double half_angle) {
  // Distance from the cone's axis to the sector, on the circle.
  const double middle = 0.5 * (sector.from + sector.to);
  const double half_width = 0.5 * (sector.to - sector.from);
  const double apart = std::abs(std::remainder(middle - direction, 2 * std::numbers::pi));
  return apart <= half_width + half_angle;
}

}  // namespace autoshovel::perception
