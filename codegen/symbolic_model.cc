// Builds the symbolic model. The plant is derived from the Lagrangian quantities (gravity as
// −∂V/∂q, joint inertia from |∂c/∂q|²), deliberately not the way the interpreted reference model
// (runtime/model/interpreted_model.h) computes them, so that the verification tests compare two
// derivations of the same physics.
#include "codegen/symbolic_model.h"

#include <numbers>

#include "runtime/model/interpreted_model.h"
#include "runtime/model/plant_constants.h"

namespace autoshovel::codegen {
namespace {

using GiNaC::ex;
using model::ActuatorKind;
using model::MachineDescription;

struct P2 {
  ex x, z;
};
P2 operator+(const P2& a, const P2& b) { return {a.x + b.x, a.z + b.z}; }
P2 operator-(const P2& a, const P2& b) { return {a.x - b.x, a.z - b.z}; }
P2 Scale(const ex& k, const P2& a) { return {k * a.x, k * a.z}; }
P2 Rotate(const ex& angle, const Eigen::Vector2d& v) {
  return {GiNaC::cos(angle) * v.x() - GiNaC::sin(angle) * v.y(),
          GiNaC::sin(angle) * v.x() + GiNaC::cos(angle) * v.y()};
}
P2 Constant(const Eigen::Vector2d& v) { return {ex(v.x()), ex(v.y())}; }
ex Norm(const P2& a) { return GiNaC::sqrt(a.x * a.x + a.z * a.z); }
ex Smooth(const ex& value, double width) {
  return (value + GiNaC::sqrt(value * value + width * width)) / 2;
}

// d Smooth / d value: a smooth step from 0 to 1 over `width`.
ex Step(const ex& value, double width) {
  return (1 + value / GiNaC::sqrt(value * value + width * width)) / 2;
}

// Link frames in M from joint positions: φ_1 = q_1, φ_k = φ_{k−1} + q_k.
struct Frames {
  std::vector<P2> origins;  // n + 1
  std::vector<ex> angles;   // n
};

Frames LinkFrames(const MachineDescription& m, const std::vector<ex>& q) {
  Frames f;
  f.origins.push_back({0, 0});
  ex phi = 0;
  for (std::size_t k = 0; k < m.links.size(); ++k) {
    phi = k == 0 ? q[0] : phi + q[k];
    f.angles.push_back(phi);
    const double l = m.links[k].length;
    f.origins.push_back(f.origins.back() + P2{l * GiNaC::cos(phi), l * GiNaC::sin(phi)});
  }
  return f;
}

// The rocker of link `link`'s four-bar: its pivot E in M and its angle (towards F). Four-bar
// closure: F lies at distance r from E and c from the child's coupler point G.
struct RockerPose {
  P2 pivot, far_end, coupler_point;
  ex angle;
};

RockerPose Rocker(const MachineDescription& m, int link, const Frames& f) {
  const model::FourBarLinkage& bar = *m.links[link].linkage;
  const P2 e = f.origins[link - 1] + Rotate(f.angles[link - 1], bar.rocker_pivot);
  const P2 g = f.origins[link] + Rotate(f.angles[link], bar.child_coupler_point);
  const P2 eg = g - e;
  const ex d2 = eg.x * eg.x + eg.z * eg.z;
  const ex d = GiNaC::sqrt(d2);
  const double r = bar.rocker_length, c = bar.coupler_length;
  const ex a = (r * r - c * c + d2) / (2 * d);
  const ex h = bar.assembly_branch * GiNaC::sqrt(r * r - a * a);
  const P2 f_point{e.x + (a * eg.x - h * eg.z) / d, e.z + (a * eg.z + h * eg.x) / d};
  return {e, f_point, g, GiNaC::atan2(f_point.z - e.z, f_point.x - e.x)};
}

P2 MountPoint(const MachineDescription& m, const model::Mount& mount, int joint_link,
              const Frames& f) {
  if (mount.body == "chassis") return Constant(mount.point);
  if (mount.body == "rocker") {
    const RockerPose rocker = Rocker(m, joint_link, f);
    return rocker.pivot + Rotate(rocker.angle, mount.point);
  }
  const int k = m.LinkIndex(mount.body);
  return f.origins[k] + Rotate(f.angles[k], mount.point);
}

ex CylinderLength(const MachineDescription& m, int actuator, const std::vector<ex>& q) {
  const model::Actuator& a = m.hydraulics.actuators[actuator];
  if (a.kind == ActuatorKind::kMotor) return q.back();
  const int joint_link = m.LinkIndex(a.joint);
  const Frames f = LinkFrames(m, q);
  return Norm(MountPoint(m, a.rod_mount, joint_link, f) -
              MountPoint(m, a.base_mount, joint_link, f));
}

// Eq. (2) in frame M from IMU angles: φ_k = θ_k − θ_cab + α_k (Eq. 1).
P2 TipInM(const MachineDescription& m, const std::vector<ex>& angles,
          const std::vector<GiNaC::symbol>& params, ex* last_phi) {
  const int n = static_cast<int>(m.links.size());
  P2 tip{0, 0};
  for (int k = 0; k < n; ++k) {
    const ex phi = angles[k + 1] - angles[0] + params[n + k];
    tip = tip + Scale(params[k], P2{GiNaC::cos(phi), GiNaC::sin(phi)});
    if (last_phi != nullptr) *last_phi = phi;
  }
  return tip;
}

std::vector<ex> AsEx(const std::vector<GiNaC::symbol>& symbols) {
  return std::vector<ex>(symbols.begin(), symbols.end());
}

void BuildKinematics(const MachineDescription& m, SymbolicMachine& s) {
  ex phi_n;
  const P2 tip = TipInM(m, AsEx(s.angles), s.params, &phi_n);
  const ex radial = tip.x + m.arm_pivot.x();
  if (m.swing) {
    const ex psi = s.angles[s.num_links + 1];
    s.pose = {GiNaC::cos(psi) * radial, GiNaC::sin(psi) * radial, tip.z + m.arm_pivot.y(), phi_n};
  } else {
    s.pose = {radial, ex(0), tip.z + m.arm_pivot.y(), phi_n};
  }
  for (const ex& p : s.pose) {
    for (const auto& a : s.angles) s.d_pose_d_angles.push_back(p.diff(a));
  }
  for (const ex& p : s.pose) {
    for (const auto& a : s.params) s.d_pose_d_params.push_back(p.diff(a));
  }
  const auto ai = MakeSymbols("angles_i", s.num_angles);
  const auto aj = MakeSymbols("angles_j", s.num_angles);
  const P2 tip_i = TipInM(m, AsEx(ai), s.params, nullptr);
  const P2 tip_j = TipInM(m, AsEx(aj), s.params, nullptr);
  s.tip_m_i = {tip_i.x, tip_i.z};
  s.tip_m_j = {tip_j.x, tip_j.z};

  // Inverse: the planar two-link problem (boom, next link) to the wrist point W, for both
  // elbow branches σ. For a loader W is the tip; for an excavator W = tip − l_3 (cos φ_3,
  // sin φ_3) in the arm plane and the swing is atan2(y, x).
  const auto target = MakeSymbols("target", 4);
  ex wx, wz;
  const ex l1 = s.params[0], l2 = s.params[1];
  if (m.swing) {
    const ex radial_t = GiNaC::sqrt(target[0] * target[0] + target[1] * target[1]);
    wx = radial_t - m.arm_pivot.x() - s.params[2] * GiNaC::cos(target[3]);
    wz = target[2] - m.arm_pivot.y() - s.params[2] * GiNaC::sin(target[3]);
  } else {
    wx = target[0] - m.arm_pivot.x();
    wz = target[2] - m.arm_pivot.y();
  }
  const ex cos_q2 = (wx * wx + wz * wz - l1 * l1 - l2 * l2) / (2 * l1 * l2);
  s.inverse_cos_elbow = cos_q2;
  for (int b = 0; b < 2; ++b) {
    const int sigma = b == 0 ? 1 : -1;
    const ex q2 = sigma * GiNaC::acos(cos_q2);
    const ex q1 =
        GiNaC::atan2(wz, wx) - GiNaC::atan2(l2 * GiNaC::sin(q2), l1 + l2 * GiNaC::cos(q2));
    s.inverse[b] = {q1, q2};
    if (m.swing) {
      s.inverse[b].push_back(target[3] - q1 - q2);
      s.inverse[b].push_back(GiNaC::atan2(target[1], target[0]));
    }
  }
}

void BuildCylinders(const MachineDescription& m, SymbolicMachine& s) {
  const std::vector<ex> q = AsEx(s.q);
  for (std::size_t i = 0; i < m.hydraulics.actuators.size(); ++i) {
    const ex length = CylinderLength(m, static_cast<int>(i), q);
    const model::Actuator& a = m.hydraulics.actuators[i];
    const int joint = a.joint == "swing" ? s.num_joints - 1 : m.LinkIndex(a.joint);
    s.cylinder_length.push_back(length);
    s.lever_arm.push_back(length.diff(s.q[joint]));
  }
}

// Every moving body of the arm as a planar rigid body: its centre of mass in M, its angle,
// mass and inertia about the centre of mass. Links, the payload riding on the last link, the
// rocker and coupler of each four-bar, and each cylinder's barrel and rod (a body without mass
// is left out). Positions are functions of the driven joints q alone: the passive angles of the
// closed chains are solved in closed form (Rocker), so the Lagrangian below is already
// projected onto the independent coordinates.
struct Body {
  P2 center;
  ex angle;
  ex mass;
  double inertia;
};

std::vector<Body> MovingBodies(const MachineDescription& m, const std::vector<ex>& q,
                               const ex& payload) {
  const int n = static_cast<int>(m.links.size());
  const Frames f = LinkFrames(m, q);
  std::vector<Body> bodies;
  for (int k = 0; k < n; ++k) {
    const model::Link& link = m.links[k];
    bodies.push_back({f.origins[k] + Rotate(f.angles[k], link.center_of_mass), f.angles[k],
                      link.mass, link.inertia});
  }
  bodies.push_back({f.origins[n - 1] + Rotate(f.angles[n - 1], model::BucketPayloadCenter(m)),
                    f.angles[n - 1], payload, 0.0});
  for (int k = 1; k < n; ++k) {
    if (!m.links[k].linkage) continue;
    const model::FourBarLinkage& bar = *m.links[k].linkage;
    const RockerPose rocker = Rocker(m, k, f);
    if (bar.rocker_mass > 0) {
      bodies.push_back({rocker.pivot + Rotate(rocker.angle, bar.rocker_center_of_mass),
                        rocker.angle, bar.rocker_mass, bar.rocker_inertia});
    }
    if (bar.coupler_mass > 0) {
      const P2 fg = rocker.coupler_point - rocker.far_end;
      bodies.push_back({Scale(ex(1) / 2, rocker.far_end + rocker.coupler_point),
                        GiNaC::atan2(fg.z, fg.x), bar.coupler_mass, bar.coupler_inertia});
    }
  }
  for (const model::Actuator& a : m.hydraulics.actuators) {
    if (a.kind != ActuatorKind::kCylinder || (a.barrel_mass <= 0 && a.rod_mass <= 0)) continue;
    const int joint_link = m.LinkIndex(a.joint);
    const P2 base = MountPoint(m, a.base_mount, joint_link, f);
    const P2 rod = MountPoint(m, a.rod_mount, joint_link, f);
    const P2 axis = rod - base;
    const ex length = Norm(axis);
    const ex angle = GiNaC::atan2(axis.z, axis.x);
    // Each part as a slender uniform bar of twice its centre's distance from its pin.
    if (a.barrel_mass > 0) {
      bodies.push_back({base + Scale(a.barrel_center / length, axis), angle,
                        a.count * a.barrel_mass,
                        a.count * a.barrel_mass * a.barrel_center * a.barrel_center / 3});
    }
    if (a.rod_mass > 0) {
      bodies.push_back({rod - Scale(a.rod_center / length, axis), angle, a.count * a.rod_mass,
                        a.count * a.rod_mass * a.rod_center * a.rod_center / 3});
    }
  }
  return bodies;
}

// Rigid-body dynamics from the Lagrangian L = T − V of every moving body:
//   T = ½ Σ_b (m_b |ċ_b|² + I_b φ̇_b²) [+ ½ (I_swing + Σ_b m_b r_b²) ψ̇² on an excavator, with
//   r_b the body's distance from the swing axis], V = −Σ_b m_b g_M·c_b,
// gives M(q) q̈ + h(q, q̇) − Q_g(q) = τ with M = Σ m J_cᵀJ_c + I J_φᵀJ_φ, the velocity-product
// terms h = Σ m J_cᵀ(J̇_c q̇) + I J_φᵀ(J̇_φ q̇) (Coriolis and centrifugal; J̇q̇ is the second
// directional derivative of the position along q̇) plus the swing's centrifugal and Coriolis
// couplings, and Q_g = −∂V/∂q.
void BuildRigidBodyDynamics(const MachineDescription& m, SymbolicMachine& s,
                            std::vector<ex>& gravity_force) {
  const int J = s.num_joints, n = s.num_links;
  const std::vector<ex> q(s.x.begin(), s.x.begin() + J);
  const std::vector<ex> qd(s.x.begin() + J, s.x.begin() + 2 * J);
  const ex payload = s.u[2 * J], pitch = s.u[2 * J + 1];
  const std::vector<Body> bodies = MovingBodies(m, q, payload);

  const P2 gravity{-model::plant::kGravity * GiNaC::sin(pitch),
                   -model::plant::kGravity * GiNaC::cos(pitch)};
  ex potential = 0;
  for (const Body& b : bodies)
    potential -= b.mass * (gravity.x * b.center.x + gravity.z * b.center.z);

  s.mass_matrix.assign(J * J, ex(0));
  std::vector<ex> h(J, ex(0));
  ex swing_inertia = 0, swing_momentum_rate = 0;
  for (const Body& b : bodies) {
    std::vector<ex> jx(n), jz(n), jphi(n);
    for (int k = 0; k < n; ++k) {
      jx[k] = b.center.x.diff(s.x[k]);
      jz[k] = b.center.z.diff(s.x[k]);
      jphi[k] = b.angle.diff(s.x[k]);
    }
    // J̇q̇ = Σ_k Σ_l ∂²c/∂q_k∂q_l q̇_k q̇_l.
    ex ax = 0, az = 0, aphi = 0;
    for (int k = 0; k < n; ++k) {
      ex vx = 0, vz = 0, vphi = 0;
      for (int l = 0; l < n; ++l) {
        vx += jx[l].diff(s.x[k]) * qd[l];
        vz += jz[l].diff(s.x[k]) * qd[l];
        vphi += jphi[l].diff(s.x[k]) * qd[l];
      }
      ax += vx * qd[k];
      az += vz * qd[k];
      aphi += vphi * qd[k];
    }
    for (int i = 0; i < n; ++i) {
      for (int j = i; j < n; ++j) {
        s.mass_matrix[i * J + j] +=
            b.mass * (jx[i] * jx[j] + jz[i] * jz[j]) + b.inertia * jphi[i] * jphi[j];
      }
      h[i] += b.mass * (jx[i] * ax + jz[i] * az) + b.inertia * jphi[i] * aphi;
    }
    if (m.swing) {
      const ex radial = b.center.x + m.arm_pivot.x();
      ex radial_rate = 0;
      for (int k = 0; k < n; ++k) radial_rate += jx[k] * qd[k];
      swing_inertia += b.mass * radial * radial;
      swing_momentum_rate += 2 * b.mass * radial * radial_rate * qd[n];
      // ∂T/∂q_i holds m r ∂r/∂q_i ψ̇²: the centrifugal pull of the swing on the arm.
      for (int i = 0; i < n; ++i) h[i] -= b.mass * radial * jx[i] * qd[n] * qd[n];
    }
  }
  if (m.swing) {
    s.mass_matrix[n * J + n] = m.swing->inertia + swing_inertia;
    h[n] = swing_momentum_rate;
  }
  for (int i = 0; i < J; ++i) {
    for (int j = 0; j < i; ++j) s.mass_matrix[i * J + j] = s.mass_matrix[j * J + i];
  }
  gravity_force.assign(J, ex(0));
  for (int j = 0; j < n; ++j) gravity_force[j] = -potential.diff(s.x[j]);
  s.bias.resize(J);
  for (int j = 0; j < J; ++j) s.bias[j] = h[j] - gravity_force[j];
  ex kinetic = 0;
  for (int i = 0; i < J; ++i) {
    for (int j = 0; j < J; ++j) kinetic += s.mass_matrix[i * J + j] * qd[i] * qd[j];
  }
  s.energy = {kinetic / 2, potential};
  s.velocity_terms = h;
}

void BuildPlant(const MachineDescription& m, SymbolicMachine& s) {
  const int J = s.num_joints, n = s.num_links;
  std::vector<ex> q(s.x.begin(), s.x.begin() + J);
  const std::vector<ex> qd(s.x.begin() + J, s.x.begin() + 2 * J);
  std::vector<ex> generalized;
  BuildRigidBodyDynamics(m, s, generalized);

  const auto& hyd = m.hydraulics;
  std::vector<ex> xdot(s.num_states);
  for (int j = 0; j < J; ++j) {
    const int index = m.ActuatorOfJoint(j);
    const model::Actuator& a = hyd.actuators[index];
    const ex xs = s.x[2 * J + j], pa = s.x[3 * J + j], pb = s.x[4 * J + j];
    ex area_a, area_b, volume_a, volume_b, rate, end_force = 0;
    std::vector<ex> lever(J, 0);
    if (a.kind == ActuatorKind::kMotor) {
      area_a = area_b = a.displacement;
      volume_a = volume_b = a.line_volume;
      rate = qd[j];
      lever[j] = 1;
    } else {
      const ex length = CylinderLength(m, index, q);
      for (int i = 0; i < J; ++i) lever[i] = length.diff(s.x[i]);
      const double c = a.count * std::numbers::pi / 4;
      area_a = c * a.bore * a.bore;
      area_b = c * (a.bore * a.bore - a.rod * a.rod);
      const ex extension = length - a.retracted_length;
      volume_a = a.dead_volume + area_a * extension;
      volume_b = a.dead_volume + area_b * (a.stroke - extension);
      rate = 0;
      for (int i = 0; i < J; ++i) rate += lever[i] * qd[i];
      end_force = a.count * model::plant::kEndStopStiffness *
                      (Smooth(-extension, model::plant::kEndStopSmoothing) -
                       Smooth(extension - a.stroke, model::plant::kEndStopSmoothing)) -
                  a.count * model::plant::kEndStopDamping * rate *
                      (Step(-extension, model::plant::kEndStopSmoothing) +
                       Step(extension - a.stroke, model::plant::kEndStopSmoothing));
    }
    const double t = model::plant::kOrificeTransitionPressure;
    auto orifice = [t](const ex& dp) {
      return dp / GiNaC::pow(dp * dp + t * t, GiNaC::numeric(1, 4));
    };
    const ex open_a = Smooth(xs, model::plant::kSpoolUnderlap);
    const ex open_b = Smooth(-xs, model::plant::kSpoolUnderlap);
    const ex pp = s.u[2 * J + 2 + j];  // this valve section's supply pressure (an input)
    const double pt = hyd.tank_pressure, kv = a.valve.flow_gain;
    // From the supply only through the section's load check valve (plant_constants.h).
    const double wc = model::plant::kCheckValveWidth;
    const ex flow_a = kv * (open_a * orifice(Smooth(pp - pa, wc)) - open_b * orifice(pa - pt));
    const ex flow_b = kv * (open_b * orifice(Smooth(pp - pb, wc)) - open_a * orifice(pb - pt));
    const double relief_gain = a.valve.rated_flow / model::plant::kReliefFullFlowOverpressure;
    auto relief = [&](const ex& p) {
      return relief_gain * (Smooth(p - a.relief_pressure, model::plant::kReliefPressureWidth) -
                            Smooth(pt - p, model::plant::kReliefPressureWidth));
    };
    xdot[2 * J + j] = (s.u[j] - xs) / a.valve.spool_time_constant;
    xdot[3 * J + j] = hyd.bulk_modulus / volume_a * (flow_a - area_a * rate - relief(pa));
    xdot[4 * J + j] = hyd.bulk_modulus / volume_b * (flow_b + area_b * rate - relief(pb));
    const ex force = pa * area_a - pb * area_b + end_force;
    for (int i = 0; i < J; ++i) generalized[i] += force * lever[i];
  }
  // M q̈ = force: hydraulic, gravity, external and friction forces less the velocity terms.
  s.force.resize(J);
  for (int j = 0; j < J; ++j) {
    const double friction = j < n ? m.links[j].viscous_friction : m.swing->viscous_friction;
    xdot[j] = qd[j];
    xdot[J + j] = 0;  // solved numerically from the mass matrix in the emitted code
    s.force[j] = generalized[j] + s.u[J + j] - friction * qd[j] - s.velocity_terms[j];
  }
  s.rhs = xdot;
  for (int row = 0; row < s.num_states; ++row) {
    for (const auto& xi : s.x) {
      s.jacobian.push_back(row >= J && row < 2 * J ? ex(0) : s.rhs[row].diff(xi));
    }
  }
  // ∂force/∂x, except ∂h/∂q: h already holds second derivatives of the closed chain's body
  // positions, and a third symbolic derivative swells the expressions past what GiNaC builds in
  // reasonable time once rockers, couplers and cylinders have mass (minutes per machine). The
  // emitted Jacobian adds −∂h/∂q by central differences of the emitted h instead (h is small
  // beside the hydraulic forces in these rows, so the rounding stays far below the row's scale).
  for (int j = 0; j < J; ++j) {
    const ex without_velocity_terms = s.force[j] + s.velocity_terms[j];
    for (int i = 0; i < s.num_states; ++i) {
      const ex& source = i < J ? without_velocity_terms : s.force[j];
      s.d_force_d_x.push_back(source.diff(s.x[i]));
    }
  }
  for (int k = 0; k < J; ++k) {
    for (const ex& entry : s.mass_matrix) s.d_mass_d_q.push_back(entry.diff(s.x[k]));
  }
}

}  // namespace

std::vector<GiNaC::symbol> MakeSymbols(const std::string& array, int count) {
  std::vector<GiNaC::symbol> out;
  for (int i = 0; i < count; ++i) out.emplace_back(array + "[" + std::to_string(i) + "]");
  return out;
}

SymbolicMachine BuildSymbolicMachine(const MachineDescription& machine) {
  const model::ModelSizes sizes = model::SizesOf(machine);
  SymbolicMachine s;
  s.num_links = sizes.num_links;
  s.num_joints = sizes.num_joints;
  s.num_angles = sizes.num_angles;
  s.num_params = sizes.num_params;
  s.num_states = sizes.num_states;
  s.num_inputs = sizes.num_inputs;
  s.angles = MakeSymbols("angles", s.num_angles);
  s.params = MakeSymbols("params", s.num_params);
  s.q = MakeSymbols("q", s.num_joints);
  s.x = MakeSymbols("x", s.num_states);
  s.u = MakeSymbols("u", s.num_inputs);
  BuildKinematics(machine, s);
  BuildCylinders(machine, s);
  BuildPlant(machine, s);
  return s;
}

}  // namespace autoshovel::codegen
