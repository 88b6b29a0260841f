#include "runtime/control/excavator/obstacle_box.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::control {
namespace {

Eigen::Vector2d ToBox(const ObstacleBox& box, const Eigen::Vector2d& xy) {
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  const Eigen::Vector2d d = xy - box.center;
  return Eigen::Vector2d(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
}

}  // namespace

double ObstacleBox::SignedDistance(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d local = ToBox(*this, p.head<2>());
  const double half_height = 0.5 * (z_max - z_min);
  const Eigen::Vector3d offset(std::abs(local.x()) - half_extents.x(),
                               std::abs(local.y()) - half_extents.y(),
                               std::abs(p.z() - 0.5 * (z_min + z_max)) - half_height);
  const double outside = offset.cwiseMax(0.0).norm();
  const double inside = std::min(offset.maxCoeff(), 0.0);
  return outside + inside;
}

double ObstacleBox::FootprintDistance(const Eigen::Vector2d& xy) const {
  const Eigen::Vector2d local = ToBox(*this, xy);
  const Eigen::Vector2d offset(std::abs(local.x()) - half_extents.x(),
                               std::abs(local.y()) - half_extents.y());
  return offset.cwiseMax(0.0).norm();
}

void ObstacleBox::Corners(Eigen::Vector2d corners[4]) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const Eigen::Vector2d ax(c, s), ay(-s, c);
  corners[0] = center + half_extents.x() * ax + half_extents.y() * ay;
  corners[1] = center - half_extents.x() * ax + half_extents.y() * ay;
  corners[2] = center - half_extents.x() * ax - half_extents.y() * ay;
  corners[3] = center + half_extents.x() * ax - half_extents.y() * ay;
}

void Validate(const ObstacleBox& box, const char* what) {
  const std::string name(what);
  if (!box.center.allFinite() || !std::isfinite(box.yaw) || !box.half_extents.allFinite() ||
      !std::isfinite(box.z_min) || !std::isfinite(box.z_max)) {
    throw std::invalid_argument(name + ": box values must be finite");
  }
  if (!(box.half_extents.minCoeff() > 0)) {
    throw std::invalid_argument(name + ": box half extents must be positive");
  }
  if (!(box.z_max > box.z_min)) throw std::invalid_argument(name + ": box z_max must exceed z_min");
}

}  // namespace autoshovel::control
