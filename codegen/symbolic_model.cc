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

P2 MountPoint(const MachineDescription& m, const model::Mount& mount, int joint_link,
              const Frames& f) {
  if (mount.body == "chassis") return Constant(mount.point);
  if (mount.body == "rocker") {
    // Four-bar closure: F at distance r from the rocker pivot E and c from the bucket point G.
    const model::FourBarLinkage& bar = *m.links[joint_link].linkage;
    const P2 e = f.origins[joint_link - 1] + Rotate(f.angles[joint_link - 1], bar.rocker_pivot);
    const P2 g = f.origins[joint_link] + Rotate(f.angles[joint_link], bar.child_coupler_point);
    const P2 eg = g - e;
    const ex d2 = eg.x * eg.x + eg.z * eg.z;
    const ex d = GiNaC::sqrt(d2);
    const double r = bar.rocker_length, c = bar.coupler_length;
    const ex a = (r * r - c * c + d2) / (2 * d);
    const ex h = bar.assembly_branch * GiNaC::sqrt(r * r - a * a);
    const P2 f_point{e.x + (a * eg.x - h * eg.z) / d, e.z + (a * eg.z + h * eg.x) / d};
    const ex rocker_angle = GiNaC::atan2(f_point.z - e.z, f_point.x - e.x);
    return e + Rotate(rocker_angle, mount.point);
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

void BuildPlant(const MachineDescription& m, SymbolicMachine& s) {
  const int J = s.num_joints, n = s.num_links;
  std::vector<ex> q(s.x.begin(), s.x.begin() + J);
  const std::vector<ex> qd(s.x.begin() + J, s.x.begin() + 2 * J);
  const ex payload = s.u[2 * J], pitch = s.u[2 * J + 1];
  const Frames f = LinkFrames(m, q);
  const Eigen::Vector2d payload_center = model::BucketPayloadCenter(m);

  // Bodies: link centres of mass and the payload point on the last link.
  struct Body {
    P2 center;
    ex angle;
    ex mass;
    double inertia;
  };
  std::vector<Body> bodies;
  for (int k = 0; k < n; ++k) {
    bodies.push_back({f.origins[k] + Rotate(f.angles[k], m.links[k].center_of_mass), f.angles[k],
                      m.links[k].mass, m.links[k].inertia});
  }
  bodies.push_back(
      {f.origins[n - 1] + Rotate(f.angles[n - 1], payload_center), f.angles[n - 1], payload, 0.0});

  // Potential energy V = −Σ m g_M·c, gravity in M for a frame pitched by `pitch`.
  const P2 gravity{-model::plant::kGravity * GiNaC::sin(pitch),
                   -model::plant::kGravity * GiNaC::cos(pitch)};
  ex potential = 0;
  for (const Body& b : bodies)
    potential -= b.mass * (gravity.x * b.center.x + gravity.z * b.center.z);

  std::vector<ex> generalized(J), inertia(J);
  for (int j = 0; j < J; ++j) {
    generalized[j] = j < n ? -potential.diff(s.x[j]) : ex(0);
    // Diagonal of the mass matrix from T = ½ Σ (m |ċ|² + I φ̇²).
    ex mjj = 0;
    if (j < n) {
      for (const Body& b : bodies) {
        const ex dx = b.center.x.diff(s.x[j]), dz = b.center.z.diff(s.x[j]);
        mjj += b.mass * (dx * dx + dz * dz) + b.inertia * GiNaC::pow(b.angle.diff(s.x[j]), 2);
      }
    } else {
      mjj = m.swing->inertia;
      for (const Body& b : bodies) {
        const ex radial = b.center.x + m.arm_pivot.x();
        mjj += b.mass * radial * radial;
      }
    }
    inertia[j] = mjj;
  }

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
    const ex flow_a = kv * (open_a * orifice(pp - pa) - open_b * orifice(pa - pt));
    const ex flow_b = kv * (open_b * orifice(pp - pb) - open_a * orifice(pb - pt));
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
  for (int j = 0; j < J; ++j) {
    const double friction = j < n ? m.links[j].viscous_friction : m.swing->viscous_friction;
    xdot[j] = qd[j];
    xdot[J + j] = (generalized[j] + s.u[J + j] - friction * qd[j]) / inertia[j];
  }
  s.rhs = xdot;
  for (const ex& row : s.rhs) {
    for (const auto& xi : s.x) s.jacobian.push_back(row.diff(xi));
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
