#include "runtime/planning/dig/dig_geometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::planning {
namespace {

std::string Point(const Eigen::Vector3d& p) {
  return "(" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) +
         ")";
}

}  // namespace

void Validate(const DigGeometryConfig& config, const std::string& what) {
  auto fail = [&](const std::string& field, const std::string& rule, double value) {
    throw std::invalid_argument(what + "." + field + ": " + rule + ", got " +
                                std::to_string(value));
  };
  const double pi = std::numbers::pi;
  auto check_range = [&](const std::string& name, double lo, double hi) {
    if (!(std::isfinite(lo) && lo >= -2 * pi && lo <= 2 * pi)) {
      fail(name + "_min", "must be finite and in [-2pi, 2pi] rad", lo);
    }
    if (!(std::isfinite(hi) && hi >= lo && hi <= 2 * pi)) {
      fail(name + "_max", "must be finite, >= " + name + "_min and <= 2pi rad", hi);
    }
  };
  check_range("entry_attitude", config.entry_attitude_min, config.entry_attitude_max);
  check_range("drag_end_attitude", config.drag_end_attitude_min, config.drag_end_attitude_max);
  if (config.attitude_samples < 1) {
    fail("attitude_samples", "must be >= 1", config.attitude_samples);
  }
  if (!(std::isfinite(config.undercarriage_radius) && config.undercarriage_radius >= 0)) {
    fail("undercarriage_radius", "must be finite and >= 0 m", config.undercarriage_radius);
  }
  if (!(std::isfinite(config.keep_out_margin) && config.keep_out_margin >= 0)) {
    fail("keep_out_margin", "must be finite and >= 0 m", config.keep_out_margin);
  }
  if (!(std::isfinite(config.path_spacing) && config.path_spacing > 0)) {
    fail("path_spacing", "must be finite and > 0 m", config.path_spacing);
  }
  if (!(std::isfinite(config.lift_clearance) && config.lift_clearance >= 0)) {
    fail("lift_clearance", "must be finite and >= 0 m", config.lift_clearance);
  }
}

double UndercarriageRadius(const model::MachineDescription& machine, double margin) {
  const model::Chassis& c = machine.chassis;
  if (!(c.track_length > 0 && c.track_gauge > 0 && c.track_shoe_width >= 0)) {
    throw std::invalid_argument("UndercarriageRadius: " + machine.name +
                                " has no track length, gauge and shoe width");
  }
  if (!(std::isfinite(margin) && margin >= 0)) {
    throw std::invalid_argument("UndercarriageRadius: margin must be finite and >= 0 m, got " +
                                std::to_string(margin));
  }
  return 0.5 * std::hypot(c.track_length, c.track_gauge + c.track_shoe_width) + margin;
}

Eigen::Vector3d TipInBase(double swing, double radius, double z) {
  return control::ExcavatorKinematics::BaseFromArmPlane(swing, Eigen::Vector2d(radius, z));
}

std::vector<Eigen::Vector3d> NominalTipPath(const DigAction& action, double lift_clearance) {
  const double cut = action.entry_height - action.depth;
  const double drag_end = action.radius - action.drag_length;
  return {TipInBase(action.swing, action.radius, action.entry_height),
          TipInBase(action.swing, action.radius, cut), TipInBase(action.swing, drag_end, cut),
          TipInBase(action.swing, drag_end, action.entry_height + lift_clearance)};
}

DigReachability::DigReachability(const control::ExcavatorKinematics& kinematics,
                                 const DigGeometryConfig& config)
    : kinematics_(kinematics), config_(config) {
  Validate(config_, "DigGeometryConfig");
}

std::optional<control::JointVector> DigReachability::Solve(const Eigen::Vector3d& p_base_tip,
                                                           double attitude_min,
                                                           double attitude_max) const {
  const int n = config_.attitude_samples;
  std::vector<double> attitudes(n, 0.5 * (attitude_min + attitude_max));
  for (int k = 0; k < n && n > 1; ++k) {
    attitudes[k] = attitude_min + (attitude_max - attitude_min) * k / (n - 1);
  }
  // Nearest the middle of the range first: the first reachable attitude is the most central.
  const double middle = 0.5 * (attitude_min + attitude_max);
  std::stable_sort(attitudes.begin(), attitudes.end(),
                   [&](double a, double b) { return std::abs(a - middle) < std::abs(b - middle); });
  for (double attitude : attitudes) {
    std::optional<control::JointVector> q = kinematics_.SolveTip(p_base_tip, attitude);
    if (q) return q;
  }
  return std::nullopt;
}

bool DigReachability::Reachable(const DigAction& action, std::string& why) const {
  if (!IsFinite(action)) {
    why = "action has a non-finite parameter";
    return false;
  }
  const double cut = action.entry_height - action.depth;
  const double drag_end = action.radius - action.drag_length;
  struct Check {
    const char* name;
    double radius, z, lo, hi;
  };
  const Check checks[] = {
      {"entry", action.radius, action.entry_height, config_.entry_attitude_min,
       config_.entry_attitude_max},
      {"penetration bottom", action.radius, cut, config_.entry_attitude_min,
       config_.entry_attitude_max},
      {"drag end", drag_end, cut, config_.drag_end_attitude_min, config_.drag_end_attitude_max},
  };
  for (const Check& c : checks) {
    // SolveTip's swing is the tip's azimuth: a point on or behind the swing axis would be
    // solved in the opposite arm plane.
    if (!(c.radius > 0) || !Solve(TipInBase(action.swing, c.radius, c.z), c.lo, c.hi).has_value()) {
      why = std::string("unreachable ") + c.name + " at r = " + std::to_string(c.radius) +
            " m, z = " + std::to_string(c.z) + " m";
      return false;
    }
  }
  return true;
}

bool PathCollides(const std::vector<Eigen::Vector3d>& tip_path,
                  const std::vector<control::ObstacleBox>& keep_out_base,
                  const DigGeometryConfig& config, std::string& why) {
  auto point_collides = [&](const Eigen::Vector3d& p) {
    if (p.head<2>().norm() < config.undercarriage_radius) {
      why = "tip at " + Point(p) + " within the undercarriage radius " +
            std::to_string(config.undercarriage_radius) + " m";
      return true;
    }
    for (std::size_t b = 0; b < keep_out_base.size(); ++b) {
      if (keep_out_base[b].SignedDistance(p) < config.keep_out_margin) {
        why = "tip at " + Point(p) + " within " + std::to_string(config.keep_out_margin) +
              " m of keep-out box " + std::to_string(b);
        return true;
      }
    }
    return false;
  };
  for (std::size_t i = 0; i < tip_path.size(); ++i) {
    if (point_collides(tip_path[i])) return true;
    if (i + 1 == tip_path.size()) break;
    const Eigen::Vector3d delta = tip_path[i + 1] - tip_path[i];
    const int steps = static_cast<int>(std::ceil(delta.norm() / config.path_spacing));
    for (int k = 1; k < steps; ++k) {
      if (point_collides(tip_path[i] + (static_cast<double>(k) / steps) * delta)) return true;
    }
  }
  return false;
}

}  // namespace autoshovel::planning
