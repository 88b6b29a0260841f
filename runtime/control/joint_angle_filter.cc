#include "runtime/control/joint_angle_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::control {

JointAngleFilter::JointAngleFilter(double gain) : gain_(gain) {
  if (!(gain > 0 && gain <= 1)) {
    throw std::invalid_argument("joint angle filter: gain must be in (0, 1], got " +
                                std::to_string(gain));
  }
}

double JointAngleFilter::Update(double angle, double rate, double dt) {
  if (!initialised_) {
    if (std::isfinite(angle)) {
      estimate_ = angle;
      initialised_ = true;
    }
    return estimate_;
  }
  const double predicted =
      estimate_ + (std::isfinite(rate) && std::isfinite(dt) && dt > 0 ? rate * dt : 0.0);
  estimate_ = std::isfinite(angle) ? predicted + gain_ * (angle - predicted) : predicted;
  return estimate_;
}

}  // namespace autoshovel::control
