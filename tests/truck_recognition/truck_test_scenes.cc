#include "truck_test_scenes.h"

#include <cmath>
#include <numbers>

namespace autoshovel::perception::truck_sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

double Uniform(Rng& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

ScannerSpec RandomScanner(Rng& rng, const SceneOptions& options) {
  ScannerSpec scanner;
  scanner.p_world_sensor =
      Eigen::Vector3d(0, 0, Uniform(rng, options.sensor_height_min, options.sensor_height_max));
  scanner.range_noise_sigma = Uniform(rng, options.noise_sigma_min, options.noise_sigma_max);
  scanner.dropout_probability = Uniform(rng, options.dropout_min, options.dropout_max);
  scanner.pan_step_deg = options.pan_step_deg;
  scanner.elevation_step_deg = options.elevation_step_deg;
  return scanner;
}

// A plan position at range [r_lo, r_hi] inside the scanned sector.
Eigen::Vector2d RandomSpot(Rng& rng, double r_lo, double r_hi) {
  const double az = Uniform(rng, 45, 135) * kDegToRad;
  const double r = Uniform(rng, r_lo, r_hi);
  return {r * std::cos(az), r * std::sin(az)};
}

struct Keepout {
  Eigen::Vector2d centre;
  double radius;
};

bool Clear(const std::vector<Keepout>& keepouts, const Eigen::Vector2d& p, double radius) {
  for (const Keepout& k : keepouts) {
    if ((p - k.centre).norm() < k.radius + radius + 0.5) return false;
  }
  // Nothing on top of the excavator.
  return p.norm() > radius + 3.0;
}

void AddPile(TestScene& s, Rng& rng, double r_lo, double r_hi, std::vector<Keepout>& keepouts) {
  for (int attempt = 0; attempt < 50; ++attempt) {
    SimCone cone;
    cone.height = Uniform(rng, 1.5, 3.0);
    cone.base_radius = cone.height / std::tan(Uniform(rng, 30, 38) * kDegToRad);
    cone.p_world_centre = RandomSpot(rng, r_lo, r_hi);
    if (!Clear(keepouts, cone.p_world_centre, cone.base_radius)) continue;
    s.scene.cones.push_back(cone);
    keepouts.push_back({cone.p_world_centre, cone.base_radius});
    return;
  }
}

void AddWall(TestScene& s, Rng& rng, double r_lo, double r_hi, std::vector<Keepout>& keepouts) {
  for (int attempt = 0; attempt < 50; ++attempt) {
    const double length = Uniform(rng, 8, 20);
    const Eigen::Vector2d p = RandomSpot(rng, r_lo, r_hi);
    // Roughly facing the excavator, as a bench wall or a bin wall would.
    const double yaw = std::atan2(p.y(), p.x()) + std::numbers::pi / 2 + Uniform(rng, -0.6, 0.6);
    if (!Clear(keepouts, p, 0.5 * length)) continue;
    s.scene.AddBox({p.x(), p.y(), 0}, yaw, {length, 0.3, Uniform(rng, 1.5, 4.0)});
    keepouts.push_back({p, 0.5 * length});
    return;
  }
}

void AddNonTruckBox(TestScene& s, Rng& rng, double r_lo, double r_hi,
                    std::vector<Keepout>& keepouts) {
  for (int attempt = 0; attempt < 50; ++attempt) {
    const Eigen::Vector3d size(Uniform(rng, 3, 8), Uniform(rng, 2, 3.5), Uniform(rng, 1.5, 3.5));
    const Eigen::Vector2d p = RandomSpot(rng, r_lo, r_hi);
    const double radius = 0.5 * std::hypot(size.x(), size.y());
    if (!Clear(keepouts, p, radius)) continue;
    s.scene.AddBox({p.x(), p.y(), 0}, Uniform(rng, -std::numbers::pi, std::numbers::pi), size);
    keepouts.push_back({p, radius});
    return;
  }
}

}  // namespace

TestScene MakeTruckScene(const TruckSpec& spec, Rng& rng, const SceneOptions& options) {
  TestScene s;
  s.scanner = RandomScanner(rng, options);
  const Eigen::Vector2d p_bed(Uniform(rng, -2, 2), Uniform(rng, 6, 8));
  const double heading = std::bernoulli_distribution(0.5)(rng) ? 0.0 : std::numbers::pi;
  const double yaw = heading + Uniform(rng, -30, 30) * kDegToRad;
  s.truth = AddTruck(spec, p_bed, yaw, &s.scene);
  if (options.clutter) {
    std::vector<Keepout> keepouts{{s.truth->p_world_footprint_centre, s.truth->footprint_radius}};
    AddPile(s, rng, 11, 16, keepouts);
    AddWall(s, rng, 14, 18, keepouts);
    AddNonTruckBox(s, rng, 10, 15, keepouts);
  }
  return s;
}

std::string_view NegativeKindName(NegativeKind kind) {
  switch (kind) {
    case NegativeKind::kGround:
      return "ground";
    case NegativeKind::kPile:
      return "piles";
    case NegativeKind::kWall:
      return "wall";
    case NegativeKind::kBox:
      return "box";
    case NegativeKind::kAllClutter:
      return "all clutter";
    case NegativeKind::kParallelWalls:
      return "parallel walls";
    case NegativeKind::kOpenSkip:
      return "open skip";
  }
  return "?";
}

TestScene MakeNegativeScene(NegativeKind kind, Rng& rng, const SceneOptions& options) {
  TestScene s;
  s.scanner = RandomScanner(rng, options);
  std::vector<Keepout> keepouts;
  switch (kind) {
    case NegativeKind::kGround:
      break;
    case NegativeKind::kPile:
      AddPile(s, rng, 6, 12, keepouts);
      AddPile(s, rng, 6, 12, keepouts);
      break;
    case NegativeKind::kWall:
      AddWall(s, rng, 5, 10, keepouts);
      break;
    case NegativeKind::kBox:
      AddNonTruckBox(s, rng, 5.5, 9, keepouts);
      break;
    case NegativeKind::kAllClutter:
      AddNonTruckBox(s, rng, 5.5, 9, keepouts);
      AddPile(s, rng, 6, 12, keepouts);
      AddWall(s, rng, 8, 14, keepouts);
      break;
    case NegativeKind::kParallelWalls: {
      // Two free-standing walls facing the excavator, 2–3.5 m apart, tops 2.3–3.5 m up.
      const Eigen::Vector2d p(Uniform(rng, -2, 2), Uniform(rng, 5.5, 7.5));
      const double yaw = Uniform(rng, -0.5, 0.5);
      const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw));
      const double gap = Uniform(rng, 2.0, 3.5);
      const double length = Uniform(rng, 4, 8);
      const double height = Uniform(rng, 2.3, 3.5);
      for (double side : {-0.5, 0.5}) {
        const Eigen::Vector2d q = p + side * gap * across;
        s.scene.AddBox({q.x(), q.y(), 0}, yaw, {length, 0.2, height});
      }
      break;
    }
    case NegativeKind::kOpenSkip: {
      // A steel skip: floor plate on the ground, four walls, no roof.
      const Eigen::Vector2d p(Uniform(rng, -2, 2), Uniform(rng, 6, 8));
      const double yaw = Uniform(rng, -std::numbers::pi, std::numbers::pi);
      const double length = Uniform(rng, 4, 6.5);
      const double width = Uniform(rng, 2.0, 2.5);
      const double height = Uniform(rng, 1.5, 2.5);
      const double t = 0.08;
      const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw));
      const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw));
      const auto add = [&](const Eigen::Vector2d& offset, const Eigen::Vector3d& size) {
        const Eigen::Vector2d q = p + offset.x() * along + offset.y() * across;
        s.scene.AddBox({q.x(), q.y(), 0}, yaw, size);
      };
      add({0, 0}, {length, width, t});
      add({0, 0.5 * (width - t)}, {length, t, height});
      add({0, -0.5 * (width - t)}, {length, t, height});
      add({0.5 * (length - t), 0}, {t, width, height});
      add({-0.5 * (length - t), 0}, {t, width, height});
      break;
    }
  }
  return s;
}

}  // namespace autoshovel::perception::truck_sim
