#include "runtime/plant/poses.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace autoshovel::plant {

std::vector<double> BucketOnFloor(const model::MachineDescription& machine, double tip_height) {
  if (machine.links.size() != 2 || machine.bucket.profile.size() < 2) {
    throw std::invalid_argument("BucketOnFloor: needs a two-link arm with a bucket profile (" +
                                machine.name + ")");
  }
  // The floor edge points back from the tip; level means it points along −x in frame M.
  const Eigen::Vector2d floor = machine.bucket.profile[1] - machine.bucket.profile[0];
  double phi_bucket = std::numbers::pi - std::atan2(floor.y(), floor.x());
  phi_bucket = std::remainder(phi_bucket, 2 * std::numbers::pi);
  const double l1 = machine.links[0].length, l2 = machine.links[1].length;
  const double sin_boom = (tip_height - machine.arm_pivot.y() - l2 * std::sin(phi_bucket)) / l1;
  if (std::abs(sin_boom) > 1) {
    throw std::invalid_argument("BucketOnFloor: " + machine.name + " cannot reach the floor");
  }
  const double boom = std::asin(sin_boom);
  return {boom, phi_bucket - boom};
}

}  // namespace autoshovel::plant
