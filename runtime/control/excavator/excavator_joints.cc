#include "runtime/control/excavator/excavator_joints.h"

#include <cmath>

namespace autoshovel::control {

std::string_view JointName(ExcavatorJoint joint) {
  switch (joint) {
    case ExcavatorJoint::kBoom:
      return "boom";
    case ExcavatorJoint::kStick:
      return "stick";
    case ExcavatorJoint::kBucket:
      return "bucket";
    case ExcavatorJoint::kSwing:
      return "swing";
  }
  return "?";
}

int FirstNonFinite(const JointVector& v) {
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    if (!std::isfinite(v[j])) return j;
  }
  return -1;
}

}  // namespace autoshovel::control
