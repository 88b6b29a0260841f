#include "runtime/sensors/rangefinder/scanner_geometry.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace autoshovel::sensors {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Wraps an angle to (−π, π].
double WrapAngle(double angle) {
  double a = std::fmod(angle + std::numbers::pi, kTwoPi);
  if (a < 0) a += kTwoPi;
  a -= std::numbers::pi;
  return a == -std::numbers::pi ? std::numbers::pi : a;
}

void RequirePositive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0) {
    throw std::invalid_argument(std::string("ScannerConfig: ") + name +
                                " must be finite and positive, got " + std::to_string(value));
  }
}

void RequireFinite(double value, const char* what) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument(std::string(what) + " must be finite, got " +
                                std::to_string(value));
  }
}

ScannerConfig MountedAt(const Eigen::Vector3d& p_cab_scanner) {
  ScannerConfig config;
  config.T_cab_scanner = Eigen::Isometry3d::Identity();
  config.T_cab_scanner.translation() = p_cab_scanner;
  return config;
}

}  // namespace

ScannerConfig LeftScannerConfig() { return MountedAt({0.4, 0.8, 2.6}); }

ScannerConfig RightScannerConfig() { return MountedAt({0.4, -0.8, 2.6}); }

PanSweep HoldPan(double angle) { return PanSweep{0.0, angle, angle, 0.0}; }

ScannerGeometry::ScannerGeometry(const ScannerConfig& config) : config_(config) {
  RequirePositive(config.pulse_rate, "pulse_rate");
  RequirePositive(config.mirror_rate, "mirror_rate");
  RequirePositive(config.pan_rate_limit, "pan_rate_limit");
  RequireFinite(config.mirror_phase, "ScannerConfig: mirror_phase");
  RequireFinite(config.active_elevation_min, "ScannerConfig: active_elevation_min");
  RequireFinite(config.active_elevation_max, "ScannerConfig: active_elevation_max");
  RequireFinite(config.pan_min, "ScannerConfig: pan_min");
  RequireFinite(config.pan_max, "ScannerConfig: pan_max");
  if (config.mirror_rate >= 0.5 * config.pulse_rate) {
    throw std::invalid_argument(
        "ScannerConfig: mirror_rate must be below half the pulse rate (at least two pulses per "
        "circle), got " +
        std::to_string(config.mirror_rate) + " rev/s at " + std::to_string(config.pulse_rate) +
        " Hz");
  }
  if (!(config.active_elevation_min < config.active_elevation_max) ||
      config.active_elevation_min < -std::numbers::pi ||
      config.active_elevation_max > std::numbers::pi) {
    throw std::invalid_argument(
        "ScannerConfig: the active arc must satisfy −π ≤ active_elevation_min < "
        "active_elevation_max ≤ π, got [" +
        std::to_string(config.active_elevation_min) + ", " +
        std::to_string(config.active_elevation_max) + "] rad");
  }
  if (!(config.pan_min < config.pan_max)) {
    throw std::invalid_argument("ScannerConfig: pan_min must be below pan_max, got [" +
                                std::to_string(config.pan_min) + ", " +
                                std::to_string(config.pan_max) + "] rad");
  }
  const Eigen::Matrix4d m = config.T_cab_scanner.matrix();
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if (!m.allFinite() || !(r.transpose() * r).isIdentity(1e-9) || r.determinant() < 0) {
    throw std::invalid_argument(
        "ScannerConfig: T_cab_scanner must be a finite rigid transform (orthonormal rotation, "
        "determinant +1)");
  }
}

double ScannerGeometry::PulseTime(std::int64_t k) const {
  return static_cast<double>(k) / config_.pulse_rate;
}

std::int64_t ScannerGeometry::FirstPulseAtOrAfter(double t) const {
  RequireFinite(t, "ScannerGeometry::FirstPulseAtOrAfter: t");
  auto k = static_cast<std::int64_t>(std::ceil(t * config_.pulse_rate));
  // Guard against the rounding of t·rate putting the pulse just before t.
  while (PulseTime(k) < t) ++k;
  while (PulseTime(k - 1) >= t) --k;
  return k;
}

double ScannerGeometry::ElevationAt(double t) const {
  RequireFinite(t, "ScannerGeometry::ElevationAt: t");
  // The phase is reduced per revolution before scaling to radians, so long runs (hours at
  // 20 rev/s) keep full precision.
  const double turns = config_.mirror_rate * t;
  const double fraction = turns - std::floor(turns);
  return WrapAngle(config_.mirror_phase + kTwoPi * fraction);
}

bool ScannerGeometry::InActiveArc(double elevation) const {
  return elevation >= config_.active_elevation_min && elevation <= config_.active_elevation_max;
}

double ScannerGeometry::elevation_step() const {
  return kTwoPi * config_.mirror_rate / config_.pulse_rate;
}

void ScannerGeometry::Validate(const PanSweep& pan) const {
  RequireFinite(pan.start_time, "PanSweep: start_time");
  RequireFinite(pan.start_angle, "PanSweep: start_angle");
  RequireFinite(pan.end_angle, "PanSweep: end_angle");
  RequireFinite(pan.rate, "PanSweep: rate");
  for (const double angle : {pan.start_angle, pan.end_angle}) {
    if (angle < config_.pan_min || angle > config_.pan_max) {
      throw std::invalid_argument("PanSweep: angle " + std::to_string(angle / kDegree) +
                                  "° is outside the pan range [" +
                                  std::to_string(config_.pan_min / kDegree) + "°, " +
                                  std::to_string(config_.pan_max / kDegree) + "°]");
    }
  }
  if (pan.rate < 0 || pan.rate > config_.pan_rate_limit) {
    throw std::invalid_argument("PanSweep: rate " + std::to_string(pan.rate / kDegree) +
                                "°/s is outside [0, " +
                                std::to_string(config_.pan_rate_limit / kDegree) + "]°/s");
  }
  if (pan.rate == 0 && pan.start_angle != pan.end_angle) {
    throw std::invalid_argument("PanSweep: a sweep between different angles needs a rate > 0");
  }
}

double ScannerGeometry::PanAtUnchecked(const PanSweep& pan, double t) const {
  if (t <= pan.start_time || pan.start_angle == pan.end_angle) return pan.start_angle;
  const double span = pan.end_angle - pan.start_angle;
  const double travelled = pan.rate * (t - pan.start_time);
  if (travelled >= std::abs(span)) return pan.end_angle;
  return pan.start_angle + std::copysign(travelled, span);
}

double ScannerGeometry::PanAt(const PanSweep& pan, double t) const {
  Validate(pan);
  RequireFinite(t, "ScannerGeometry::PanAt: t");
  return PanAtUnchecked(pan, t);
}

Eigen::Vector3d ScannerGeometry::DirectionInScanner(double elevation, double pan) {
  const double ce = std::cos(elevation);
  return {ce * std::cos(pan), ce * std::sin(pan), std::sin(elevation)};
}

ScanRay ScannerGeometry::Ray(std::int64_t k, const PanSweep& pan) const {
  Validate(pan);
  ScanRay ray;
  ray.index = k;
  ray.time = PulseTime(k);
  ray.elevation = ElevationAt(ray.time);
  ray.pan = PanAtUnchecked(pan, ray.time);
  ray.active = InActiveArc(ray.elevation);
  ray.direction_scanner = DirectionInScanner(ray.elevation, ray.pan);
  ray.origin_cab = config_.T_cab_scanner.translation();
  ray.direction_cab = config_.T_cab_scanner.linear() * ray.direction_scanner;
  return ray;
}

}  // namespace autoshovel::sensors
