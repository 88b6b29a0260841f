// The reference evaluation of a machine description at run time: kinematics, cylinder
// geometry and the hydraulic–mechanical plant right-hand side, computed directly from the
// description's numbers. It is written independently of the code generator (no symbolic
// algebra, gravity from the chain's geometry rather than from a potential) and serves as the
// oracle that generated code is verified against, and as the fallback for a machine that has
// no generated code yet. Templated on the scalar so that Eigen's AutoDiffScalar (or ceres::Jet)
// gives exact derivatives.
//
// Kinematics (wheel-loader seed §3.1):
//   Eq. (1)  φ_k = θ_k − θ_cab + α_k           (IMU pitch of link k, of the cab; mounting offset)
//   Eq. (2)  p_M_tip = Σ_k l_k (cos φ_k, sin φ_k)
// Angles vector a = [θ_cab, θ_1 … θ_n, (ψ_swing)], parameters p = [l_1 … l_n, α_1 … α_n].
// Output pose = [x, y, z, φ_n] of the bucket tip B in the vehicle (base) frame:
//   loader:     (pivot_x + x_M, 0, pivot_z + z_M);
//   excavator:  (cos ψ (pivot_x + x_M), sin ψ (pivot_x + x_M), pivot_z + z_M).
// Joint positions q: q_1 = φ_1, q_k = φ_k − φ_{k−1}, then ψ for excavators.
//
// Plant, per joint j with its one actuator (x = [q, q̇, x_s, p_A, p_B] each block of J entries;
// u = [valve command after dead zone and delay (J), external torque (J), payload mass,
// pitch of frame M, supply pressure p_P of each joint's valve section (J)]):
//   ẋ_s = (u_j − x_s)/τ_s
//   Q_A = K_v [pos(x_s) g(c(p_P − p_A)) − pos(−x_s) g(p_A − p_T)]
//   Q_B = K_v [pos(−x_s) g(c(p_P − p_B)) − pos(x_s) g(p_B − p_T)]
//   (c: the section's load check valve, a smooth positive part: no flow back into the supply)
//   ṗ_A = β/V_A (Q_A − A_A ṡ + Q_makeup(p_A) − Q_relief(p_A)), V_A = V_0 + A_A s
//   ṗ_B = β/V_B (Q_B + A_B ṡ + Q_makeup(p_B) − Q_relief(p_B)), V_B = V_0 + A_B (S − s)
//   F = p_A A_A − p_B A_B + F_endstop(s, ṡ) (spring and cushion damper past either end);
//   generalized force F ∂L/∂q_i on every joint i
//   M(q) q̈ + h(q, q̇) = Σ F ∂L/∂q + Q_gravity(q) + τ_ext − b q̇
// with s = L(q) − L_retracted the cylinder extension. M is the full mass matrix of every moving
// body (links, payload, rockers, couplers, cylinder barrels and rods), h the Coriolis and
// centrifugal terms (and the swing's couplings), both from the body positions through the
// closed chains: M = Σ m J_cᵀJ_c + I J_φᵀJ_φ and h = Σ m J_cᵀ(J̇_c q̇) + I J_φᵀ(J̇_φ q̇), the
// Jacobians by forward dual numbers and J̇q̇ as a second directional derivative by nested
// ones (issue 39). A motor (swing) has ṡ = q̇, A_A = A_B = displacement, constant line volumes
// and no end stops.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/model/dual.h"
#include "runtime/model/plant_constants.h"

namespace autoshovel::model {

/// Sizes of the vectors of a machine.
struct ModelSizes {
  int num_links = 0;
  int num_joints = 0;
  int num_angles = 0;  ///< IMU angles (+ swing)
  int num_params = 0;  ///< calibration parameters l_k, α_k
  int num_states = 0;
  int num_inputs = 0;
};

ModelSizes SizesOf(const MachineDescription& machine);

/// Centroid of the bucket profile polygon in the bucket frame (where the payload acts) [m].
Eigen::Vector2d BucketPayloadCenter(const MachineDescription& machine);

/// Cross-section area of the bucket profile [m²] (struck volume = area × width).
double BucketProfileArea(const MachineDescription& machine);

/// The bucket's attitude in the arm plane (q_boom + q_bucket for a loader) at which its opening,
/// the cutting edge (profile's first point) to the top of the back wall (its last), is
/// horizontal: the seed's §6.2 "upper edge leveled" [rad].
double BucketLevelAttitude(const MachineDescription& machine);

/// A planar point or vector [x, z] over any scalar (Eigen matrices would need NumTraits for the
/// nested dual numbers used for lever arms).
template <typename S>
struct V2 {
  S x, z;
};
template <typename S>
V2<S> operator+(const V2<S>& a, const V2<S>& b) {
  return {a.x + b.x, a.z + b.z};
}
template <typename S>
V2<S> operator-(const V2<S>& a, const V2<S>& b) {
  return {a.x - b.x, a.z - b.z};
}
template <typename S, typename K>
V2<S> operator*(const K& k, const V2<S>& a) {
  return {k * a.x, k * a.z};
}

/// One moving body of the arm at a configuration: centre of mass in M, angle, mass, inertia
/// about the centre of mass.
template <typename S>
struct BodyState {
  V2<S> center;
  S angle;
  double mass = 0;
  double inertia = 0;
};

/// Reference model of one machine. Holds a reference: the description must outlive it.
class InterpretedModel {
 public:
  explicit InterpretedModel(const MachineDescription& machine);

  const MachineDescription& machine() const { return machine_; }
  const ModelSizes& sizes() const { return sizes_; }

  /// Nominal calibration parameters [l_1 … l_n, α_1 … α_n] from the description.
  std::vector<double> NominalParams() const;

  /// Eq. (1)–(2): pose [x, y, z, φ_n] of the bucket tip in the base frame.
  template <typename S>
  void ForwardKinematics(const S* angles, const S* params, S* pose) const;

  /// IMU angles [θ_cab = 0, θ_k, (ψ)] that produce joint positions q with the given params.
  std::vector<double> AnglesFromJoints(const double* q, const double* params) const;

  /// Pose [x, y, z, φ_n] of the bucket tip for joint positions q, nominal parameters.
  Eigen::Vector4d TipFromJoints(const double* q) const;

  /// Link frame origins (n + 1: the last is the tip) and angles in M for joint positions q.
  template <typename S>
  void LinkFrames(const S* q, std::vector<V2<S>>& origins, std::vector<S>& angles) const;

  /// Rocker pivot in M and rocker angle of link `link`'s four-bar; false if it cannot close.
  template <typename S>
  bool SolveLinkage(int link, const std::vector<V2<S>>& origins, const std::vector<S>& angles,
                    V2<S>& rocker_origin, S& rocker_angle) const;

  /// Pin-to-pin length of cylinder `actuator` at joint positions q [m]; NaN if its linkage does
  /// not close. For a motor: the position of its joint [rad].
  template <typename S>
  S CylinderLength(int actuator, const S* q) const;

  /// ∂L/∂q_i for every joint i (the lever arms) [m/rad]; for a motor 1 on its joint.
  template <typename S>
  std::vector<S> LeverArms(int actuator, const S* q) const;

  /// Generalized gravity forces on the link joints [N·m] for joint positions q, a payload [kg]
  /// and the pitch of frame M [rad] (swing: 0).
  std::vector<double> GravityTorques(const double* q, double payload, double pitch) const;

  /// Every moving body at joint positions q (links, the payload point, rockers, couplers,
  /// cylinder barrels and rods; bodies without mass left out); false if a linkage cannot close.
  template <typename S>
  bool MovingBodies(const S* q, double payload, std::vector<BodyState<S>>& bodies) const;

  /// Rigid-body terms: mass matrix (J × J row-major), velocity terms h (Coriolis, centrifugal)
  /// and generalized gravity forces Q_g, so that M q̈ + h = Q_g + actuator + external forces.
  template <typename S>
  void Dynamics(const S* q, const S* qd, double payload, double pitch, S* mass, S* velocity_terms,
                S* gravity) const;

  /// Kinetic and potential energy of the arm [J] (potential zero at M's origin).
  std::array<double, 2> MechanicalEnergy(const double* q, const double* qd, double payload,
                                         double pitch) const;

  /// Plant right-hand side ẋ = f(t, x, u) (the model is autonomous: t does not enter).
  template <typename S>
  void PlantRhs(const S* x, const double* u, S* xdot) const;

  /// Dense ∂f/∂x, row-major, by automatic differentiation.
  void PlantJacobian(const double* x, const double* u, double* jacobian) const;

  int ActuatorOfJoint(int joint) const { return actuator_of_joint_[joint]; }

 private:
  template <typename S>
  V2<S> PointInM(const Mount& mount, int joint_link, const std::vector<V2<S>>& origins,
                 const std::vector<S>& angles, bool& ok) const;

  const MachineDescription& machine_;
  ModelSizes sizes_;
  Eigen::Vector2d payload_center_;
  std::vector<int> actuator_of_joint_;
};

// ---------------------------------------------------------------------------------------------
// Template definitions.

namespace internal {

template <typename S>
V2<S> Rotate(const S& angle, const Eigen::Vector2d& v) {
  using std::cos;
  using std::sin;
  const S c = cos(angle), s = sin(angle);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

template <typename S>
S SmoothPositive(const S& x, double width) {
  using std::sqrt;
  return (x + sqrt(x * x + width * width)) / 2.0;
}

template <typename S>
S SmoothStep(const S& x, double width) {
  using std::sqrt;
  return (1.0 + x / sqrt(x * x + width * width)) / 2.0;
}

template <typename S>
S OrificeRoot(const S& dp) {
  using std::pow;
  const double t = plant::kOrificeTransitionPressure;
  return dp / pow(dp * dp + t * t, 0.25);
}

}  // namespace internal

template <typename S>
void InterpretedModel::ForwardKinematics(const S* angles, const S* params, S* pose) const {
  using std::cos;
  using std::sin;
  const int n = sizes_.num_links;
  S x_m(0.0), z_m(0.0), phi(0.0);
  for (int k = 0; k < n; ++k) {
    phi = angles[k + 1] - angles[0] + params[n + k];  // Eq. (1)
    x_m += params[k] * cos(phi);                      // Eq. (2)
    z_m += params[k] * sin(phi);
  }
  const S radial = x_m + machine_.arm_pivot.x();
  if (machine_.swing) {
    const S psi = angles[n + 1];
    pose[0] = cos(psi) * radial;
    pose[1] = sin(psi) * radial;
  } else {
    pose[0] = radial;
    pose[1] = S(0.0);
  }
  pose[2] = z_m + machine_.arm_pivot.y();
  pose[3] = phi;
}

template <typename S>
void InterpretedModel::LinkFrames(const S* q, std::vector<V2<S>>& origins,
                                  std::vector<S>& angles) const {
  using std::cos;
  using std::sin;
  const int n = sizes_.num_links;
  origins.assign(n + 1, V2<S>{S(0.0), S(0.0)});
  angles.assign(n, S(0.0));
  S phi(0.0);
  for (int k = 0; k < n; ++k) {
    phi = (k == 0) ? q[0] : phi + q[k];
    angles[k] = phi;
    const double l = machine_.links[k].length;
    origins[k + 1] = origins[k] + V2<S>{l * cos(phi), l * sin(phi)};
  }
}

template <typename S>
bool InterpretedModel::SolveLinkage(int link, const std::vector<V2<S>>& origins,
                                    const std::vector<S>& angles, V2<S>& rocker_origin,
                                    S& rocker_angle) const {
  using std::atan2;
  using std::sqrt;
  const FourBarLinkage& bar = *machine_.links[link].linkage;
  // The rocker pivots on the parent link (frame M itself for the first link).
  const S parent_angle = link > 0 ? angles[link - 1] : S(0.0);
  const V2<S> parent_origin = link > 0 ? origins[link - 1] : V2<S>{S(0.0), S(0.0)};
  const V2<S> e = parent_origin + internal::Rotate(parent_angle, bar.rocker_pivot);
  const V2<S> g = origins[link] + internal::Rotate(angles[link], bar.child_coupler_point);
  const V2<S> eg = g - e;
  const S d2 = eg.x * eg.x + eg.z * eg.z;
  const S d = sqrt(d2);
  const double r = bar.rocker_length, c = bar.coupler_length;
  // Circle–circle intersection: F lies at distance r from E and c from G.
  const S a = (r * r - c * c + d2) / (2.0 * d);
  const S h2 = r * r - a * a;
  if (!(h2 > S(0.0))) return false;
  const S h = double(bar.assembly_branch) * sqrt(h2);
  const V2<S> unit{eg.x / d, eg.z / d};
  const V2<S> f = e + a * unit + h * V2<S>{-unit.z, unit.x};
  rocker_origin = e;
  rocker_angle = atan2(f.z - e.z, f.x - e.x);
  return true;
}

template <typename S>
V2<S> InterpretedModel::PointInM(const Mount& mount, int joint_link,
                                 const std::vector<V2<S>>& origins, const std::vector<S>& angles,
                                 bool& ok) const {
  if (mount.body == "chassis") return V2<S>{S(mount.point.x()), S(mount.point.y())};
  if (mount.body == "rocker") {
    V2<S> rocker_origin;
    S rocker_angle;
    if (!SolveLinkage(joint_link, origins, angles, rocker_origin, rocker_angle)) {
      ok = false;
      return V2<S>{S(0.0), S(0.0)};
    }
    return rocker_origin + internal::Rotate(rocker_angle, mount.point);
  }
  const int k = machine_.LinkIndex(mount.body);
  return origins[k] + internal::Rotate(angles[k], mount.point);
}

template <typename S>
S InterpretedModel::CylinderLength(int actuator, const S* q) const {
  using std::sqrt;
  const Actuator& act = machine_.hydraulics.actuators[actuator];
  if (act.kind == ActuatorKind::kMotor) return q[sizes_.num_joints - 1];
  const int joint_link = machine_.LinkIndex(act.joint);
  std::vector<V2<S>> origins;
  std::vector<S> angles;
  LinkFrames(q, origins, angles);
  bool ok = true;
  const V2<S> base = PointInM(act.base_mount, joint_link, origins, angles, ok);
  const V2<S> rod = PointInM(act.rod_mount, joint_link, origins, angles, ok);
  if (!ok) return S(std::numeric_limits<double>::quiet_NaN());
  const V2<S> d = rod - base;
  return sqrt(d.x * d.x + d.z * d.z);
}

template <typename S>
std::vector<S> InterpretedModel::LeverArms(int actuator, const S* q) const {
  const int J = sizes_.num_joints;
  std::vector<S> lever(J, S(0.0));
  const Actuator& act = machine_.hydraulics.actuators[actuator];
  if (act.kind == ActuatorKind::kMotor) {
    lever[J - 1] = S(1.0);
    return lever;
  }
  std::vector<Dual<S>> seeded(J);
  for (int i = 0; i < sizes_.num_links; ++i) {
    for (int k = 0; k < J; ++k) seeded[k] = Dual<S>(q[k], S(k == i ? 1.0 : 0.0));
    lever[i] = CylinderLength(actuator, seeded.data()).d;
  }
  return lever;
}

template <typename S>
void InterpretedModel::PlantRhs(const S* x, const double* u, S* xdot) const {
  using internal::OrificeRoot;
  using internal::SmoothPositive;
  const int J = sizes_.num_joints;
  const int n = sizes_.num_links;
  const S* q = x;
  const S* qd = x + J;
  const S* xs = x + 2 * J;
  const S* pa = x + 3 * J;
  const S* pb = x + 4 * J;
  const double* command = u;
  const double* tau_ext = u + J;
  const double payload = u[2 * J];
  const double pitch = u[2 * J + 1];
  const Hydraulics& hyd = machine_.hydraulics;

  std::vector<S> mass(J * J), velocity_terms(J), generalized(J);
  Dynamics(q, qd, payload, pitch, mass.data(), velocity_terms.data(), generalized.data());

  const double p_tank = hyd.tank_pressure;
  for (int j = 0; j < J; ++j) {
    const Actuator& act = hyd.actuators[actuator_of_joint_[j]];
    const Valve& valve = act.valve;
    // Supply behind this valve section (a pressure-compensated load-sensing system gives each
    // section its own: load plus margin; see runtime/plant/plant.h).
    const double p_pump = u[2 * J + 2 + j];
    S area_a(0.0), area_b(0.0), volume_a(0.0), volume_b(0.0), extension_rate(0.0);
    S end_force(0.0);
    const std::vector<S> lever = LeverArms(actuator_of_joint_[j], q);
    if (act.kind == ActuatorKind::kMotor) {
      area_a = area_b = S(act.displacement);
      volume_a = volume_b = S(act.line_volume);
      extension_rate = qd[j];
    } else {
      const double c = act.count * std::numbers::pi / 4.0;
      area_a = S(c * act.bore * act.bore);
      area_b = S(c * (act.bore * act.bore - act.rod * act.rod));
      const S s = CylinderLength(actuator_of_joint_[j], q) - act.retracted_length;
      volume_a = act.dead_volume + area_a * s;
      volume_b = act.dead_volume + area_b * (act.stroke - s);
      for (int i = 0; i < J; ++i) extension_rate += lever[i] * qd[i];
      end_force = act.count * plant::kEndStopStiffness *
                      (SmoothPositive(S(-s), plant::kEndStopSmoothing) -
                       SmoothPositive(S(s - act.stroke), plant::kEndStopSmoothing)) -
                  act.count * plant::kEndStopDamping * extension_rate *
                      (internal::SmoothStep(S(-s), plant::kEndStopSmoothing) +
                       internal::SmoothStep(S(s - act.stroke), plant::kEndStopSmoothing));
    }
    const S open_a = SmoothPositive(xs[j], plant::kSpoolUnderlap);
    const S open_b = SmoothPositive(S(-xs[j]), plant::kSpoolUnderlap);
    // From the supply only through the section's load check valve (plant_constants.h).
    const S flow_a =
        valve.flow_gain *
        (open_a * OrificeRoot(SmoothPositive(S(p_pump - pa[j]), plant::kCheckValveWidth)) -
         open_b * OrificeRoot(S(pa[j] - p_tank)));
    const S flow_b =
        valve.flow_gain *
        (open_b * OrificeRoot(SmoothPositive(S(p_pump - pb[j]), plant::kCheckValveWidth)) -
         open_a * OrificeRoot(S(pb[j] - p_tank)));
    const double relief_gain = valve.rated_flow / plant::kReliefFullFlowOverpressure;
    auto relief = [&](const S& p) {
      // Relief to tank above the setting, anti-cavitation make-up from tank below tank pressure.
      return relief_gain *
             (SmoothPositive(S(p - act.relief_pressure), plant::kReliefPressureWidth) -
              SmoothPositive(S(p_tank - p), plant::kReliefPressureWidth));
    };
    xdot[2 * J + j] = (command[j] - xs[j]) / valve.spool_time_constant;
    xdot[3 * J + j] =
        hyd.bulk_modulus / volume_a * (flow_a - area_a * extension_rate - relief(pa[j]));
    xdot[4 * J + j] =
        hyd.bulk_modulus / volume_b * (flow_b + area_b * extension_rate - relief(pb[j]));
    const S force = pa[j] * area_a - pb[j] * area_b + end_force;
    for (int i = 0; i < J; ++i) generalized[i] += force * lever[i];
  }
  std::vector<S> force(J);
  for (int j = 0; j < J; ++j) {
    const double friction =
        j < n ? machine_.links[j].viscous_friction : machine_.swing->viscous_friction;
    xdot[j] = qd[j];
    force[j] = generalized[j] + tau_ext[j] - friction * qd[j] - velocity_terms[j];
  }
  // M q̈ = force by Gaussian elimination (M is symmetric positive definite: no pivoting).
  for (int k = 0; k < J; ++k) {
    for (int i = k + 1; i < J; ++i) {
      const S factor = mass[i * J + k] / mass[k * J + k];
      for (int c = k; c < J; ++c) mass[i * J + c] = mass[i * J + c] - factor * mass[k * J + c];
      force[i] = force[i] - factor * force[k];
    }
  }
  for (int i = J - 1; i >= 0; --i) {
    S value = force[i];
    for (int c = i + 1; c < J; ++c) value = value - mass[i * J + c] * xdot[J + c];
    xdot[J + i] = value / mass[i * J + i];
  }
}

template <typename S>
bool InterpretedModel::MovingBodies(const S* q, double payload,
                                    std::vector<BodyState<S>>& bodies) const {
  using std::atan2;
  using std::sqrt;
  const int n = sizes_.num_links;
  std::vector<V2<S>> origins;
  std::vector<S> angles;
  LinkFrames(q, origins, angles);
  bodies.clear();
  for (int k = 0; k < n; ++k) {
    const Link& link = machine_.links[k];
    bodies.push_back({origins[k] + internal::Rotate(angles[k], link.center_of_mass), angles[k],
                      link.mass, link.inertia});
  }
  bodies.push_back({origins[n - 1] + internal::Rotate(angles[n - 1], payload_center_),
                    angles[n - 1], payload, 0.0});
  bool ok = true;
  for (int k = 1; k < n; ++k) {
    if (!machine_.links[k].linkage) continue;
    const FourBarLinkage& bar = *machine_.links[k].linkage;
    V2<S> pivot;
    S rocker_angle;
    if (!SolveLinkage(k, origins, angles, pivot, rocker_angle)) return false;
    if (bar.rocker_mass > 0) {
      bodies.push_back({pivot + internal::Rotate(rocker_angle, bar.rocker_center_of_mass),
                        rocker_angle, bar.rocker_mass, bar.rocker_inertia});
    }
    if (bar.coupler_mass > 0) {
      const V2<S> f =
          pivot + internal::Rotate(rocker_angle, Eigen::Vector2d(bar.rocker_length, 0.0));
      const V2<S> g = origins[k] + internal::Rotate(angles[k], bar.child_coupler_point);
      const V2<S> fg = g - f;
      bodies.push_back({0.5 * (f + g), atan2(fg.z, fg.x), bar.coupler_mass, bar.coupler_inertia});
    }
  }
  for (const Actuator& act : machine_.hydraulics.actuators) {
    if (act.kind != ActuatorKind::kCylinder || (act.barrel_mass <= 0 && act.rod_mass <= 0)) {
      continue;
    }
    const int joint_link = machine_.LinkIndex(act.joint);
    const V2<S> base = PointInM(act.base_mount, joint_link, origins, angles, ok);
    const V2<S> rod = PointInM(act.rod_mount, joint_link, origins, angles, ok);
    if (!ok) return false;
    const V2<S> axis = rod - base;
    const S length = sqrt(axis.x * axis.x + axis.z * axis.z);
    const S angle = atan2(axis.z, axis.x);
    const V2<S> unit{axis.x / length, axis.z / length};
    // Barrel and rod as slender uniform bars of twice their centre's distance from the pin.
    if (act.barrel_mass > 0) {
      bodies.push_back({base + act.barrel_center * unit, angle, act.count * act.barrel_mass,
                        act.count * act.barrel_mass * act.barrel_center * act.barrel_center / 3});
    }
    if (act.rod_mass > 0) {
      bodies.push_back({rod - act.rod_center * unit, angle, act.count * act.rod_mass,
                        act.count * act.rod_mass * act.rod_center * act.rod_center / 3});
    }
  }
  return true;
}

template <typename S>
void InterpretedModel::Dynamics(const S* q, const S* qd, double payload, double pitch, S* mass,
                                S* velocity_terms, S* gravity) const {
  const int J = sizes_.num_joints, n = sizes_.num_links;
  const double g_x = -plant::kGravity * std::sin(pitch);
  const double g_z = -plant::kGravity * std::cos(pitch);
  const S nan(std::numeric_limits<double>::quiet_NaN());
  // Body Jacobians, one forward pass per link joint.
  std::vector<std::vector<BodyState<Dual<S>>>> seeded(n);
  std::vector<Dual<S>> qs(J);
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < J; ++i) qs[i] = Dual<S>(q[i], S(i == k ? 1.0 : 0.0));
    if (!MovingBodies(qs.data(), payload, seeded[k])) {
      for (int i = 0; i < J * J; ++i) mass[i] = nan;
      for (int i = 0; i < J; ++i) velocity_terms[i] = gravity[i] = nan;
      return;
    }
  }
  // J̇q̇ = d²c(q + s q̇)/ds² at s = 0: nested dual numbers seeded with q̇ at both levels.
  std::vector<Dual<Dual<S>>> qq(J);
  for (int i = 0; i < J; ++i) {
    qq[i] = Dual<Dual<S>>(Dual<S>(q[i], qd[i]), Dual<S>(qd[i], S(0.0)));
  }
  std::vector<BodyState<Dual<Dual<S>>>> curved;
  MovingBodies(qq.data(), payload, curved);
  for (int i = 0; i < J * J; ++i) mass[i] = S(0.0);
  for (int i = 0; i < J; ++i) velocity_terms[i] = gravity[i] = S(0.0);
  S swing_inertia(0.0), swing_momentum_rate(0.0);
  for (std::size_t b = 0; b < curved.size(); ++b) {
    const double m = curved[b].mass, inertia = curved[b].inertia;
    const S ax = curved[b].center.x.d.d, az = curved[b].center.z.d.d, aphi = curved[b].angle.d.d;
    for (int i = 0; i < n; ++i) {
      const BodyState<Dual<S>>& bi = seeded[i][b];
      for (int j = 0; j < n; ++j) {
        const BodyState<Dual<S>>& bj = seeded[j][b];
        mass[i * J + j] = mass[i * J + j] +
                          m * (bi.center.x.d * bj.center.x.d + bi.center.z.d * bj.center.z.d) +
                          inertia * bi.angle.d * bj.angle.d;
      }
      velocity_terms[i] = velocity_terms[i] + m * (bi.center.x.d * ax + bi.center.z.d * az) +
                          inertia * bi.angle.d * aphi;
      gravity[i] = gravity[i] + m * (g_x * bi.center.x.d + g_z * bi.center.z.d);
    }
    if (machine_.swing) {
      const S radial = curved[b].center.x.v.v + machine_.arm_pivot.x();
      const S radial_rate = curved[b].center.x.v.d;
      swing_inertia = swing_inertia + m * radial * radial;
      swing_momentum_rate = swing_momentum_rate + 2.0 * m * radial * radial_rate * qd[n];
      for (int i = 0; i < n; ++i) {
        velocity_terms[i] =
            velocity_terms[i] - m * radial * seeded[i][b].center.x.d * qd[n] * qd[n];
      }
    }
  }
  if (machine_.swing) {
    mass[n * J + n] = machine_.swing->inertia + swing_inertia;
    velocity_terms[n] = swing_momentum_rate;
  }
}

}  // namespace autoshovel::model
