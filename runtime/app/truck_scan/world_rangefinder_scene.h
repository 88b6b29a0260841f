// The simulated yard as the excavator's scanning rangefinders see it (excavator seed §2–3): the
// world's terrain and boxes through the project's ray caster (runtime/sensors/raycast.h), and
// optionally dust clouds (§3) composed in front of them. Every rangefinder pulse asks Trace for
// the first solid surface on its ray; the waveform simulation does the rest
// (runtime/sensors/rangefinder/return_waveform.h).
//
// From a RayHit to a SolidHit: range as cast, the surface's Lambertian reflectivity (terrain:
// the material's or the bare floor's; boxes: their own), cos_incidence = |normal · direction|.
// Dust lies in the world nowhere else, so the clouds are held here, in a SimpleScene of dust
// only, and cut at the solid surface (dust behind the target is invisible).
#pragma once

#include <Eigen/Geometry>

#include "runtime/sensors/rangefinder/rangefinder_scene.h"
#include "runtime/sensors/raycast.h"

namespace autoshovel::app {

class WorldRangefinderScene final : public sensors::RangefinderScene {
 public:
  /// Keeps a reference to `world`: it must outlive this scene, and whoever changes the world
  /// updates the RaycastScene (Update, UpdateTerrain, UpdateBoxes) before the next pulse.
  explicit WorldRangefinderScene(const sensors::RaycastScene& world);
  explicit WorldRangefinderScene(sensors::RaycastScene&& world) = delete;

  /// Dust clouds (§3). Throw std::invalid_argument as SimpleScene's do.
  void AddDustSphere(const Eigen::Vector3d& p_world_center, double radius,
                     const sensors::DustProperties& dust);
  void AddDustBox(const Eigen::Isometry3d& T_world_box, const Eigen::Vector3d& half_extents,
                  const sensors::DustProperties& dust);
  /// The dust settles.
  void ClearDust();

  /// A non-finite origin or direction, or a non-positive max_range, sees nothing.
  sensors::RayProfile Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                            double max_range) const override;

 private:
  const sensors::RaycastScene* world_;
  sensors::SimpleScene dust_;
  bool has_dust_ = false;
};

}  // namespace autoshovel::app
