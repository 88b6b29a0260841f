#include "identification/camera_lidar/street_simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace autoshovel::identification {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kNone = std::numeric_limits<double>::infinity();

struct Object {
  enum Kind { kBox, kCylinder } kind = kBox;
  Eigen::Vector3d centre;         // box centre / cylinder axis foot
  Eigen::Vector3d half{1, 1, 1};  // box half sizes; cylinder: radius, -, height
  double yaw = 0;
  double reflectivity = 0.5;
  cv::Vec3b colour{128, 128, 128};
};

// Distance along the unit ray to a box turned by `yaw` about z, and the outward normal there.
double HitBox(const Object& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
              Eigen::Vector3d& normal) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(b.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d lo = R.transpose() * (o - b.centre), ld = R.transpose() * d;
  double t_near = -kNone, t_far = kNone;
  int axis = -1;
  double sign = 0;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(ld[i]) < 1e-12) {
      if (std::abs(lo[i]) > b.half[i]) return kNone;
      continue;
    }
    double t1 = (-b.half[i] - lo[i]) / ld[i], t2 = (b.half[i] - lo[i]) / ld[i];
    double s = -1;
    if (t1 > t2) {
      std::swap(t1, t2);
      s = 1;
    }
    if (t1 > t_near) {
      t_near = t1;
      axis = i;
      sign = s;
    }
    t_far = std::min(t_far, t2);
  }
  if (t_near > t_far || t_far < 0 || t_near < 0.05 || axis < 0) return kNone;
  Eigen::Vector3d local = Eigen::Vector3d::Zero();
  local[axis] = sign;
  normal = R * local;
  return t_near;
}

double HitCylinder(const Object& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                   Eigen::Vector3d& normal) {
  const Eigen::Vector2d p(o.x() - c.centre.x(), o.y() - c.centre.y()), q(d.x(), d.y());
  const double a = q.squaredNorm(), b = 2 * p.dot(q), k = p.squaredNorm() - c.half.x() * c.half.x();
  const double disc = b * b - 4 * a * k;
  if (a < 1e-12 || disc < 0) return kNone;
  const double t = (-b - std::sqrt(disc)) / (2 * a);
  if (t < 0.05) return kNone;
  const double z = o.z() + t * d.z();
  if (z < c.centre.z() || z > c.centre.z() + c.half.z()) return kNone;
  const Eigen::Vector2d radial = p + t * q;
  normal = Eigen::Vector3d(radial.x(), radial.y(), 0).normalized();
  return t;
}

struct Scene {
  double slope, cross, height;
  std::vector<Object> objects;
  double ground_reflectivity = 0.18;

  double GroundZ(double x, double y) const { return -height + slope * x + cross * y; }

  // Nearest hit: object index (−1 ground, −2 nothing), distance, normal.
  int Cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double& distance,
           Eigen::Vector3d& normal) const {
    int hit = -2;
    distance = kNone;
    // Ground: n · p = −h with n = (−slope, −cross, 1).
    const Eigen::Vector3d n(-slope, -cross, 1.0);
    const double denominator = n.dot(d);
    if (denominator < -1e-9) {
      const double t = (-height - n.dot(o)) / denominator;
      if (t > 0.05 && t < 200) {
        distance = t;
        normal = n.normalized();
        hit = -1;
      }
    }
    for (std::size_t k = 0; k < objects.size(); ++k) {
      Eigen::Vector3d m;
      const double t = objects[k].kind == Object::kBox ? HitBox(objects[k], o, d, m)
                                                       : HitCylinder(objects[k], o, d, m);
      if (t < distance) {
        distance = t;
        normal = m;
        hit = static_cast<int>(k);
      }
    }
    return hit;
  }
};

Scene MakeScene(const StreetSceneOptions& options, std::mt19937_64& rng) {
  Scene scene{options.ground_slope, options.ground_cross_slope, options.lidar_height, {}};
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto place = [&](Object o, double half_height) {
    o.centre.z() =
        scene.GroundZ(o.centre.x(), o.centre.y()) + (o.kind == Object::kBox ? half_height : 0.0);
    scene.objects.push_back(o);
  };
  auto free_at = [&](double x, double y, double clearance) {
    for (const Object& o : scene.objects) {
      if (std::hypot(o.centre.x() - x, o.centre.y() - y) < clearance + o.half.head<2>().norm()) {
        return false;
      }
    }
    return true;
  };
  // A building front across the end of the street.
  Object building;
  building.centre = {34, 0, 0};
  building.half = {1.0, 20.0, 6.0};
  building.reflectivity = 0.25;
  building.colour = {150, 160, 175};
  place(building, 6.0);
  // Cars, turned a little, in two lanes.
  const cv::Vec3b car_colours[] = {{40, 40, 200}, {210, 210, 210}, {30, 30, 30}, {160, 90, 20}};
  for (int k = 0, tries = 0; k < 4 && tries < 200; ++tries) {
    Object car;
    car.centre = {8 + 14 * unit(rng), (unit(rng) < 0.5 ? -1 : 1) * (1.5 + 3 * unit(rng)), 0};
    car.half = {2.2, 0.9, 0.75};
    car.yaw = 0.3 * (unit(rng) - 0.5);
    car.reflectivity = 0.45 + 0.3 * unit(rng);
    car.colour = car_colours[k];
    if (!free_at(car.centre.x(), car.centre.y(), 1.0)) continue;
    place(car, 0.75);
    ++k;
  }
  // Poles at the kerbs.
  for (int k = 0, tries = 0; k < 3 && tries < 200; ++tries) {
    Object pole;
    pole.kind = Object::kCylinder;
    pole.centre = {6 + 12 * unit(rng), (unit(rng) < 0.5 ? -1 : 1) * (6 + 2 * unit(rng)), 0};
    pole.half = {0.12, 0, 6.0};
    pole.reflectivity = 0.8;
    pole.colour = {90, 110, 90};
    if (!free_at(pole.centre.x(), pole.centre.y(), 0.5)) continue;
    place(pole, 0);
    ++k;
  }
  // Clutter: kerb stones, bins, boxes.
  for (int k = 0, tries = 0; k < 14 && tries < 400; ++tries) {
    Object box;
    box.centre = {5 + 20 * unit(rng), -9 + 18 * unit(rng), 0};
    const double size = 0.25 + 0.5 * unit(rng);
    box.half = {size, size * (0.6 + 0.8 * unit(rng)), size * (0.5 + unit(rng))};
    box.yaw = std::numbers::pi * unit(rng);
    box.reflectivity = 0.2 + 0.6 * unit(rng);
    box.colour = cv::Vec3b(static_cast<std::uint8_t>(60 + 150 * unit(rng)),
                           static_cast<std::uint8_t>(60 + 150 * unit(rng)),
                           static_cast<std::uint8_t>(60 + 150 * unit(rng)));
    if (!free_at(box.centre.x(), box.centre.y(), 0.3)) continue;
    place(box, box.half.z());
    ++k;
  }
  return scene;
}

}  // namespace

Eigen::Isometry3d StreetSceneMount() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.7 * kDeg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(2.0 * kDeg, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.05, 0.1, -0.4);
  return T;
}

StreetFrame SimulateStreetFrame(const Eigen::Isometry3d& T_lidar_camera,
                                const StreetSceneOptions& options) {
  std::mt19937_64 rng(options.seed);
  const Scene scene = MakeScene(options, rng);
  StreetFrame frame;
  frame.T_lidar_camera = T_lidar_camera;
  frame.intrinsics.width = options.width;
  frame.intrinsics.height = options.height;
  frame.intrinsics.K << options.focal, 0, options.width / 2.0, 0, options.focal,
      options.height / 2.0, 0, 0, 1;

  // LiDAR: lines from −16° to +15°, denser near the horizon (as a 32-line automotive head).
  std::normal_distribution<double> range_noise(0.0, options.range_noise);
  std::normal_distribution<double> intensity_noise(0.0, options.intensity_noise);
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (int line = 0; line < options.lines; ++line) {
    const double u = -1.0 + 2.0 * line / (options.lines - 1);
    const double elevation = (u < 0 ? 16.0 : 15.0) * u * std::pow(std::abs(u), 0.7) * kDeg;
    for (double azimuth = -90.0; azimuth <= 90.0; azimuth += options.azimuth_step_deg) {
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth * kDeg),
                              std::cos(elevation) * std::sin(azimuth * kDeg), std::sin(elevation));
      double distance = 0;
      Eigen::Vector3d normal;
      const int hit = scene.Cast(origin, d, distance, normal);
      if (hit == -2 || distance > 120) continue;
      const double reflectivity = hit == -1
                                      ? scene.ground_reflectivity
                                      : scene.objects[static_cast<std::size_t>(hit)].reflectivity;
      sensors::LidarPoint point;
      point.p_sensor = ((distance + range_noise(rng)) * d).cast<float>();
      point.intensity = static_cast<float>(
          std::clamp(reflectivity * std::abs(normal.dot(d)) + intensity_noise(rng), 0.0, 1.0));
      point.ring = static_cast<std::uint16_t>(line);
      frame.cloud.points.push_back(point);
    }
  }

  // Camera: each pixel's ray through the true extrinsic; masks are the objects' silhouettes.
  const Eigen::Matrix3d R_lidar_optical = T_lidar_camera.linear() * BodyFromOpticalRotation();
  const Eigen::Vector3d c = T_lidar_camera.translation();
  cv::Mat ids(options.height, options.width, CV_32S, cv::Scalar(-2));
  frame.image = cv::Mat(options.height, options.width, CV_8UC3, cv::Scalar(235, 215, 200));
  for (int v = 0; v < options.height; ++v) {
    for (int u = 0; u < options.width; ++u) {
      const Eigen::Vector3d ray_optical((u - frame.intrinsics.K(0, 2)) / options.focal,
                                        (v - frame.intrinsics.K(1, 2)) / options.focal, 1.0);
      const Eigen::Vector3d d = (R_lidar_optical * ray_optical).normalized();
      double distance = 0;
      Eigen::Vector3d normal;
      const int hit = scene.Cast(c, d, distance, normal);
      ids.at<int>(v, u) = hit;
      if (hit == -2) continue;
      const cv::Vec3b base =
          hit == -1 ? cv::Vec3b(95, 100, 105) : scene.objects[static_cast<std::size_t>(hit)].colour;
      const double shade = 0.55 + 0.45 * std::abs(normal.dot(d));
      frame.image.at<cv::Vec3b>(v, u) = base * shade;
    }
  }
  frame.masks.width = options.width;
  frame.masks.height = options.height;
  for (int id = -1; id < static_cast<int>(scene.objects.size()); ++id) {
    cv::Mat mask = ids == id;
    if (cv::countNonZero(mask) >= 30) frame.masks.masks.push_back(mask);
  }
  return frame;
}

}  // namespace autoshovel::identification
