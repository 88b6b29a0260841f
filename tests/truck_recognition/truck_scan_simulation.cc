#include "truck_scan_simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace autoshovel::perception::truck_sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

double RayBox(const SimBox& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  const Eigen::Matrix3d R = box.T_world_box.linear();
  const Eigen::Vector3d o = R.transpose() * (origin - box.T_world_box.translation());
  const Eigen::Vector3d d = R.transpose() * direction;
  double t_enter = -kInf;
  double t_exit = kInf;
  for (int i = 0; i < 3; ++i) {
    const double h = box.half_extents(i);
    if (std::abs(d(i)) < 1e-12) {
      if (std::abs(o(i)) > h) return kInf;
      continue;
    }
    const double t1 = (-h - o(i)) / d(i);
    const double t2 = (h - o(i)) / d(i);
    t_enter = std::max(t_enter, std::min(t1, t2));
    t_exit = std::min(t_exit, std::max(t1, t2));
  }
  if (t_exit < t_enter || t_enter <= 1e-9) return kInf;
  return t_enter;
}

double RayCone(const SimCone& cone, double ground_z, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& d) {
  // (x − cx)² + (y − cy)² = k² (apex_z − z)², k = R / h, on the lower nappe 0 ≤ z − ground ≤ h.
  const double k2 = std::pow(cone.base_radius / cone.height, 2);
  const double qx = origin.x() - cone.p_world_centre.x();
  const double qy = origin.y() - cone.p_world_centre.y();
  const double w = ground_z + cone.height - origin.z();
  const double a = d.x() * d.x() + d.y() * d.y() - k2 * d.z() * d.z();
  const double b = 2 * (qx * d.x() + qy * d.y() + k2 * w * d.z());
  const double c = qx * qx + qy * qy - k2 * w * w;
  double roots[2] = {kInf, kInf};
  if (std::abs(a) < 1e-12) {
    if (std::abs(b) > 1e-12) roots[0] = -c / b;
  } else {
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return kInf;
    const double s = std::sqrt(disc);
    roots[0] = (-b - s) / (2 * a);
    roots[1] = (-b + s) / (2 * a);
    if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
  }
  for (double t : roots) {
    if (!(t > 1e-9) || !std::isfinite(t)) continue;
    const double z = origin.z() + t * d.z() - ground_z;
    if (z >= 0 && z <= cone.height) return t;
  }
  return kInf;
}

}  // namespace

void SimScene::AddBox(const Eigen::Vector3d& p_world_bottom, double yaw_rad,
                      const Eigen::Vector3d& size) {
  SimBox box;
  box.T_world_box.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).matrix();
  box.T_world_box.translation() = p_world_bottom + Eigen::Vector3d(0, 0, 0.5 * size.z());
  box.half_extents = 0.5 * size;
  boxes.push_back(box);
}

double CastRay(const SimScene& scene, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& direction, double max_range) {
  double best = kInf;
  if (direction.z() < -1e-12) best = (scene.ground_z - origin.z()) / direction.z();
  for (const SimBox& box : scene.boxes) best = std::min(best, RayBox(box, origin, direction));
  for (const SimCone& cone : scene.cones) {
    best = std::min(best, RayCone(cone, scene.ground_z, origin, direction));
  }
  return best <= max_range ? best : kInf;
}

TruckTruth AddTruck(const TruckSpec& spec, const Eigen::Vector2d& p_world_bed_xy, double yaw_rad,
                    SimScene* scene) {
  const double L = spec.inner_length;
  const double W = spec.inner_width;
  const double H = spec.wall_height;
  const double t = spec.wall_thickness;
  const double rim = spec.floor_height + H;

  TruckTruth truth;
  truth.T_world_bed.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).matrix();
  truth.T_world_bed.translation() = Eigen::Vector3d(p_world_bed_xy.x(), p_world_bed_xy.y(), rim);
  truth.yaw_rad = yaw_rad;
  truth.length = L;
  truth.width = W;
  truth.wall_height = H;
  truth.floor_height = spec.floor_height;
  truth.rim_height = rim;
  truth.p_world_corners = {truth.T_world_bed * Eigen::Vector3d(L / 2, W / 2, 0),
                           truth.T_world_bed * Eigen::Vector3d(L / 2, -W / 2, 0),
                           truth.T_world_bed * Eigen::Vector3d(-L / 2, -W / 2, 0),
                           truth.T_world_bed * Eigen::Vector3d(-L / 2, W / 2, 0)};

  for (const app::TruckBodyBox& part : app::TruckBodyBoxes(spec)) {
    SimBox box;
    box.half_extents = 0.5 * (part.hi_bed - part.lo_bed);
    Eigen::Isometry3d T_bed_box = Eigen::Isometry3d::Identity();
    T_bed_box.translation() = 0.5 * (part.hi_bed + part.lo_bed);
    box.T_world_box = truth.T_world_bed * T_bed_box;
    scene->boxes.push_back(box);
  }

  const double rear_end = -L / 2 - (spec.has_tailgate ? t : 0.0);
  const double cab_end = L / 2 + t + spec.cab_gap + spec.cab_length;
  const double front = cab_end;
  const double back = rear_end;
  const Eigen::Vector3d mid = truth.T_world_bed * Eigen::Vector3d(0.5 * (front + back), 0, 0);
  truth.p_world_footprint_centre = mid.head<2>();
  truth.footprint_radius = std::hypot(0.5 * (front - back) + 0.2, W / 2 + t + 0.2);
  return truth;
}

std::vector<Scanline> SimulateScan(const SimScene& scene, const ScannerSpec& scanner, Rng& rng) {
  std::normal_distribution<double> noise(0.0, scanner.range_noise_sigma);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const int num_lines =
      static_cast<int>(
          std::floor((scanner.pan_end_deg - scanner.pan_start_deg) / scanner.pan_step_deg + 1e-9)) +
      1;
  const int num_samples =
      static_cast<int>(std::floor((scanner.elevation_max_deg - scanner.elevation_min_deg) /
                                      scanner.elevation_step_deg +
                                  1e-9)) +
      1;
  std::vector<Scanline> lines(static_cast<std::size_t>(std::max(num_lines, 0)));
  for (int k = 0; k < num_lines; ++k) {
    Scanline& line = lines[static_cast<std::size_t>(k)];
    line.p_world_sensor = scanner.p_world_sensor;
    line.points.resize(static_cast<std::size_t>(num_samples));
    for (int j = 0; j < num_samples; ++j) {
      const double elevation_deg = scanner.elevation_min_deg + j * scanner.elevation_step_deg;
      double azimuth_deg = scanner.pan_start_deg + k * scanner.pan_step_deg;
      if (scanner.pan_during_sweep) {
        azimuth_deg += scanner.pan_step_deg * (elevation_deg - scanner.elevation_min_deg) / 360.0;
      }
      const double el = elevation_deg * kDegToRad;
      const double az = azimuth_deg * kDegToRad;
      const Eigen::Vector3d direction(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                      std::sin(el));
      const double range = CastRay(scene, scanner.p_world_sensor, direction, scanner.max_range);
      if (!std::isfinite(range)) continue;
      const double measured = range + noise(rng);
      if (uniform(rng) < scanner.dropout_probability) continue;
      ScanPoint& point = line.points[static_cast<std::size_t>(j)];
      point.p_world = scanner.p_world_sensor + measured * direction;
      point.valid = true;
    }
  }
  return lines;
}

}  // namespace autoshovel::perception::truck_sim
