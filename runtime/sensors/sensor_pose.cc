#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::sensors {

Eigen::Isometry3d PoseToIsometry(const model::Pose3& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(pose.rpy.z(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pose.rpy.y(), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(pose.rpy.x(), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = pose.xyz;
  return T;
}

Eigen::Isometry3d SensorInWorld(const plant::MachineState& state, const model::Pose3& pose,
                                double swing_angle) {
  return state.T_world_cab(swing_angle) * PoseToIsometry(pose);
}

}  // namespace autoshovel::sensors
