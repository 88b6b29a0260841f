// Simulated camera: an ideal pinhole (no distortion) ray cast against the yard, giving the
// ground-truth semantic label of every pixel and a shaded 8-bit BGR image.
//
// Frames. The description gives the camera pose in the base-frame convention (x forward, y
// left, z up, rpy as in sensor_pose.h): the camera *body* frame. Images use the optical frame
// (x right, y down, z forward; OpenCV, REP 103 "_optical" frames). The fixed rotation between
// them maps optical z to body x, optical x to body −y and optical y to body −z:
//
//                 [ 0  0  1 ]
//   R_body_opt =  [-1  0  0 ]      T_world_optical = T_world_body · R_body_opt.
//                 [ 0 -1  0 ]
//
// Pixels (OpenCV convention): pixel (u, v) is column u, row v, its centre at image coordinates
// (u, v); a point p (optical frame, p_z > 0) projects to u = fx·p_x/p_z + cx, v = fy·p_y/p_z +
// cy, and is seen by the pixel (round(u), round(v)).
//
// Image formation. Radiance = albedo·(ambient + direct·max(0, n·s)·visible), s the unit vector
// towards the sun, n the surface normal (terrain: the gradient of the bilinear surface, i.e.
// finite differences of the cell heights; boxes: the face normal), `visible` from a shadow ray
// to the sun. Albedo per class, per material for piles (sand yellow-brown, gravel grey), with a
// per-cell texture (±12 % on piles, ±6 % on the floor, a hash of the cell index: deterministic
// and fixed to the ground, so it moves with the terrain in the image as real texture does and
// segmentation has something to see). Sky: a horizon-to-zenith gradient, labelled kOther. The
// exposure maps radiance E to 8 bits through an sRGB-like gamma 1/2.2, then sensor noise
// (Gaussian, σ² = read² + shot·DN) is added and the value is rounded and clipped.
//
// Cost (issue 45; tests/bench/sensor_stages_bench, docs/performance.md). Each box is tested only
// against the pixels its projection covers, not by walking every ray through the yard's box grid;
// the terrain ray is cut at the nearest box; a shadow ray stops at its first occluder. What
// every pixel sees is what RaycastScene::Cast of its ray finds. The gamma comes from a table and
// the noise from a ziggurat generator (Boost.Random), on a stream of the frame's own.
//
// Lighting conditions (what the segmentation must survive, cf. the seed's §4.2 data set):
// - kNormal: sun at the given direction, ambient sky light 0.30, direct 0.75, hard shadows,
//   little noise (read 1 DN).
// - kBright: midday glare: direct 1.3, exposure gain 1.5 and a veiling-glare offset 0.12:
//   highlights clip at 255, contrast drops, hard shadows.
// - kDim: overcast dusk: weak diffuse light (ambient 0.22, direct 0.08, no shadows), low
//   exposure gain 0.35 and the amplified sensor noise of a high analogue gain (read 5 DN, shot
//   0.5 DN).
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string_view>

#include "runtime/model/description.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/rng.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::sensors {

// The yard's lighting is part of the world (plant/world.h), shared with the scenario files.
using plant::Lighting;
using plant::ParseLighting;
using plant::ToString;

struct CameraOptions {
  Lighting lighting = Lighting::kNormal;
  /// Towards the sun, world frame (normalised on use). Default: south-west, 45° elevation.
  Eigen::Vector3d sun_direction = Eigen::Vector3d(-0.5, -0.5, 0.70710678118654757);
  bool shadows = true;     ///< cast shadow rays (kDim never has hard shadows)
  double max_range = 400;  ///< beyond this a pixel sees sky [m]
  /// Dirt on the lens (fault injection): pixels within `lens_dirt_radius_px` of
  /// `lens_dirt_center_px` see a dark, even blot (radiance 0.02, sensor noise still on top),
  /// and the simulator's labels there are ground, what a segmenter would make of a featureless
  /// brown patch low in the image. Radius 0: a clean lens.
  Eigen::Vector2d lens_dirt_center_px = Eigen::Vector2d::Zero();
  double lens_dirt_radius_px = 0;
};

/// Body (x forward, y left, z up) ← optical (x right, y down, z forward).
Eigen::Matrix3d BodyFromOptical();

/// World ← optical frame, from the camera body pose (e.g. SensorInWorld(state, camera.pose)).
Eigen::Isometry3d OpticalInWorld(const Eigen::Isometry3d& T_world_body);

/// Image coordinates of a point in the optical frame; false behind the camera (p_z ≤ 0).
bool ProjectToPixel(const model::Camera& camera, const Eigen::Vector3d& p_optical,
                    Eigen::Vector2d& uv);

/// Unit ray through image coordinates (u, v), optical frame.
Eigen::Vector3d PixelRay(const model::Camera& camera, double u, double v);

/// 255·x^(1/2.2) for x clamped to [0, 1]: the camera's gamma, from a table (within 0.02 DN of
/// std::pow).
double GammaEncode(double exposed);

/// Renders one frame seen from T_world_body (camera body frame in the world). Draws one number
/// from `rng`, which seeds the frame's own noise stream (three normal variates per pixel, in
/// row-major pixel order).
CameraFrame SimulateCameraFrame(const model::Camera& camera, const RaycastScene& scene,
                                const Eigen::Isometry3d& T_world_body, double stamp,
                                const CameraOptions& options, Rng& rng);

}  // namespace autoshovel::sensors
