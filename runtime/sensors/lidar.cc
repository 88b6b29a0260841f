#include "runtime/sensors/lidar.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace autoshovel::sensors {
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Vector3d FromAngles(double azimuth, double elevation) {
  const double ce = std::cos(elevation);
  return {ce * std::cos(azimuth), ce * std::sin(azimuth), std::sin(elevation)};
}

// 2π·frac(f·t): the phase of a rotation at f [Hz], reduced before the multiplication by 2π so a
// large clock value keeps its precision.
double Phase(double f, double t) { return 2 * kPi * std::fmod(f * t, 1.0); }

void CheckRates(const model::Lidar& lidar) {
  if (!(lidar.rate > 0) || !(lidar.points_per_second > 0)) {
    throw std::invalid_argument("LiDAR '" + lidar.name +
                                "': rate and points_per_second must be > 0");
  }
}

}  // namespace

Eigen::Vector3d RosetteDirection(const model::Lidar& lidar, double t, int emitter) {
  // Unit-disc deflection of the Risley pair, w = ½(e^{ip₁} + e^{ip₂}), turned by the emitter's
  // offset (a complex product, so two sincos per ray instead of four).
  const double p1 = Phase(kRosetteF1, t), p2 = Phase(kRosetteF2, t);
  static const std::array<Eigen::Vector2d, kRosetteEmitters> kTurns = [] {
    std::array<Eigen::Vector2d, kRosetteEmitters> turns;
    for (int k = 0; k < kRosetteEmitters; ++k) {
      const double turn = 2 * kPi * k / kRosetteEmitters;
      turns[k] = Eigen::Vector2d(std::cos(turn), std::sin(turn));
    }
    return turns;
  }();
  const double w_re = 0.5 * (std::cos(p1) + std::cos(p2));
  const double w_im = 0.5 * (std::sin(p1) + std::sin(p2));
  const int k = ((emitter % kRosetteEmitters) + kRosetteEmitters) % kRosetteEmitters;
  const double c = kTurns[k].x(), s = kTurns[k].y();
  const double wx = c * w_re - s * w_im, wy = s * w_re + c * w_im;
  return FromAngles(0.5 * lidar.horizontal_fov * wx, 0.5 * lidar.vertical_fov * wy);
}

std::vector<LidarRay> LidarScanPattern(const model::Lidar& lidar, double stamp) {
  CheckRates(lidar);
  std::vector<LidarRay> rays;
  if (lidar.model == "spinning") {
    if (lidar.lines < 1) {
      throw std::invalid_argument("LiDAR '" + lidar.name + "': a spinning head needs lines >= 1");
    }
    const double per_revolution = lidar.points_per_second / (lidar.rate * lidar.lines);
    const int columns_per_revolution = std::max(1, static_cast<int>(std::lround(per_revolution)));
    const double step = 2 * kPi / columns_per_revolution;
    const double fov = std::min(lidar.horizontal_fov, 2 * kPi);
    const int columns = std::max(1, static_cast<int>(std::lround(fov / step)));
    const double column_period = 1.0 / (lidar.rate * columns_per_revolution);
    rays.reserve(static_cast<std::size_t>(columns) * lidar.lines);
    // Each ring's elevation and each column's azimuth once: the same directions FromAngles gives
    // ray by ray, with a sine and cosine per ring and per column instead of per ray.
    std::vector<double> ring_cos(lidar.lines), ring_sin(lidar.lines);
    for (int ring = 0; ring < lidar.lines; ++ring) {
      const double elevation = lidar.lines == 1 ? 0.0
                                                : -0.5 * lidar.vertical_fov +
                                                      ring * lidar.vertical_fov / (lidar.lines - 1);
      ring_cos[ring] = std::cos(elevation);
      ring_sin[ring] = std::sin(elevation);
    }
    for (int c = 0; c < columns; ++c) {
      // Clockwise from above: azimuth decreases with time.
      const double azimuth = 0.5 * fov - (c + 0.5) * step;
      const double ca = std::cos(azimuth), sa = std::sin(azimuth);
      const float time_offset = static_cast<float>(c * column_period);
      for (int ring = 0; ring < lidar.lines; ++ring) {
        const double ce = ring_cos[ring];
        rays.push_back({Eigen::Vector3d(ce * ca, ce * sa, ring_sin[ring]),
                        static_cast<std::uint16_t>(ring), time_offset});
      }
    }
  } else if (lidar.model == "non_repetitive") {
    const int count = static_cast<int>(std::lround(lidar.points_per_second / lidar.rate));
    const double sample_period = kRosetteEmitters / lidar.points_per_second;  // per emitter
    rays.reserve(count);
    for (int j = 0; j < count; ++j) {
      const int emitter = j % kRosetteEmitters;
      const double dt = (j / kRosetteEmitters) * sample_period;
      rays.push_back({RosetteDirection(lidar, stamp + dt, emitter),
                      static_cast<std::uint16_t>(emitter), static_cast<float>(dt)});
    }
  } else {
    throw std::invalid_argument("LiDAR '" + lidar.name + "': unknown model '" + lidar.model + "'");
  }
  return rays;
}

double LidarRangeSigma(const model::Lidar& lidar, double range) {
  return lidar.range_noise * (0.5 + 0.5 * range / 10.0);
}

double LidarReturnProbability(const model::Lidar& lidar, double range, double reflectivity,
                              double cos_incidence) {
  if (range > lidar.max_range) return 0.0;
  const double power = reflectivity * cos_incidence / kLidarReferenceReflectivity;
  if (!(power > 0)) return 0.0;
  const double r_det = lidar.max_range * std::sqrt(power);
  const double x = range / r_det;
  const double x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  return 1.0 / (1.0 + x8 * x8);
}

PointCloud SimulateLidarFrame(const model::Lidar& lidar, const RaycastScene& scene,
                              const Eigen::Isometry3d& T_world_sensor, double stamp, Rng& rng) {
  return SimulateLidarFrame(lidar, scene, T_world_sensor, stamp, rng,
                            LidarScanPattern(lidar, stamp));
}

PointCloud SimulateLidarFrame(const model::Lidar& lidar, const RaycastScene& scene,
                              const Eigen::Isometry3d& T_world_sensor, double stamp, Rng& rng,
                              const std::vector<LidarRay>& rays) {
  PointCloud cloud;
  cloud.stamp = stamp;
  cloud.sensor = lidar.name;
  cloud.points.reserve(rays.size());
  const Eigen::Matrix3d R = T_world_sensor.linear();
  const Eigen::Vector3d origin = T_world_sensor.translation();
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (const LidarRay& ray : rays) {
    const Eigen::Vector3d d = R * ray.direction;
    const RayHit hit = scene.Cast(origin, d, lidar.max_range);
    if (!hit.hit) continue;
    // Two draws per hit, always, so the stream does not depend on the outcome of the first.
    const double u = uniform(rng);
    const double n = gauss(rng);
    const double cos_incidence = std::abs(d.dot(hit.normal));
    if (u >= LidarReturnProbability(lidar, hit.range, hit.reflectivity, cos_incidence)) continue;
    const double measured = hit.range + LidarRangeSigma(lidar, hit.range) * n;
    if (measured <= 0) continue;
    LidarPoint p;
    p.p_sensor = (ray.direction * measured).cast<float>();
    p.intensity = static_cast<float>(std::clamp(hit.reflectivity * cos_incidence, 0.0, 1.0));
    p.ring = ray.ring;
    p.time_offset = ray.time_offset;
    cloud.points.push_back(p);
  }
  return cloud;
}

}  // namespace autoshovel::sensors
