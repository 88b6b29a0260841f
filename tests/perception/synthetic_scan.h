// A synthetic scan for the scan-map tests (issue 43): a solid, given as a predicate over world
// points (z up), seen from a scanner the way a handheld or tripod LiDAR records it: the points
// in the scanner's frame with z along the line of sight to a target (the range axis), x to its
// right, as a Livox writes them, with Gaussian range noise.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <random>

#include "runtime/perception/scan/scan_map.h"

namespace autoshovel::perception {

struct ScanPattern {
  double half_a = 0.45, half_b = 0.35;  ///< half field of view across and along [rad, tangent]
  double step = 0.0025;                 ///< between rays [rad, tangent]
  double march = 0.01;                  ///< ray march step before bisection [m]
  double near = 0.05, far = 20;         ///< march range [m]
  int bisections = 30;
  double noise = 0.003;  ///< range noise σ [m]
};

/// Marches each ray to the first point inside `solid`, then bisects; rays that meet nothing are
/// not returned. `T_world_scanner` receives the scanner's pose.
inline ScanCloud ScanSolid(const std::function<bool(const Eigen::Vector3d&)>& solid,
                           const Eigen::Vector3d& scanner, const Eigen::Vector3d& target,
                           unsigned seed, Eigen::Isometry3d& T_world_scanner,
                           const ScanPattern& pattern = {}) {
  const Eigen::Vector3d z = (target - scanner).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  T_world_scanner = Eigen::Isometry3d::Identity();
  T_world_scanner.linear() << x, y, z;
  T_world_scanner.translation() = scanner;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, pattern.noise);
  ScanCloud scan;
  for (double a = -pattern.half_a; a <= pattern.half_a; a += pattern.step) {
    for (double b = -pattern.half_b; b <= pattern.half_b; b += pattern.step) {
      const Eigen::Vector3d d = (z + a * x + b * y).normalized();
      double t0 = 0, t1 = 0;
      bool hit = false;
      for (double t = pattern.near; t < pattern.far; t += pattern.march) {
        if (solid(scanner + t * d)) {
          t0 = t - pattern.march;
          t1 = t;
          hit = true;
          break;
        }
      }
      if (!hit) continue;
      for (int i = 0; i < pattern.bisections; ++i) {
        const double t = 0.5 * (t0 + t1);
        (solid(scanner + t * d) ? t1 : t0) = t;
      }
      sensors::LidarPoint point;
      point.p_sensor =
          (T_world_scanner.inverse() * (scanner + (t1 + noise(rng)) * d)).cast<float>();
      scan.cloud.points.push_back(point);
    }
  }
  return scan;
}

}  // namespace autoshovel::perception
