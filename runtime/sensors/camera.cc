#include "runtime/sensors/camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace autoshovel::sensors {
namespace {

using core::SemanticClass;
using Rgb = Eigen::Array3d;  // linear radiance or albedo, red, green, blue

struct Exposure {
  double ambient, direct, gain, flare, read_noise, shot_noise;
  bool shadows;
};

Exposure ExposureOf(Lighting lighting) {
  switch (lighting) {
    case Lighting::kBright:
      return {0.45, 1.3, 1.5, 0.12, 1.0, 0.1, true};
    case Lighting::kDim:
      return {0.22, 0.08, 0.35, 0.0, 5.0, 0.5, false};
    case Lighting::kNormal:
      break;
  }
  return {0.30, 0.75, 1.0, 0.0, 1.0, 0.1, true};
}

// Visible-light albedo of a pile by its material's name: sand is yellow-brown, gravel grey
// (its reflectivity field is at the LiDAR's 905 nm, not in the visible).
Rgb PileAlbedo(const plant::World& world, int material) {
  if (material >= 0 && material < static_cast<int>(world.materials.size())) {
    const std::string& name = world.materials[material].name;
    if (name.find("sand") != std::string::npos) return {0.62, 0.50, 0.33};
    if (name.find("big_gravel") != std::string::npos) return {0.40, 0.39, 0.37};
    if (name.find("gravel") != std::string::npos) return {0.48, 0.46, 0.42};
    if (name.find("ore") != std::string::npos) return {0.36, 0.19, 0.13};  // haematite red-brown
  }
  return {0.45, 0.38, 0.30};
}

Rgb ClassAlbedo(SemanticClass c) {
  switch (c) {
    case SemanticClass::kGround:
      return {0.30, 0.28, 0.25};  // dusty concrete
    case SemanticClass::kPile:
      return {0.45, 0.38, 0.30};
    case SemanticClass::kOwnLoader:
      return {0.75, 0.55, 0.05};  // XCMG yellow
    case SemanticClass::kOtherLoader:
      return {0.80, 0.30, 0.05};  // orange
    case SemanticClass::kPerson:
      return {0.70, 0.90, 0.10};  // hi-vis yellow-green vest
    case SemanticClass::kWall:
      return {0.50, 0.50, 0.48};  // concrete
    case SemanticClass::kOther:
      break;
  }
  return {0.25, 0.22, 0.20};
}

// A hash of a cell index to [−1, 1] (SplitMix64 finaliser): a fixed texture on the ground.
double CellTexture(int ix, int iy) {
  std::uint64_t z = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix)) << 32) ^
                    static_cast<std::uint32_t>(iy);
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

Rgb Sky(const Eigen::Vector3d& d) {
  const double up = std::clamp(d.z(), 0.0, 1.0);
  const Rgb horizon(0.75, 0.80, 0.85), zenith(0.35, 0.50, 0.80);
  return horizon + (zenith - horizon) * std::sqrt(up);
}

}  // namespace

Eigen::Matrix3d BodyFromOptical() {
  Eigen::Matrix3d R;
  // Columns: the optical x (right), y (down), z (forward) axes in the body frame.
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return R;
}

Eigen::Isometry3d OpticalInWorld(const Eigen::Isometry3d& T_world_body) {
  Eigen::Isometry3d T = T_world_body;
  T.linear() = T_world_body.linear() * BodyFromOptical();
  return T;
}

bool ProjectToPixel(const model::Camera& camera, const Eigen::Vector3d& p_optical,
                    Eigen::Vector2d& uv) {
  if (!(p_optical.z() > 0)) return false;
  uv = Eigen::Vector2d(camera.fx * p_optical.x() / p_optical.z() + camera.cx,
                       camera.fy * p_optical.y() / p_optical.z() + camera.cy);
  return true;
}

Eigen::Vector3d PixelRay(const model::Camera& camera, double u, double v) {
  return Eigen::Vector3d((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0)
      .normalized();
}

CameraFrame SimulateCameraFrame(const model::Camera& camera, const RaycastScene& scene,
                                const Eigen::Isometry3d& T_world_body, double stamp,
                                const CameraOptions& options, Rng& rng) {
  if (camera.width_px <= 0 || camera.height_px <= 0 || !(camera.fx > 0) || !(camera.fy > 0)) {
    throw std::invalid_argument("camera: size and focal lengths must be positive");
  }
  const Exposure ex = ExposureOf(options.lighting);
  const bool shadows = options.shadows && ex.shadows;
  const Eigen::Vector3d sun = options.sun_direction.normalized();
  const Eigen::Isometry3d T_world_optical = OpticalInWorld(T_world_body);
  const Eigen::Matrix3d R = T_world_optical.linear();
  const Eigen::Vector3d origin = T_world_optical.translation();
  const plant::World& world = scene.world();

  CameraFrame frame;
  frame.stamp = stamp;
  frame.width = camera.width_px;
  frame.height = camera.height_px;
  const std::size_t n = static_cast<std::size_t>(frame.width) * frame.height;
  frame.labels.resize(n);
  frame.bgr.resize(3 * n);
  std::normal_distribution<double> gauss(0.0, 1.0);

  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * frame.width + u;
      const Eigen::Vector3d d = R * PixelRay(camera, u, v);
      Rgb radiance;
      if (options.lens_dirt_radius_px > 0 &&
          (Eigen::Vector2d(u, v) - options.lens_dirt_center_px).norm() <=
              options.lens_dirt_radius_px) {
        frame.labels[i] = static_cast<std::uint8_t>(SemanticClass::kGround);
        radiance = Rgb::Constant(0.02);
        const Rgb exposed = (ex.gain * radiance + ex.flare).min(1.0).max(0.0);
        for (int c = 0; c < 3; ++c) {
          const double dn = 255.0 * std::pow(exposed[c], 1.0 / 2.2);
          const double sigma = std::sqrt(ex.read_noise * ex.read_noise + ex.shot_noise * dn);
          frame.bgr[3 * i + (2 - c)] = static_cast<std::uint8_t>(
              std::clamp(std::round(dn + sigma * gauss(rng)), 0.0, 255.0));
        }
        continue;
      }
      const RayHit hit = scene.Cast(origin, d, options.max_range);
      if (!hit.hit) {
        frame.labels[i] = static_cast<std::uint8_t>(SemanticClass::kOther);
        radiance = Sky(d);
      } else {
        frame.labels[i] = static_cast<std::uint8_t>(hit.semantic_class);
        Rgb albedo = ClassAlbedo(hit.semantic_class);
        if (hit.box < 0) {
          const bool pile = hit.semantic_class == SemanticClass::kPile;
          if (pile) albedo = PileAlbedo(world, world.terrain.material(hit.cell_x, hit.cell_y));
          albedo *= 1.0 + (pile ? 0.12 : 0.06) * CellTexture(hit.cell_x, hit.cell_y);
        }
        // A surface seen from behind (a ray grazing into a terrain fold) is lit like its front.
        Eigen::Vector3d normal = hit.normal;
        if (normal.dot(d) > 0) normal = -normal;
        double lambert = std::max(0.0, normal.dot(sun));
        if (lambert > 0 && shadows) {
          const Eigen::Vector3d start = hit.point + 1e-3 * normal;
          if (scene.Cast(start, sun, options.max_range).hit) lambert = 0;
        }
        radiance = albedo * (ex.ambient + ex.direct * lambert);
      }
      const Rgb exposed = (ex.gain * radiance + ex.flare).min(1.0).max(0.0);
      for (int c = 0; c < 3; ++c) {
        const double dn = 255.0 * std::pow(exposed[c], 1.0 / 2.2);
        const double sigma = std::sqrt(ex.read_noise * ex.read_noise + ex.shot_noise * dn);
        const double value = std::round(dn + sigma * gauss(rng));
        // BGR: red (c = 0) goes last.
        frame.bgr[3 * i + (2 - c)] = static_cast<std::uint8_t>(std::clamp(value, 0.0, 255.0));
      }
    }
  }
  return frame;
}

}  // namespace autoshovel::sensors
