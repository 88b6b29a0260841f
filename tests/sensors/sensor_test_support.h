// Worlds and machines shared by the sensor tests and the benchmark.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/plant/world.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::sensors::testing {

inline std::string SourcePath(const std::string& relative) {
  return std::string(AUTOSHOVEL_SOURCE_DIR) + "/" + relative;
}

inline const model::MachineDescription& Xcmg() {
  static const model::MachineDescription d =
      model::LoadMachineDescription(SourcePath("models/loaders/xcmg_968ev.yaml"));
  return d;
}

inline const model::Lidar& FindLidar(const model::MachineDescription& d, const std::string& name) {
  for (const auto& l : d.sensors.lidars) {
    if (l.name == name) return l;
  }
  throw std::runtime_error("no LiDAR " + name);
}

inline model::Material MakeMaterial(const std::string& name, double reflectivity) {
  model::Material m;
  m.name = name;
  m.density = 1600;
  m.reflectivity = reflectivity;
  return m;
}

/// A flat yard of size_x × size_y [m] centred on the world origin, floor at z = 0.
inline plant::World FlatWorld(double size_x, double size_y, double resolution) {
  plant::GridGeometry g;
  g.resolution = resolution;
  g.nx = static_cast<int>(std::lround(size_x / resolution));
  g.ny = static_cast<int>(std::lround(size_y / resolution));
  g.origin = Eigen::Vector2d(-0.5 * g.nx * resolution, -0.5 * g.ny * resolution);
  plant::World w;
  w.terrain = plant::Terrain(g, 0.0);
  w.materials = {MakeMaterial("river_sand", 0.25), MakeMaterial("small_gravel", 0.32)};
  w.ground_reflectivity = 0.2;
  return w;
}

/// Analytic cone over a floor at z = 0: z = max(0, H·(1 − r/R)).
inline double ConeHeight(const Eigen::Vector2d& apex, double H, double R, double x, double y) {
  const double r = std::hypot(x - apex.x(), y - apex.y());
  return std::max(0.0, H * (1.0 - r / R));
}

/// Raises the cells under a cone (cell-centre samples of ConeHeight), keeping the higher of the
/// cone and what is already there.
inline void AddCone(plant::Terrain& t, const Eigen::Vector2d& apex, double H, double R,
                    std::int16_t material) {
  for (int iy = 0; iy < t.ny(); ++iy) {
    for (int ix = 0; ix < t.nx(); ++ix) {
      const Eigen::Vector2d c = t.CellCenter(ix, iy);
      const double z = ConeHeight(apex, H, R, c.x(), c.y());
      if (z > 0 && z > t.height(ix, iy)) {
        t.SetHeight(ix, iy, z);
        t.SetMaterial(ix, iy, material);
      }
    }
  }
}

inline plant::OrientedBox MakeBox(const std::string& name, const Eigen::Vector3d& center,
                                  const Eigen::Vector3d& half, double yaw, core::SemanticClass c,
                                  double reflectivity = 0.3) {
  plant::OrientedBox b;
  b.name = name;
  b.center = center;
  b.half_extents = half;
  b.yaw = yaw;
  b.semantic_class = c;
  b.reflectivity = reflectivity;
  return b;
}

/// The benchmark yard: 60 m × 60 m at 0.05 m (1200 × 1200 cells), three piles at the angle of
/// repose in front of the machine, a bin wall, another loader, a person.
inline plant::World Yard() {
  plant::World w = FlatWorld(60.0, 60.0, 0.05);
  AddCone(w.terrain, {12.0, 0.0}, 4.0, 6.0, 0);
  AddCone(w.terrain, {10.0, 9.0}, 3.0, 4.5, 1);
  AddCone(w.terrain, {16.0, -8.0}, 3.5, 5.0, 1);
  w.obstacles.push_back(MakeBox("bin_wall", {20.0, 0.0, 2.0}, {0.3, 14.0, 2.0}, 0.0,
                                core::SemanticClass::kWall, 0.4));
  w.obstacles.push_back(MakeBox("loader_2", {4.0, -10.0, 1.7}, {4.5, 1.5, 1.7}, 0.6,
                                core::SemanticClass::kOtherLoader, 0.5));
  w.obstacles.push_back(
      MakeBox("person", {6.0, 4.0, 0.9}, {0.25, 0.3, 0.9}, 0.0, core::SemanticClass::kPerson, 0.6));
  return w;
}

/// Bytes of a point cloud, field by field (LidarPoint has padding, whose bytes are not data).
inline std::vector<std::uint8_t> Bytes(const PointCloud& cloud) {
  std::vector<std::uint8_t> out;
  auto put = [&out](const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    out.insert(out.end(), b, b + n);
  };
  put(&cloud.stamp, sizeof cloud.stamp);
  put(cloud.sensor.data(), cloud.sensor.size());
  for (const auto& p : cloud.points) {
    put(p.p_sensor.data(), 3 * sizeof(float));
    put(&p.intensity, sizeof p.intensity);
    put(&p.ring, sizeof p.ring);
    put(&p.time_offset, sizeof p.time_offset);
  }
  return out;
}

}  // namespace autoshovel::sensors::testing
