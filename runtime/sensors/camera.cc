#include "runtime/sensors/camera.h"

#include <algorithm>
#include <array>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace autoshovel::sensors {
namespace {

using core::SemanticClass;
using Rgb = Eigen::Array3d;  // linear radiance or albedo, red, green, blue
// Boost's normal variate is Marsaglia and Tsang's ziggurat (one uniform draw for most variates),
// several times cheaper than libstdc++'s polar method (a log and a rejection loop): the camera
// draws three per pixel, half a million per frame.
using NormalVariate = boost::random::normal_distribution<double>;

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

namespace {

// 255·x^(1/2.2) for x in [0, 1]. Written x^(1/2.2) = s^(2/2.2) with s = √x, the curve is nearly
// linear in s (exponent 0.909), so linear interpolation over 1024 equal steps of s stays within
// 0.02 DN of std::pow everywhere (the worst is the first step, where the slope is infinite at 0;
// a test holds it to that), at a fraction of its cost: three per pixel.
class GammaTable {
 public:
  GammaTable() {
    for (int k = 0; k <= kSteps; ++k) {
      dn_[k] = 255.0 * std::pow(static_cast<double>(k) / kSteps, 2.0 / 2.2);
    }
  }
  double operator()(double x) const {
    const double s = std::sqrt(std::clamp(x, 0.0, 1.0)) * kSteps;
    const int k = std::min(static_cast<int>(s), kSteps - 1);
    const double f = s - k;
    return dn_[k] + f * (dn_[k + 1] - dn_[k]);
  }

 private:
  static constexpr int kSteps = 1024;
  std::array<double, kSteps + 1> dn_{};
};

const GammaTable& Gamma() {
  static const GammaTable table;
  return table;
}

// One channel: radiance already through exposure (in [0, 1]) to an 8-bit value with sensor
// noise, σ² = read² + shot·DN, rounded half up and clipped.
std::uint8_t Digitise(double exposed, const Exposure& ex, NormalVariate& gauss, Rng& noise) {
  const double dn = Gamma()(exposed);
  const double sigma = std::sqrt(ex.read_noise * ex.read_noise + ex.shot_noise * dn);
  const double value = dn + sigma * gauss(noise);
  if (!(value > 0)) return 0;
  if (value >= 255) return 255;
  return static_cast<std::uint8_t>(value + 0.5);
}

// The pixel rectangle [u0, u1] × [v0, v1] whose rays can meet `box`: the bounds of the projection
// of the part of the box in front of the camera (its corners in front, and where its edges cross
// the plane just in front of the centre), widened by a pixel. Empty (u0 > u1) when the box lies
// wholly behind. A ray through a pixel outside it cannot meet the box, so testing only these
// pixels finds what a test of every ray would.
struct PixelRect {
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;
};

PixelRect ProjectedRect(const plant::OrientedBox& box, const model::Camera& camera,
                        const Eigen::Isometry3d& T_optical_world) {
  constexpr double kNear = 1e-6;  // [m] optical z of the clipping plane
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  const Eigen::Vector3d h = box.half_extents.cwiseAbs();
  std::array<Eigen::Vector3d, 8> corner;
  for (int k = 0; k < 8; ++k) {
    const double x = (k & 1 ? 1 : -1) * h.x(), y = (k & 2 ? 1 : -1) * h.y();
    const double z = (k & 4 ? 1 : -1) * h.z();
    const Eigen::Vector3d p_world = box.center + Eigen::Vector3d(c * x - s * y, s * x + c * y, z);
    corner[k] = T_optical_world * p_world;
  }
  PixelRect r;
  if (!std::all_of(corner.begin(), corner.end(),
                   [](const Eigen::Vector3d& p) { return p.allFinite(); })) {
    // Not a box one can bound (the slab test decides each ray): every pixel.
    r.u1 = camera.width_px - 1, r.v1 = camera.height_px - 1;
    return r;
  }
  double u_lo = std::numeric_limits<double>::infinity(), v_lo = u_lo;
  double u_hi = -u_lo, v_hi = -u_lo;
  auto include = [&](const Eigen::Vector3d& p) {
    const double u = camera.fx * p.x() / p.z() + camera.cx;
    const double v = camera.fy * p.y() / p.z() + camera.cy;
    u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u);
    v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
  };
  for (int k = 0; k < 8; ++k) {
    if (corner[k].z() >= kNear) include(corner[k]);
    for (int bit = 1; bit < 8; bit <<= 1) {  // the edges to the corners one bit above
      const int j = k | bit;
      if (j == k) continue;
      const double za = corner[k].z() - kNear, zb = corner[j].z() - kNear;
      if ((za < 0) == (zb < 0)) continue;
      const double f = za / (za - zb);
      Eigen::Vector3d p = corner[k] + f * (corner[j] - corner[k]);
      p.z() = kNear;
      include(p);
    }
  }
  if (!(u_lo <= u_hi) || !(v_lo <= v_hi)) return r;  // behind the camera, or not finite
  const double w = camera.width_px - 1, hgt = camera.height_px - 1;
  r.u0 = static_cast<int>(std::floor(std::clamp(u_lo - 1, 0.0, w)));
  r.u1 = static_cast<int>(std::ceil(std::clamp(u_hi + 1, 0.0, w)));
  r.v0 = static_cast<int>(std::floor(std::clamp(v_lo - 1, 0.0, hgt)));
  r.v1 = static_cast<int>(std::ceil(std::clamp(v_hi + 1, 0.0, hgt)));
  if (u_hi + 1 < 0 || u_lo - 1 > w || v_hi + 1 < 0 || v_lo - 1 > hgt) r.u1 = r.u0 - 1;
  return r;
}

}  // namespace

double GammaEncode(double exposed) { return Gamma()(exposed); }

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
  // The sensor noise has a stream of its own, seeded by one draw of the caller's: what the
  // camera draws depends on the image size alone, and other sensors' streams do not depend on
  // it.
  Rng noise(rng());
  NormalVariate gauss;
  std::optional<ParallelRayBoxes> sun_boxes;  // the shadow rays' boxes
  if (shadows) sun_boxes.emplace(scene, sun);

  CameraFrame frame;
  frame.stamp = stamp;
  frame.width = camera.width_px;
  frame.height = camera.height_px;
  const std::size_t n = static_cast<std::size_t>(frame.width) * frame.height;
  frame.labels.resize(n);
  frame.bgr.resize(3 * n);
  auto ray = [&](int u, int v) -> Eigen::Vector3d { return R * PixelRay(camera, u, v); };
  auto dirty = [&](int u, int v) {
    return options.lens_dirt_radius_px > 0 &&
           (Eigen::Vector2d(u, v) - options.lens_dirt_center_px).norm() <=
               options.lens_dirt_radius_px;
  };

  // The boxes first, each over the pixels its projection covers: the nearest box per pixel, as
  // RaycastScene::CastBoxes finds it (the same slab test, in index order, a later box winning a
  // tie), without walking every ray through the yard's box grid.
  std::vector<double> box_range(n, options.max_range);
  std::vector<int> box_index(n, -1);
  const Eigen::Isometry3d T_optical_world = T_world_optical.inverse();
  for (int b = 0; b < static_cast<int>(scene.boxes().size()); ++b) {
    const PixelRect r = ProjectedRect(scene.boxes()[b], camera, T_optical_world);
    for (int v = r.v0; v <= r.v1; ++v) {
      for (int u = r.u0; u <= r.u1; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * frame.width + u;
        double range;
        Eigen::Vector3d normal;
        if (scene.IntersectBoxAt(b, origin, ray(u, v), box_range[i], range, normal)) {
          box_range[i] = range;
          box_index[i] = b;
        }
      }
    }
  }

  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * frame.width + u;
      const Eigen::Vector3d d = ray(u, v);
      Rgb radiance;
      if (dirty(u, v)) {
        frame.labels[i] = static_cast<std::uint8_t>(SemanticClass::kGround);
        radiance = Rgb::Constant(0.02);
      } else {
        // RaycastScene::Cast: the terrain up to the nearest box, else that box.
        RayHit hit = scene.CastTerrain(origin, d, box_range[i]);
        if (!hit.hit && box_index[i] >= 0) {
          Eigen::Vector3d normal;
          double range;
          scene.IntersectBoxAt(box_index[i], origin, d, options.max_range, range, normal);
          hit = scene.BoxHit(box_index[i], origin, d, range, normal);
        }
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
          // A surface seen from behind (a ray grazing into a terrain fold) is lit like its
          // front.
          Eigen::Vector3d normal = hit.normal;
          if (normal.dot(d) > 0) normal = -normal;
          double lambert = std::max(0.0, normal.dot(sun));
          if (lambert > 0 && shadows) {
            const Eigen::Vector3d start = hit.point + 1e-3 * normal;
            if (sun_boxes->Occluded(start, options.max_range) ||
                scene.CastTerrain(start, sun, options.max_range).hit) {
              lambert = 0;
            }
          }
          radiance = albedo * (ex.ambient + ex.direct * lambert);
        }
      }
      const Rgb exposed = (ex.gain * radiance + ex.flare).min(1.0).max(0.0);
      // BGR: red (c = 0) goes last.
      for (int c = 0; c < 3; ++c)
        frame.bgr[3 * i + (2 - c)] = Digitise(exposed[c], ex, gauss, noise);
    }
  }
  return frame;
}

}  // namespace autoshovel::sensors
