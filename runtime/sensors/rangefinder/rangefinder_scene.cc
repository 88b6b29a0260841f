#include "runtime/sensors/rangefinder/rangefinder_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace autoshovel::sensors {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

bool InUnitInterval(double x) { return x >= 0 && x <= 1; }

void ValidateDust(const DustProperties& dust, const char* what) {
  Require(std::isfinite(dust.extinction) && dust.extinction >= 0,
          std::string(what) + ": extinction must be finite and ≥ 0, got " +
              std::to_string(dust.extinction));
  Require(std::isfinite(dust.lidar_ratio) && dust.lidar_ratio > 0,
          std::string(what) + ": lidar_ratio must be finite and > 0, got " +
              std::to_string(dust.lidar_ratio));
  Require(std::isfinite(dust.granularity) && dust.granularity >= 0,
          std::string(what) + ": granularity must be finite and ≥ 0, got " +
              std::to_string(dust.granularity));
}

void ValidateBox(const Eigen::Isometry3d& T_scene_box, const Eigen::Vector3d& half_extents,
                 const char* what) {
  const Eigen::Matrix3d r = T_scene_box.linear();
  Require(T_scene_box.matrix().allFinite() && (r.transpose() * r).isIdentity(1e-9),
          std::string(what) + ": the box pose must be a finite rigid transform");
  Require(half_extents.allFinite() && (half_extents.array() > 0).all(),
          std::string(what) + ": half extents must be finite and positive");
}

// Slab test (Kay and Kajiya 1986) in the box frame: [t_near, t_far] of the ray's passage
// through the box and the box-frame axis of the entry face. False when the ray misses.
bool SlabInterval(const Eigen::Isometry3d& T_scene_box, const Eigen::Vector3d& half_extents,
                  const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double& t_near,
                  double& t_far, Eigen::Vector3d& entry_normal_box) {
  const Eigen::Vector3d o = T_scene_box.inverse() * origin;
  const Eigen::Vector3d d = T_scene_box.linear().transpose() * direction;
  t_near = -kInf;
  t_far = kInf;
  entry_normal_box = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0) {
      if (std::abs(o[i]) > half_extents[i]) return false;
      continue;
    }
    double t0 = (-half_extents[i] - o[i]) / d[i];
    double t1 = (half_extents[i] - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) {
      t_near = t0;
      entry_normal_box = Eigen::Vector3d::Zero();
      entry_normal_box[i] = d[i] > 0 ? -1.0 : 1.0;
    }
    t_far = std::min(t_far, t1);
    if (t_near > t_far) return false;
  }
  return true;
}

}  // namespace

void ValidateRayProfile(const RayProfile& profile) {
  // Called for every simulated pulse: messages are built only when something is wrong.
  if (profile.solid) {
    const SolidHit& s = *profile.solid;
    if (!(std::isfinite(s.range) && s.range >= 0)) {
      throw std::invalid_argument("RayProfile: solid range must be finite and ≥ 0, got " +
                                  std::to_string(s.range));
    }
    if (!InUnitInterval(s.reflectivity)) {
      throw std::invalid_argument("RayProfile: reflectivity must be in [0, 1], got " +
                                  std::to_string(s.reflectivity));
    }
    if (!InUnitInterval(s.cos_incidence)) {
      throw std::invalid_argument("RayProfile: cos_incidence must be in [0, 1], got " +
                                  std::to_string(s.cos_incidence));
    }
  }
  for (const DustSegment& d : profile.dust) {
    if (!(std::isfinite(d.range_begin) && std::isfinite(d.range_end) && d.range_begin >= 0 &&
          d.range_end > d.range_begin)) {
      throw std::invalid_argument(
          "RayProfile: a dust segment needs finite ranges 0 ≤ begin < end, got [" +
          std::to_string(d.range_begin) + ", " + std::to_string(d.range_end) + "]");
    }
    if (!(std::isfinite(d.extinction) && d.extinction >= 0 && std::isfinite(d.backscatter) &&
          d.backscatter >= 0 && std::isfinite(d.granularity) && d.granularity >= 0)) {
      throw std::invalid_argument("RayProfile: dust coefficients must be finite and ≥ 0");
    }
  }
}

FunctionScene::FunctionScene(TraceFunction trace) : trace_(std::move(trace)) {
  Require(static_cast<bool>(trace_), "FunctionScene: the trace function is empty");
}

RayProfile FunctionScene::Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                double max_range) const {
  return trace_(origin, direction, max_range);
}

void SimpleScene::AddPlane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                           double reflectivity) {
  Require(point.allFinite() && normal.allFinite() && normal.norm() > 0,
          "SimpleScene::AddPlane: point and normal must be finite, the normal non-zero");
  Require(InUnitInterval(reflectivity), "SimpleScene::AddPlane: reflectivity must be in [0, 1]");
  planes_.push_back({point, normal.normalized(), reflectivity});
}

void SimpleScene::AddBox(const Eigen::Isometry3d& T_scene_box, const Eigen::Vector3d& half_extents,
                         double reflectivity) {
  ValidateBox(T_scene_box, half_extents, "SimpleScene::AddBox");
  Require(InUnitInterval(reflectivity), "SimpleScene::AddBox: reflectivity must be in [0, 1]");
  boxes_.push_back({T_scene_box, half_extents, reflectivity});
}

void SimpleScene::AddDustSphere(const Eigen::Vector3d& center, double radius,
                                const DustProperties& dust) {
  Require(center.allFinite() && std::isfinite(radius) && radius > 0,
          "SimpleScene::AddDustSphere: centre must be finite, radius finite and > 0");
  ValidateDust(dust, "SimpleScene::AddDustSphere");
  dust_spheres_.push_back({center, radius, dust});
}

void SimpleScene::AddDustBox(const Eigen::Isometry3d& T_scene_box,
                             const Eigen::Vector3d& half_extents, const DustProperties& dust) {
  ValidateBox(T_scene_box, half_extents, "SimpleScene::AddDustBox");
  ValidateDust(dust, "SimpleScene::AddDustBox");
  dust_boxes_.push_back({T_scene_box, half_extents, dust});
}

RayProfile SimpleScene::Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                              double max_range) const {
  RayProfile profile;
  if (!origin.allFinite() || !direction.allFinite() || !(max_range > 0)) return profile;
  const Eigen::Vector3d d = direction.normalized();

  // The nearest solid surface in (0, max_range].
  double best = kInf;
  SolidHit hit;
  for (const Plane& p : planes_) {
    const double denom = p.normal.dot(d);
    if (denom == 0) continue;
    const double t = p.normal.dot(p.point - origin) / denom;
    if (t > 0 && t <= max_range && t < best) {
      best = t;
      hit = {t, p.reflectivity, std::abs(denom)};
    }
  }
  for (const Box& b : boxes_) {
    double t_near = 0, t_far = 0;
    Eigen::Vector3d n_box;
    if (!SlabInterval(b.T_scene_box, b.half_extents, origin, d, t_near, t_far, n_box)) continue;
    // A ray starting inside a box does not see it (the sensor looks out of its housing).
    if (t_near <= 0 || t_near > max_range || t_near >= best) continue;
    best = t_near;
    hit = {t_near, b.reflectivity, std::abs((b.T_scene_box.linear() * n_box).dot(d))};
  }
  if (best < kInf) profile.solid = hit;
  const double end = std::min(best, max_range);

  auto add_dust = [&](double t0, double t1, const DustProperties& dust) {
    t0 = std::max(t0, 0.0);
    t1 = std::min(t1, end);
    if (t1 <= t0) return;
    profile.dust.push_back(
        {t0, t1, dust.extinction, dust.extinction / dust.lidar_ratio, dust.granularity});
  };
  for (const DustSphere& s : dust_spheres_) {
    const Eigen::Vector3d oc = origin - s.center;
    const double b = -oc.dot(d);
    const double disc = b * b - (oc.squaredNorm() - s.radius * s.radius);
    if (disc <= 0) continue;
    const double h = std::sqrt(disc);
    add_dust(b - h, b + h, s.dust);
  }
  for (const DustBox& b : dust_boxes_) {
    double t_near = 0, t_far = 0;
    Eigen::Vector3d n_box;
    if (SlabInterval(b.T_scene_box, b.half_extents, origin, d, t_near, t_far, n_box)) {
      add_dust(t_near, t_far, b.dust);
    }
  }
  return profile;
}

}  // namespace autoshovel::sensors
