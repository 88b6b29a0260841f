// The figures every wheel-loader spec sheet lists, computed from the description alone (pure
// geometry and statics over the interpreted model; the hydraulic cycle times, which need the
// plant, are in runtime/plant/hydraulic_cycle_times.h). Definitions and standards, with the
// geometric model each one uses, are in docs/spec_sheet.md, "Spec-sheet figures":
//
//   breakout force    ISO 14397-2: the largest sustained vertical upward force 100 mm behind the
//                     cutting edge tip, bucket bottom level with the cutting edge on the ground,
//                     produced by the tilt cylinder(s) at relief pressure (the boom cylinders
//                     locked), and likewise by the lift cylinders (the tilt cylinder locked).
//                     Virtual work: F·∂z_P/∂q·v = Σ F_cylinder·∂L/∂q·v + Q_gravity·v along the
//                     motion v the locked cylinder leaves free.
//   static tipping    ISO 14397-1: the load at the rated load's centre of gravity (the bucket
//   load              profile's centroid) that brings the machine's centre of mass over an edge
//                     of its support (front tyre contacts and the rear axle's oscillation
//                     pivot), boom horizontal (bucket hinge pin at maximum forward reach),
//                     bucket racked back; straight and at full articulation.
//   turning radius    SAE J695 / ISO 7457: at full articulation, radius of the outside of the
//                     outer front tyre and of the bucket's outer front corner in carry.
//   heaped capacity   SAE J742 / ISO 7546: struck area below the strike line (cutting edge to
//                     the top of the back) × width, plus a heap at 2:1 slopes: W·b²/8 − b³/24.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::model {

/// Tyre width over tyre diameter assumed when the description gives none: earthmover radials
/// (23.5R25: 0.597 m wide, 1.61 m across; 17.5R25: 0.445 / 1.35; 26.5R25: 0.673 / 1.75) [-].
inline constexpr double kAssumedTyreWidthPerDiameter = 0.37;

/// Distance behind the cutting edge tip at which the breakout force acts (ISO 14397-2) [m].
inline constexpr double kBreakoutPointBehindTip = 0.100;

/// The angles of joint `joint` that its cylinder reaches within its stroke while every other
/// joint is held at q, searched over `extend` beyond the joint limits on either side (the
/// four-bar must close; the window is the run of reachable angles that contains the one nearest
/// the limits' middle). A cylinder pinned to an earlier body (a frame-mounted Z-bar or
/// parallel-lift tilt cylinder) slides this window with those joints; a motor's window is its
/// joint range. `empty`: nothing reachable [rad].
struct JointWindow {
  double min = 0, max = 0;
  bool empty = true;
};
JointWindow ReachableJointWindow(const MachineDescription& machine, int joint, const double* q,
                                 double extend = 0.0);

/// Whether the cylinder of `joint` changes length with the joints before it (its base or rod is
/// on an earlier body: chassis, or a rocker driven by the chassis side).
bool CylinderMovesWithEarlierJoints(const MachineDescription& machine, int joint);

/// Loaders: the carry pose used by `describe` (boom at 20 % of its range from the bottom, bucket
/// racked back fully: its joint limit, or as far as a frame-mounted tilt cylinder reaches at that
/// boom angle); excavators: every joint in the middle of its range [rad].
std::vector<double> CarryPose(const MachineDescription& machine);

/// Where the machine's mass is: the arm's links (their own mass and centre) and the rest of the
/// operating mass lumped at one point on the centre line of the frame it lies in, placed so
/// that the unloaded machine in the carry pose has the described front axle load fraction.
struct MassModel {
  double operating_mass = 0;       ///< [kg]
  double chassis_mass = 0;         ///< operating mass less the arm's links [kg]
  double chassis_x = 0;            ///< its centre, base frame, straight [m] (< 0: rear frame)
  double reference_cg_x = 0;       ///< whole machine in the carry pose, from the axle loads [m]
  std::vector<double> carry_pose;  ///< pose of the axle-load reference [rad]
};

MassModel MachineMassModel(const MachineDescription& machine);

/// Centre of mass of the whole machine (no payload) in the base frame's ground plane [x, y] for
/// arm pose q and articulation angle γ (the rear frame turned by −γ about the hinge) [m].
Eigen::Vector2d MachineCenterOfMass(const MachineDescription& machine, const MassModel& mass,
                                    const double* q, double articulation);

struct BreakoutForce {
  std::vector<double> pose;     ///< joint positions of the measurement pose [rad]
  bool pose_in_range = true;    ///< false: the pose needs a joint beyond its limit (clamped)
  Eigen::Vector2d p_base_point  ///< where the force acts, base frame [x, z] [m]
      = Eigen::Vector2d::Zero();
  /// Cutting edge tip at that pose, base frame [x, z] [m]: on the ground unless clamped.
  Eigen::Vector2d p_base_tip = Eigen::Vector2d::Zero();
  double bottom_slope = 0;  ///< bucket bottom against level at that pose (0 unless clamped) [rad]
  double by_tilt = 0;       ///< tilt cylinder(s) at relief, boom cylinders locked [N]
  double by_lift = 0;       ///< lift cylinders at relief, tilt cylinder locked [N]
  /// The vertical force at the same point that lifts the rear axle of the straight machine: a
  /// larger hydraulic force cannot be sustained (the machine tips first) [N].
  double tipping_limit = 0;
};

struct TippingLoad {
  std::vector<double> pose;                               ///< boom horizontal, racked back [rad]
  Eigen::Vector2d p_base_load = Eigen::Vector2d::Zero();  ///< load's centre, base [x, z] [m]
  double straight = 0;                                    ///< [kg]
  double full_turn = 0;                                   ///< at max articulation [kg]
  double articulation = 0;                                ///< of the full turn [rad]
  std::string full_turn_edge;                             ///< the tipping line at full turn
};

struct TurningRadius {
  double articulation = 0;          ///< [rad]
  double front_axle_centre = 0;     ///< [m]
  double outside_tyre = 0;          ///< outer sidewall of the outer front tyre [m]
  double bucket_corner = 0;         ///< outer front corner of the bucket in carry [m]
  double tyre_width = 0;            ///< [m]
  bool tyre_width_assumed = true;   ///< no tyre width in the description: kAssumed… × diameter
  double bucket_ahead_of_axle = 0;  ///< foremost bucket point ahead of the front axle, carry [m]
};

struct HeapedCapacity {
  double struck_area = 0;    ///< profile below the strike line [m²]
  double strike_length = 0;  ///< b: cutting edge to the top of the back [m]
  double struck = 0;         ///< area × width [m³]
  double heap = 0;           ///< W·b²/8 − b³/24 [m³]
  double heaped = 0;         ///< struck + heap [m³]
  double rated = 0;          ///< the description's rated capacity [m³]
};

struct SpecSheet {
  BreakoutForce breakout;
  TippingLoad tipping;
  TurningRadius turning;
  HeapedCapacity capacity;
  /// Boom cap-side pressure that holds the rated load in the carry pose [Pa] (whether the pump
  /// can raise it at full speed: compare with the pump pressure).
  double boom_pressure_for_rated_load = 0;
};

/// Vertical force at `point` (bucket frame) balanced by actuator `driving` at relief pressure
/// while every other actuator is locked (virtual work along the motion left free), at pose q;
/// gravity of the links included [N]. Positive: upwards.
double HydraulicVerticalForce(const MachineDescription& machine, const double* q,
                              const Eigen::Vector2d& p_bucket_point, int driving);

/// Straight and full-turn static tipping loads of a load whose centre is at `p_base_load`
/// (base frame x, on the centre line) with the arm at q [kg].
TippingLoad TippingLoadAt(const MachineDescription& machine, const MassModel& mass, const double* q,
                          const Eigen::Vector2d& p_base_load);

BreakoutForce ComputeBreakoutForce(const MachineDescription& machine, const MassModel& mass);
TippingLoad ComputeTippingLoad(const MachineDescription& machine, const MassModel& mass);
TurningRadius ComputeTurningRadius(const MachineDescription& machine);
HeapedCapacity ComputeHeapedCapacity(const MachineDescription& machine);

/// Every figure of a wheel loader. Throws std::invalid_argument for an excavator.
SpecSheet ComputeSpecSheet(const MachineDescription& machine);

}  // namespace autoshovel::model
