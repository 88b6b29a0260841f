// A simulated truck bed for the dump planning tests (excavator seed §4.3): the true soil surface
// on a fine raster, bucket loads poured onto it, and a scanner that samples it through the bed
// pose with range noise and an occluded strip. Test-only.
//
// Heap model: a load of volume V lands as a cone at the angle of repose, and the surface is then
// relaxed until no slope between neighbouring raster cells exceeds the angle of repose (material
// slides downhill, the walls keep it in the bed), so volume is conserved and a load poured on an
// earlier heap runs off it as soil does. Crude, but it makes "dumping on a heap" cost evenness
// the way it does in a real bed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "runtime/planning/dump/bed_height_map.h"

namespace autoshovel::planning::dump_sim {

/// A bed pose as truck recognition might report it: beside the excavator, yawed, on ground that
/// tilts it slightly, its opening 1.6 m above the excavator's ground.
Eigen::Isometry3d ExampleBedPose();

/// The 4.8 m × 2.4 m bed of the tests: 32 × 16 = 512 cells at 15 cm, §4.3's "on the order of
/// 500 cells".
inline constexpr BedGeometry kExampleBed{4.8, 2.4};

struct ScanConfig {
  double points_per_m2 = 300;  ///< about 7 returns per 15 cm cell
  double noise_m = 0.03;       ///< range noise along z [m]
  double occluded_y_m = 0;     ///< the strip y < this is hidden by the near wall [m]
};

class SimulatedBed {
 public:
  /// Flat, empty bed on a raster of `raster_m` cells; `repose_deg` is the soil's angle of repose.
  explicit SimulatedBed(const BedGeometry& bed, double raster_m = 0.075, double repose_deg = 35);

  /// Pours `volume_m3` centred at bed-frame plan point `p_bed_xy` and lets it settle.
  void Pour(const Eigen::Vector2d& p_bed_xy, double volume_m3);
  /// Adds a cone (no settling) of apex height `peak_m` and base radius `radius_m`.
  void AddCone(const Eigen::Vector2d& p_bed_xy, double peak_m, double radius_m);
  /// Sets the whole surface to `height_m`.
  void Fill(double height_m) { heights_.setConstant(height_m); }
  /// Lowers the raster cells whose centres lie in the given bed-frame box by `depth_m`.
  void Dig(const Eigen::Vector2d& min_xy, const Eigen::Vector2d& max_xy, double depth_m);
  /// Adds a plane z += slope_x · x.
  void Tilt(double slope_x);

  /// True surface height at a bed-frame plan point (the raster cell holding it) [m].
  double Height(const Eigen::Vector2d& p_bed_xy) const;
  /// Mean true height over the axis-aligned square of side `side_m` centred at `p_bed_xy`.
  double MeanHeight(const Eigen::Vector2d& p_bed_xy, double side_m) const;
  /// Volume of soil in the bed [m³].
  double Volume() const { return heights_.sum() * raster_m_ * raster_m_; }

  /// Scanner returns in the world frame: uniform random plan positions over the bed, z from the
  /// true surface plus Gaussian noise, then mapped by T_world_bed.
  std::vector<Eigen::Vector3d> Scan(const Eigen::Isometry3d& T_world_bed, const ScanConfig& config,
                                    std::mt19937& rng) const;
  /// The true surface as a fully known map on the simulation raster (for SummarizeFill).
  BedHeightMap Truth() const;

  const BedGeometry& bed() const { return bed_; }

 private:
  void Settle();

  BedGeometry bed_;
  double raster_m_;
  double tan_repose_;
  Eigen::MatrixXd heights_;  ///< rows along bed x, columns across
};

}  // namespace autoshovel::planning::dump_sim
