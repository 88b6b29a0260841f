// The true state of a simulated machine at one instant: what the plant integrates and what the
// simulated sensors measure (with their noise). Perception and control never see this type; they
// see sensor data (runtime/sensors) only.
//
// Frames. World: x east, y north, z up, on the yard floor. Base frame of a loader: the front
// frame, origin on the ground below the articulation hinge, x forward (models/README.md). The
// rear frame shares that origin and is turned by −γ (γ = ψ_front − ψ_rear, the articulation
// angle) about the hinge axis; the cab, its camera, LiDARs, cab IMU and localisation antenna ride
// on the rear frame, the arm on the front frame. At γ = 0 the two coincide, which is how sensor
// poses are given in a description. An excavator's base frame is its undercarriage; the swing
// joint turns the upper structure, and its sensors ride on the upper structure.
#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace autoshovel::plant {

struct MachineState {
  double time = 0;                                     ///< simulated clock [s]
  Eigen::Vector2d hinge_xy = Eigen::Vector2d::Zero();  ///< world xy of the base origin [m]
  double heading = 0;              ///< ψ_front: base x axis from world x, counter-clockwise [rad]
  double articulation = 0;         ///< γ = ψ_front − ψ_rear [rad]; 0 for an excavator
  double pitch = 0;                ///< chassis pitch, nose up positive [rad]
  double speed = 0;                ///< front axle speed along the base x axis [m/s]
  double wheel_speed = 0;          ///< lumped wheel angular speed [rad/s]
  double wheel_slip = 0;           ///< (ω r − v)/max(|v|, ω r, v_min) [-]
  std::vector<double> q;           ///< arm joints (links, then swing) [rad]
  std::vector<double> qd;          ///< [rad/s]
  std::vector<double> spool;       ///< valve spool positions [-1, 1]
  std::vector<double> pressure_a;  ///< cap side / motor port A [Pa]
  std::vector<double> pressure_b;  ///< rod side / motor port B [Pa]
  double payload_mass = 0;         ///< material in the bucket [kg]
  double payload_volume = 0;       ///< [m³]

  /// World ← base (front frame, or undercarriage).
  Eigen::Isometry3d T_world_base() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(hinge_xy.x(), hinge_xy.y(), 0.0);
    T.linear() = (Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    return T;
  }
  /// World ← the frame the cab sensors ride on: the rear frame of a loader (turned by −γ about
  /// the hinge), the upper structure of an excavator (turned by the swing joint `swing_angle`).
  Eigen::Isometry3d T_world_cab(double swing_angle = 0.0) const {
    return T_world_base() * Eigen::AngleAxisd(swing_angle - articulation, Eigen::Vector3d::UnitZ());
  }
};

}  // namespace autoshovel::plant
