#include "runtime/optimal/pile_profile.h"

#include <algorithm>
#include <stdexcept>

namespace autoshovel::optimal {

SampledCurve::SampledCurve(double start, double spacing, std::vector<double> heights)
    : start_(start), spacing_(spacing), heights_(std::move(heights)) {
  if (!std::isfinite(start) || !(spacing > 0) || !std::isfinite(spacing)) {
    throw std::invalid_argument("sampled curve: start must be finite and spacing > 0");
  }
  if (heights_.size() < 2) throw std::invalid_argument("sampled curve: fewer than 2 samples");
  for (double h : heights_) {
    if (!std::isfinite(h)) throw std::invalid_argument("sampled curve: a sample is not finite");
  }
}

SampledCurve SampledCurve::Ramp(double ground, double toe, double face_angle, double height,
                                double length, double spacing) {
  if (!(face_angle > 0 && face_angle < 1.5) || !(height >= 0) || !(length > 0)) {
    throw std::invalid_argument("pile profile: ramp needs 0 < face angle < 1.5 rad, height >= 0");
  }
  std::vector<double> heights;
  const double begin = toe - 1.0;  // a metre of floor before the toe
  for (double x = begin; x <= toe + length + 1e-9; x += spacing) {
    heights.push_back(ground + std::clamp((x - toe) * std::tan(face_angle), 0.0, height));
  }
  return SampledCurve(begin, spacing, std::move(heights));
}

}  // namespace autoshovel::optimal
