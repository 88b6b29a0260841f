#include "runtime/app/truck_scan/world_rangefinder_scene.h"

#include <algorithm>
#include <cmath>

namespace autoshovel::app {

WorldRangefinderScene::WorldRangefinderScene(const sensors::RaycastScene& world) : world_(&world) {}

void WorldRangefinderScene::AddDustSphere(const Eigen::Vector3d& p_world_center, double radius,
                                          const sensors::DustProperties& dust) {
  dust_.AddDustSphere(p_world_center, radius, dust);
  has_dust_ = true;
}

void WorldRangefinderScene::AddDustBox(const Eigen::Isometry3d& T_world_box,
                                       const Eigen::Vector3d& half_extents,
                                       const sensors::DustProperties& dust) {
  dust_.AddDustBox(T_world_box, half_extents, dust);
  has_dust_ = true;
}

void WorldRangefinderScene::ClearDust() {
  dust_ = sensors::SimpleScene();
  has_dust_ = false;
}

sensors::RayProfile WorldRangefinderScene::Trace(const Eigen::Vector3d& origin,
                                                 const Eigen::Vector3d& direction,
                                                 double max_range) const {
  sensors::RayProfile profile;
  if (!origin.allFinite() || !direction.allFinite() || !(max_range > 0)) return profile;
  const Eigen::Vector3d d = direction.normalized();
  const sensors::RayHit hit = world_->Cast(origin, d, max_range);
  double end = max_range;
  if (hit.hit && std::isfinite(hit.range)) {
    sensors::SolidHit solid;
    solid.range = hit.range;
    solid.reflectivity = std::clamp(hit.reflectivity, 0.0, 1.0);
    solid.cos_incidence = std::clamp(std::abs(hit.normal.dot(d)), 0.0, 1.0);
    profile.solid = solid;
    end = hit.range;
  }
  // The dust-only scene has no solid: its segments run to `end`, the world's surface.
  if (has_dust_ && end > 0) profile.dust = dust_.Trace(origin, d, end).dust;
  return profile;
}

}  // namespace autoshovel::app
