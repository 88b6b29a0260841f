// Where a sensor is: the description's mounting pose (base frame, given at articulation 0) and
// the machine's true state.
//
// Rotation convention of model::Pose3::rpy: roll φ about x, pitch θ about y, yaw ψ about z,
// fixed axes applied in that order, R = Rz(ψ)·Ry(θ)·Rx(φ) (URDF `rpy`, REP 103). With z up a
// positive pitch turns the sensor's x axis *down*: the xcmg_968ev camera (pitch 15°) and front
// LiDAR (pitch 20°) look down at the pile in front of the bucket. Note the opposite sign of
// plant::MachineState::pitch, which is positive nose *up* (and enters T_world_base as a
// rotation by −pitch about y for that reason).
#pragma once

#include <Eigen/Geometry>

#include "runtime/model/description.h"
#include "runtime/plant/machine_state.h"

namespace autoshovel::sensors {

/// Base (cab) ← sensor, from a description pose.
Eigen::Isometry3d PoseToIsometry(const model::Pose3& pose);

/// World ← sensor for a sensor riding on the cab (loader rear frame, excavator upper structure
/// turned by `swing_angle`): T_world_cab · T_base_sensor.
Eigen::Isometry3d SensorInWorld(const plant::MachineState& state, const model::Pose3& pose,
                                double swing_angle = 0.0);

}  // namespace autoshovel::sensors
