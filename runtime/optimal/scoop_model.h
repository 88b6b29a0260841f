// The scoop of a wheel loader as a smooth ODE, for the optimal-control scoop (scoop_ocp.h):
// the plant's physics (runtime/plant/plant.h) in the arm plane, with every switch replaced by a
// smooth function so that Ipopt can differentiate it, and the arm's rigid-body terms taken from
// the generated code (ArmDynamics, ForwardKinematicsWithJacobian, CylinderGeometry, templated on
// the scalar: differentiated exactly with ceres::Jet, never by finite differences).
//
// State x = [s, v, q_boom, q_bucket, q̇_boom, q̇_bucket, V, E]:
//   s machine travel since contact [m], v forward speed [m/s], q joints [rad], V volume taken
//   into the bucket [m³], E energy drawn, travel + hydraulic [J] (the seed's measure).
// Control u = [F_t, q̈_boom, q̈_bucket]: traction force at the tyres [N] and the joints'
//   accelerations [rad/s²]. The cylinder forces follow by inverse dynamics and are bounded by
//   path constraints: with the forces as controls the arm's small inertia against forces of
//   10⁵–10⁶ N made the collocation badly conditioned (Ipopt wandered for thousands of
//   iterations); with kinematic controls the large numbers stay in the constraints.
//
// Dynamics:
//   ṡ = v,  (m + ρV) v̇ = F_t − c_rr N σ(v) + F_s                      (plant/drive.h)
//   q̈ = u, Σ_a f_a ∂L_a/∂q = M(q, ρV) q̈ + bias(q, q̇, ρV) + b q̇ − J_tipᵀ F    (generated)
//   V̇ = w λ|PR| (v_M · n)⁺ · g(V)                                      (swept opening)
//   Ė = P_travel(F_t r, v/r) + P_pump(p_pump, Σ Q_a)
// with N = (m + ρV) g − F_z, and the plant's own loss maps (plant/power_losses.h): the travel
// motor's and inverter's map (regeneration credited where the plant credits it) and the pump's
// with its motor. The hydraulics are pressure-compensated load sensing: a section feeding its
// cylinder at p_a (force over the fed area) needs p_a + Δp at the pump (Δp the valve's rated
// drop, the LS margin); the pump runs at the highest need among the moving sections (a smooth
// maximum weighted by each section's flow), so a section below it is throttled by its
// compensator. The soil force F = (F_s, F_z) at the
// cutting edge is the plant's: Reece's equation with McKyes' factors for the cut ahead of the
// edge (the opening's rise is the blade, the material above it surcharge), the at-rest side
// shear on lifting, soil–steel friction on withdrawing, each through the smooth sign
// σ(v) = v/√(v² + ε²) of the edge's velocity. McKyes' factors enter as a C¹ interpolant over the
// rake angle (every degree, their error half-way between samples is kept).
//
// Filling: the material the bucket takes is what its opening (the segment from the cutting edge
// P to the top of the back wall R) sweeps below the free surface: the submerged fraction λ of
// the opening times its speed into the soil at the middle of the submerged part, across the
// bucket's width. g(V) closes the intake smoothly as V reaches the heaped capacity (beyond it
// the surrounding material pushes the excess ahead of the lip, as in the plant).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/optimal/pile_profile.h"
#include "runtime/plant/power_losses.h"

namespace autoshovel::optimal {

inline constexpr int kJoints = 2;     // wheel loaders: boom and bucket
inline constexpr int kActuators = 2;  // boom cylinders, bucket (tilt) cylinders
inline constexpr int kStates = 8;
inline constexpr int kControls = 1 + kActuators;
inline constexpr int kNodeVariables = kStates + kControls;

/// State indices.
enum StateIndex : int { kS = 0, kV = 1, kQ = 2, kQd = 4, kVolume = 6, kEnergy = 7 };

/// Path quantities evaluated at a node, each required to be ≥ 0 except where said.
enum PathIndex : int {
  kTractionForward = 0,                          ///< μN − F_t
  kTractionBackward,                             ///< μN + F_t
  kDrivePower,                                   ///< P_max − F_t v
  kFlowExtend,                                   ///< per actuator: Q_rated − A_cap L̇
  kFlowRetract = kFlowExtend + kActuators,       ///< per actuator: Q_rated + A_rod L̇
  kForceBelowMax = kFlowRetract + kActuators,    ///< per actuator: f_max − f
  kForceAboveMin = kForceBelowMax + kActuators,  ///< per actuator: f − f_min
  kPumpFlow = kForceAboveMin + kActuators,       ///< Q_pump − Σ Q (1 when unlimited)
  kTipAboveFloor,                                ///< z_tip − floor
  kNumPath,
};

/// What the optimiser and the reports read at a node besides the constraints.
struct ScoopModelProbe {
  double tip_x = 0, tip_z = 0;  ///< cutting edge, machine frame at s = 0 [m]
  double depth = 0;             ///< free surface above the edge (negative: above it) [m]
  double rim_depth = 0;         ///< the same for the top of the back wall [m]
  double bucket_angle = 0;      ///< φ of the bucket link [rad]
  double travel_power = 0, hydraulic_power = 0;     ///< [W]
  double soil_force_s = 0, soil_force_z = 0;        ///< on the bucket [N]
  double intake = 0;                                ///< V̇ [m³/s]
  std::array<double, kActuators> cylinder_force{};  ///< by inverse dynamics [N]
};

struct ScoopModelOptions {
  double resistance_speed = 0.05;  ///< ε of the smooth signs [m/s] (PlantOptions)
  double adhesion_fraction = 0.5;  ///< c_a/c (PlantOptions)
  double depth_smoothing = 0.02;   ///< of the depth's positive part [m]
  double flow_smoothing = 1e-2;    ///< of |L̇| in the flows [m/s]
  double fill_closing = 0.03;      ///< g(V) closes over this fraction of the capacity [-]
};

/// Everything the smooth model needs, drawn from a machine description and a material.
class ScoopModel {
 public:
  /// Throws std::invalid_argument naming what is missing for a wheel loader with a boom and a
  /// bucket (two joints, two actuator groups, an electric or diesel drive).
  ScoopModel(const model::MachineDescription& machine, const model::Material& material,
             PileProfile pile, const ScoopModelOptions& options = {});

  /// ẋ = f(x, u) and the path quantities (PathIndex); T is double or ceres::Jet<double, N>
  /// with N one of kNodeVariables, 2 kNodeVariables + 1 (instantiated in scoop_model.cc).
  template <typename T>
  void Evaluate(const T* x, const T* u, T* xdot, T* path) const;

  /// Geometry and powers at a state (for reports, tests and the terminal conditions).
  ScoopModelProbe Probe(const double* x, const double* u) const;

  /// Tip position in the machine frame at s = 0 and the bucket link's angle, for joints q.
  template <typename T>
  void Tip(const T* q, const T& s, T* tip_x, T* tip_z, T* bucket_angle) const;
  /// Depth of a point below the pile surface [m].
  template <typename T>
  T DepthBelowSurface(const T& x, const T& z) const {
    return pile_.Height(x) - z;
  }

  const std::string& machine_name() const { return machine_name_; }
  const PileProfile& pile() const { return pile_; }
  double machine_mass() const { return mass_; }
  double density() const { return density_; }
  double heaped_capacity() const { return capacity_; }
  double joint_min(int j) const { return joint_min_[j]; }
  double joint_max(int j) const { return joint_max_[j]; }
  /// Force bounds of actuator a [N]: the pump's pressure less the LS margin on the fed area.
  double force_min(int a) const { return force_min_[a]; }
  double force_max(int a) const { return force_max_[a]; }
  double max_traction_force() const { return max_traction_; }
  double valve_delay(int a) const { return valve_delay_[a]; }
  /// Largest relative error of the interpolated McKyes factors against the direct search,
  /// half-way between the samples.
  double factor_fit_error() const { return factor_fit_error_; }
  double floor_height() const { return floor_; }
  const double* link_params() const { return params_.data(); }

 private:
  /// The generated kinematics at joints q: pose [x, y, z, φ] and ∂pose/∂angles (4 × angles).
  template <typename T>
  void ArmPose(const T* q, T* pose, T* d_pose) const;
  /// Evaluate, and with `extras` (12 values) the probe's quantities in ScoopModelProbe order.
  template <typename T>
  void EvaluateDetailed(const T* x, const T* u, T* xdot, T* path, T* extras) const;
  /// The soil's reaction on the bucket along the travel (soil_s) and vertically (soil_z) [N]:
  /// Reece's cut ahead of the edge, the lift and withdrawal of the column above it, by the
  /// tip's velocity (vpx, vpz); `bx`, `bz` the opening from edge to rim.
  template <typename T>
  void SoilForces(const T& depth, const T& depth_in, const T& bx, const T& bz, const T& vpx,
                  const T& vpz, T& soil_s, T& soil_z) const;

  std::string machine_name_;
  PileProfile pile_;
  plant::TravelDriveLosses travel_losses_;
  plant::HydraulicLosses hydraulic_losses_;
  ScoopModelOptions options_;
  std::vector<double> params_;  // nominal [l_k, α_k] for the generated kinematics
  int num_angles_ = 0;
  double mass_ = 0, density_ = 0, capacity_ = 0, width_ = 0, floor_ = 0, wheel_radius_ = 1;
  double gravity_ = 9.80665;
  double traction_coefficient_ = 0, rolling_ = 0, drive_power_ = 0;
  double max_traction_ = 0;
  double pump_max_flow_ = 0;
  std::array<double, kActuators> area_cap_{}, area_rod_{}, rated_flow_{}, margin_{};
  std::array<double, kActuators> force_min_{}, force_max_{}, valve_delay_{};
  std::array<double, kJoints> joint_min_{}, joint_max_{}, friction_{};
  std::array<double, 2> tip_bucket_{}, rim_bucket_{}, normal_bucket_{};
  // Material: unit weight, cohesion, adhesion, friction tangents, at-rest pressure.
  double unit_weight_ = 0, cohesion_ = 0, adhesion_ = 0, tan_phi_ = 0, k0_ = 0, tan_delta_ = 0;
  double delta_ = 0;
  // McKyes' factors N_γ, N_c, N_q, N_a over the rake angle.
  std::array<SampledCurve, 4> factor_curves_;
  double rake_min_ = 0, rake_max_ = 0;
  double factor_fit_error_ = 0;
};

}  // namespace autoshovel::optimal
