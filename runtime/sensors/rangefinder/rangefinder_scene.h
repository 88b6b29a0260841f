// What a rangefinder's beam meets along one ray: the first solid surface and the dust it
// crosses on the way (excavator seed §3, Figs. 6–7). The waveform simulation (return_waveform.h)
// needs nothing else, so any world can be plugged in through this interface: the project's
// ray-cast yard (runtime/sensors/raycast.h: RayHit's range, normal and reflectivity fill a
// SolidHit, cos_incidence = |normal · direction|) once it carries dust, or the simple scene
// below, made of planes, boxes and dust clouds, for tests and experiments.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <optional>
#include <vector>

namespace autoshovel::sensors {

/// A surface the beam cannot pass: a Lambertian reflector.
struct SolidHit {
  double range = 0;          ///< along the unit ray direction [m]
  double reflectivity = 0;   ///< Lambertian reflectivity ρ ∈ [0, 1]
  double cos_incidence = 1;  ///< |n·d| ∈ [0, 1]
};

/// A stretch of the ray inside a dust cloud with uniform optical properties.
struct DustSegment {
  double range_begin = 0;  ///< [m]
  double range_end = 0;    ///< [m], > range_begin
  double extinction = 0;   ///< extinction coefficient α [1/m]
  double backscatter = 0;  ///< volume backscatter coefficient β [1/(m·sr)]
  /// Relative standard deviation of the backscatter of one 2.5 cm slice of the segment: the
  /// cloud's lumpiness (particle number fluctuations, eddies). 0 for a perfectly uniform cloud.
  double granularity = 0;
};

/// Everything along one ray up to the first solid surface (dust beyond it is invisible).
struct RayProfile {
  std::optional<SolidHit> solid;
  std::vector<DustSegment> dust;  ///< any order; may overlap (coefficients add)
};

/// Throws std::invalid_argument for a non-finite or negative range, a reflectivity or cosine
/// outside [0, 1], an empty dust segment or negative coefficients.
void ValidateRayProfile(const RayProfile& profile);

/// A world the rangefinders can look at.
class RangefinderScene {
 public:
  virtual ~RangefinderScene() = default;
  /// What lies along origin + r·direction, r ∈ [0, max_range]. `direction` is unit length;
  /// frame is the scene's (the caller transforms the scanner's ray into it).
  virtual RayProfile Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                           double max_range) const = 0;
};

/// Any callable as a scene: the adapter for worlds that live elsewhere.
class FunctionScene final : public RangefinderScene {
 public:
  using TraceFunction =
      std::function<RayProfile(const Eigen::Vector3d&, const Eigen::Vector3d&, double)>;
  /// Throws std::invalid_argument for an empty function.
  explicit FunctionScene(TraceFunction trace);
  RayProfile Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   double max_range) const override;

 private:
  TraceFunction trace_;
};

/// Dust clouds' optical properties. Mineral dust scatters back about 1/50 of what it removes
/// from the beam (a lidar ratio α/β of 40–60 sr is typical of dust), which is the default.
struct DustProperties {
  double extinction = 0.2;    ///< α [1/m]; visibility ≈ 3.9/α (0.2/m: ≈ 20 m)
  double lidar_ratio = 50.0;  ///< α/β [sr]
  double granularity = 0.5;   ///< see DustSegment
};

/// Planes, oriented boxes and dust clouds (spheres and oriented boxes of uniform density).
class SimpleScene final : public RangefinderScene {
 public:
  /// The surfaces. Throw std::invalid_argument for non-finite input, a zero normal, a
  /// reflectivity outside [0, 1] or a non-positive extent.
  void AddPlane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double reflectivity);
  /// `T_scene_box`: the box's centre and axes; `half_extents` along them.
  void AddBox(const Eigen::Isometry3d& T_scene_box, const Eigen::Vector3d& half_extents,
              double reflectivity);
  /// Dust clouds. Throw std::invalid_argument for non-finite input, a non-positive size,
  /// a negative extinction, a non-positive lidar ratio or a negative granularity.
  void AddDustSphere(const Eigen::Vector3d& center, double radius, const DustProperties& dust);
  void AddDustBox(const Eigen::Isometry3d& T_scene_box, const Eigen::Vector3d& half_extents,
                  const DustProperties& dust);

  /// A non-finite origin or direction, or a non-positive max_range, sees nothing (as
  /// RaycastScene::Cast). A ray starting inside a box does not see that box.
  RayProfile Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   double max_range) const override;

 private:
  struct Plane {
    Eigen::Vector3d point, normal;
    double reflectivity;
  };
  struct Box {
    Eigen::Isometry3d T_scene_box;
    Eigen::Vector3d half_extents;
    double reflectivity;
  };
  struct DustSphere {
    Eigen::Vector3d center;
    double radius;
    DustProperties dust;
  };
  struct DustBox {
    Eigen::Isometry3d T_scene_box;
    Eigen::Vector3d half_extents;
    DustProperties dust;
  };

  std::vector<Plane> planes_;
  std::vector<Box> boxes_;
  std::vector<DustSphere> dust_spheres_;
  std::vector<DustBox> dust_boxes_;
};

}  // namespace autoshovel::sensors
