// Simulated LiDARs: a spinning multi-line head (Velodyne VLP-16-like) and a solid-state sensor
// with a non-repetitive rosette pattern (Livox Avia-like), ray cast against the yard.
//
// Scan patterns (LidarScanPattern), in the sensor frame (x forward, y left, z up):
// - "spinning": `lines` beams at elevations spread evenly over vertical_fov, centred on 0
//   (VLP-16: −15°…+15° in 2° steps), ring 0 the lowest. The head turns clockwise seen from above
//   (as a Velodyne), all beams firing together at each azimuth step; the step is
//   Δ = 2π·rate·lines / points_per_second (300 000 pts/s, 16 lines, 10 Hz: 0.192°). A frame is
//   one revolution (or the horizontal_fov part of it) starting at +horizontal_fov/2.
// - "non_repetitive": the rosette of a Risley-prism pair (Livox Mid-40/Avia; Y. Li et al.,
//   "Analytical modeling of the scan pattern of a Risley prism pair", Appl. Opt. 2011). Two
//   counter-rotating wedges (f₁ > 0 > f₂) deflect each beam by w(t) = ½(e^{i2πf₁t} + e^{i2πf₂t})
//   in the unit disc, mapped onto the ellipse of half-axes horizontal_fov/2 × vertical_fov/2
//   (horizontal angle α = ½·hfov·Re w to the left, elevation β = ½·vfov·Im w up). |w| =
//   |cos π(f₁ − f₂)t|: the beam runs out to the rim and back f₁ − f₂ = 200.9 times a second
//   along petals whose axes advance by 180°·(f₁ + f₂)/(f₁ − f₂) = 37.08° = 60°/φ from one petal
//   to the next. Six emitters (the Avia has six) share the prisms, each turned by 60° in the
//   disc; the golden-ratio step makes the six emitters' petals interleave (a low-discrepancy
//   sequence of petal axes) instead of retracing each other. Coverage of the FoV therefore grows
//   with integration time: at 0.25° it is 28 % after one 0.1 s frame, 49 % after 0.2 s, 86 %
//   after 0.5 s, 99 % after 1 s (at 1°: 97 % in one frame). The pattern is a pure function of
//   absolute time, so consecutive frames continue the curve; f₁ = 24231/200 Hz and f₂ =
//   −15953/200 Hz are coprime multiples of 1/200 Hz, so it recurs exactly only after 200 s.
//   `points_per_second` / `rate` points per frame (240 000 / 10 = 24 000), the emitters
//   firing in turn.
//
// Measurement model (SimulateLidarFrame):
// - Range noise: Gaussian, σ(r) = range_noise·(0.5 + 0.5·r/10 m). The description gives σ at
//   10 m; time-of-flight jitter sets a floor at short range, and the falling SNR (received
//   power ∝ 1/r², LiDAR equation) widens it further out.
// - Detection: the LiDAR equation for an extended Lambertian target, P ∝ ρ·cos θ / r², puts
//   the detection limit at r_det = max_range·sqrt(ρ·cos θ / ρ_ref), ρ_ref = 0.8 (datasheet
//   ranges are quoted for 80 % targets: Avia 190 m @ 80 %). Speckle makes the threshold soft:
//   P(return) = 1 / (1 + (r/r_det)^16) (≈ 0.97 at 0.8·r_det, 0.5 at r_det, 0.18 at 1.1·r_det).
//   Nothing returns beyond max_range. Dark material at grazing incidence far away drops out.
// - Intensity: ρ·cos θ (range-compensated, see LidarPoint::intensity).
// - Points are ideal-direction × measured range; the pose is held for the whole frame (no
//   motion distortion: deskewing is the estimator's job and needs time_offset, which is set).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/rng.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::sensors {

/// Reflectivity at which a LiDAR's max_range is quoted.
inline constexpr double kLidarReferenceReflectivity = 0.8;
/// Emitters of the non-repetitive sensor (Livox Avia).
inline constexpr int kRosetteEmitters = 6;
/// Prism rotation frequencies of the rosette [Hz] (see above: 200.92 petals/s, a 60°/φ petal
/// step, a 200 s exact period).
inline constexpr double kRosetteF1 = 121.155;
inline constexpr double kRosetteF2 = -79.765;

/// One fired ray.
struct LidarRay {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< unit, sensor frame
  std::uint16_t ring = 0;
  float time_offset = 0;  ///< after the frame stamp [s]
};

/// The rays of the frame starting at `stamp`. Throws std::invalid_argument for an unknown model
/// or a non-positive rate or point rate.
std::vector<LidarRay> LidarScanPattern(const model::Lidar& lidar, double stamp);

/// Unit direction of the non-repetitive pattern at absolute time `t` for emitter `emitter`.
Eigen::Vector3d RosetteDirection(const model::Lidar& lidar, double t, int emitter);

/// 1σ range noise at range r [m].
double LidarRangeSigma(const model::Lidar& lidar, double range);

/// Probability of a return from a Lambertian target of reflectivity ρ at incidence cos θ.
double LidarReturnProbability(const model::Lidar& lidar, double range, double reflectivity,
                              double cos_incidence);

/// One frame: casts every ray of the pattern from T_world_sensor, keeps the returns, adds the
/// noise. Draws from `rng` in ray order (two draws per ray that hits).
PointCloud SimulateLidarFrame(const model::Lidar& lidar, const RaycastScene& scene,
                              const Eigen::Isometry3d& T_world_sensor, double stamp, Rng& rng);
/// The same with the frame's pattern already computed (LidarScanPattern(lidar, stamp)), for a
/// caller that needs the rays too (the blind-sector check): the pattern is computed once.
PointCloud SimulateLidarFrame(const model::Lidar& lidar, const RaycastScene& scene,
                              const Eigen::Isometry3d& T_world_sensor, double stamp, Rng& rng,
                              const std::vector<LidarRay>& rays);

}  // namespace autoshovel::sensors
