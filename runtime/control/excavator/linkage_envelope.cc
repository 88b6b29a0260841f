#include "runtime/control/excavator/linkage_envelope.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::control {
namespace {

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

/// Andrew's monotone chain, lower half: sorted by r then z, keeping left turns only.
void LowerHull(std::vector<Eigen::Vector2d>& points, std::vector<Eigen::Vector2d>& hull) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  hull.clear();
  for (const Eigen::Vector2d& p : points) {
    while (hull.size() >= 2 && Cross(hull[hull.size() - 2], hull.back(), p) <= 0) hull.pop_back();
    hull.push_back(p);
  }
  // A vertical edge at either end (a link standing straight up or lying level) is a side, not
  // part of the underside: keep only its lower end. Rounding may tilt it by 1e-16, hence the
  // tolerance.
  constexpr double kVertical = 1e-9;
  while (hull.size() >= 2 && hull[hull.size() - 1].x() - hull[hull.size() - 2].x() < kVertical &&
         hull[hull.size() - 1].y() > hull[hull.size() - 2].y()) {
    hull.pop_back();
  }
  while (hull.size() >= 2 && hull[1].x() - hull[0].x() < kVertical && hull[0].y() > hull[1].y()) {
    hull.erase(hull.begin());
  }
}

LinkShape Bar(double x_from, double x_to, double half_depth, double width) {
  return LinkShape{
      {{x_from, -half_depth}, {x_to, -half_depth}, {x_to, half_depth}, {x_from, half_depth}},
      width};
}

}  // namespace

std::string_view LinkName(LinkageLink link) {
  switch (link) {
    case LinkageLink::kBoom:
      return "boom";
    case LinkageLink::kStick:
      return "stick";
    case LinkageLink::kBucket:
      return "bucket";
  }
  return "?";
}

EnvelopeConfig DefaultEnvelopeConfig(const model::MachineDescription& machine) {
  if (machine.links.size() != 3 || machine.bucket.profile.size() < 3 ||
      !(machine.bucket.width > 0)) {
    throw std::invalid_argument("DefaultEnvelopeConfig: " + machine.name +
                                " needs boom, stick, bucket and a bucket profile and width");
  }
  EnvelopeConfig config;
  config.shapes[0] = Bar(-0.3, machine.links[0].length + 0.3, 0.4, 0.7);
  config.shapes[1] = Bar(-1.0, machine.links[1].length + 0.15, 0.35, 0.55);
  config.shapes[2] = LinkShape{machine.bucket.profile, machine.bucket.width};
  return config;
}

void Validate(const EnvelopeConfig& config) {
  for (int k = 0; k < 3; ++k) {
    const LinkShape& shape = config.shapes[k];
    const std::string name(LinkName(static_cast<LinkageLink>(k)));
    if (shape.outline.size() < 2) {
      throw std::invalid_argument("EnvelopeConfig: " + name + " outline needs >= 2 points");
    }
    for (const Eigen::Vector2d& p : shape.outline) {
      if (!p.allFinite()) throw std::invalid_argument("EnvelopeConfig: " + name + " outline NaN");
    }
    if (!(std::isfinite(shape.width) && shape.width >= 0)) {
      throw std::invalid_argument("EnvelopeConfig: " + name + " width must be >= 0");
    }
  }
  if (!(std::isfinite(config.max_spacing) && config.max_spacing > 0)) {
    throw std::invalid_argument("EnvelopeConfig: max_spacing must be positive");
  }
}

LinkageEnvelope::LinkageEnvelope(const ExcavatorKinematics& kinematics,
                                 const EnvelopeConfig& config)
    : kinematics_(kinematics), config_(config) {
  Validate(config_);
}

void LinkageEnvelope::LowerChainFromPins(const ArmPlanePins& pins, int link,
                                         std::vector<Eigen::Vector2d>& chain) const {
  std::vector<Eigen::Vector2d> placed;
  placed.reserve(config_.shapes[link].outline.size());
  for (const Eigen::Vector2d& p : config_.shapes[link].outline) {
    placed.push_back(ExcavatorKinematics::ArmPlanePoint(pins, link, p));
  }
  LowerHull(placed, chain);
}

std::vector<Eigen::Vector2d> LinkageEnvelope::LowerChain(const JointVector& q,
                                                         LinkageLink link) const {
  std::vector<Eigen::Vector2d> chain;
  LowerChainFromPins(kinematics_.Pins(q), static_cast<int>(link), chain);
  return chain;
}

void LinkageEnvelope::AppendLinkUnderside(const ArmPlanePins& pins, LinkageLink link,
                                          double spacing, const Eigen::Isometry3d& T_out_base,
                                          std::vector<EnvelopePoint>& points) const {
  if (!(spacing > 0)) throw std::invalid_argument("LinkageEnvelope: spacing must be positive");
  const int k = static_cast<int>(link);
  // Arm plane [r, lateral, z] to the output frame in one affine map (the swing's rotation
  // folded in once, not per point: this runs for every state of every prediction).
  const double cos_swing = std::cos(pins.swing), sin_swing = std::sin(pins.swing);
  Eigen::Matrix3d R_base_plane;
  R_base_plane << cos_swing, -sin_swing, 0, sin_swing, cos_swing, 0, 0, 0, 1;
  const Eigen::Matrix3d R = T_out_base.linear() * R_base_plane;
  const Eigen::Vector3d t = T_out_base.translation();
  std::vector<Eigen::Vector2d> chain;
  LowerChainFromPins(pins, k, chain);
  const double width = config_.shapes[k].width;
  const int across = width > 0 ? static_cast<int>(std::ceil(width / spacing)) + 1 : 1;
  auto emit = [&](const Eigen::Vector2d& p_plane) {
    for (int i = 0; i < across; ++i) {
      const double lateral = across == 1 ? 0.0 : -width / 2 + width * i / (across - 1);
      points.push_back({R * Eigen::Vector3d(p_plane.x(), lateral, p_plane.y()) + t, link});
    }
  };
  emit(chain.front());
  for (std::size_t s = 1; s < chain.size(); ++s) {
    const Eigen::Vector2d& a = chain[s - 1];
    const Eigen::Vector2d& b = chain[s];
    const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
    for (int i = 1; i <= pieces; ++i) emit(a + (b - a) * (double(i) / pieces));
  }
}

void LinkageEnvelope::Underside(const JointVector& q, const Eigen::Isometry3d& T_out_base,
                                std::vector<EnvelopePoint>& points) const {
  points.clear();
  const ArmPlanePins pins = kinematics_.Pins(q);
  for (int k = 0; k < 3; ++k) {
    AppendLinkUnderside(pins, static_cast<LinkageLink>(k), config_.max_spacing, T_out_base, points);
  }
}

std::vector<EnvelopePoint> LinkageEnvelope::Underside(const JointVector& q,
                                                      const Eigen::Isometry3d& T_out_base) const {
  std::vector<EnvelopePoint> points;
  Underside(q, T_out_base, points);
  return points;
}

}  // namespace autoshovel::control
