// The smooth scoop model (scoop_model.h). Instantiated for double and for the two ceres::Jet
// sizes the collocation differentiates with: one node, and one trapezoid (two nodes and the
// phase duration).
#include "runtime/optimal/scoop_model.h"

#include <ceres/jet.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "generated/registry.h"
#include "generated/templated_registry.h"
#include "runtime/plant/earthmoving.h"

namespace autoshovel::optimal {

namespace {

// Smooth positive part: ½(x + √(x² + ε²)) (≥ x⁺, within ε/2 of it).
template <typename T>
T Positive(const T& x, double epsilon) {
  using std::sqrt;
  return 0.5 * (x + sqrt(x * x + epsilon * epsilon));
}
template <typename T>
T SmoothMax(const T& a, const T& b, double epsilon) {
  return b + Positive(T(a - b), epsilon);
}
template <typename T>
T SmoothMin(const T& a, const T& b, double epsilon) {
  return a - Positive(T(a - b), epsilon);
}
// The plant's smooth sign v/√(v² + ε²).
template <typename T>
T SmoothSign(const T& v, double epsilon) {
  using std::sqrt;
  return v / sqrt(v * v + epsilon * epsilon);
}
double CylinderArea(double diameter) { return std::numbers::pi / 4 * diameter * diameter; }

}  // namespace

ScoopModel::ScoopModel(const model::MachineDescription& machine, const model::Material& material,
                       PileProfile pile, const ScoopModelOptions& options)
    : machine_name_(machine.name),
      pile_(std::move(pile)),
      travel_losses_(machine, plant::PowerLossOptions{}),
      hydraulic_losses_(machine, plant::PowerLossOptions{}),
      options_(options) {
  const std::string who = "optimal scoop: machine '" + machine.name + "': ";
  if (machine.kind != model::MachineKind::kWheelLoader) {
    throw std::invalid_argument(who + "only wheel loaders scoop (this is an excavator)");
  }
  if (machine.links.size() != kJoints || machine.hydraulics.actuators.size() != kActuators) {
    throw std::invalid_argument(who + "needs a boom and a bucket with one actuator group each");
  }
  const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
  if (functions == nullptr || generated::FindTemplatedArm<double>(machine.name) == nullptr) {
    throw std::invalid_argument(who +
                                "has no generated code compiled in (add it to models/, regen)");
  }
  num_angles_ = functions->num_angles;
  params_.assign(functions->nominal_params, functions->nominal_params + functions->num_params);
  for (int a = 0; a < kActuators; ++a) {
    const model::Actuator& act = machine.hydraulics.actuators[a];
    if (act.kind != model::ActuatorKind::kCylinder || functions->actuator_joint[a] != a) {
      throw std::invalid_argument(who + "actuator " + std::to_string(a) +
                                  " must be the cylinders of joint " + std::to_string(a));
    }
    area_cap_[a] = act.count * CylinderArea(act.bore);
    area_rod_[a] = act.count * (CylinderArea(act.bore) - CylinderArea(act.rod));
    rated_flow_[a] = act.valve.rated_flow;
    margin_[a] = act.valve.rated_pressure_drop;
    const double drive = machine.hydraulics.pump_pressure - margin_[a];
    force_max_[a] = drive * area_cap_[a];
    force_min_[a] = -drive * area_rod_[a];
    valve_delay_[a] = act.valve.pilot_delay + act.valve.transport_delay;
  }
  for (int j = 0; j < kJoints; ++j) {
    joint_min_[j] = machine.links[j].joint_min;
    joint_max_[j] = machine.links[j].joint_max;
    friction_[j] = machine.links[j].viscous_friction;
  }
  pump_max_flow_ = machine.hydraulics.pump_max_flow;

  const model::Chassis& chassis = machine.chassis;
  mass_ = chassis.operating_mass;
  wheel_radius_ = chassis.wheel_radius;
  traction_coefficient_ = chassis.traction_coefficient;
  rolling_ = chassis.rolling_resistance;
  if (machine.electric_motor) {
    const model::ElectricMotor& motor = *machine.electric_motor;
    max_traction_ = motor.max_torque * motor.gear_ratio / chassis.wheel_radius;
    drive_power_ = motor.max_power;
  } else if (machine.diesel_engine) {
    const model::DieselEngine& engine = *machine.diesel_engine;
    max_traction_ = engine.max_torque * engine.gear_ratio / chassis.wheel_radius;
    drive_power_ = engine.rated_power;
  } else {
    throw std::invalid_argument(who + "has neither an electric motor nor a diesel engine");
  }

  const model::Bucket& bucket = machine.bucket;
  if (bucket.profile.size() < 3) throw std::invalid_argument(who + "bucket profile too short");
  width_ = bucket.width;
  capacity_ = bucket.rated_capacity;
  tip_bucket_ = {bucket.profile.front().x(), bucket.profile.front().y()};
  rim_bucket_ = {bucket.profile.back().x(), bucket.profile.back().y()};
  // The opening's normal pointing out of the bucket: away from the floor behind the edge.
  const Eigen::Vector2d opening = bucket.profile.back() - bucket.profile.front();
  Eigen::Vector2d normal(opening.y(), -opening.x());
  normal.normalize();
  if (normal.dot(bucket.profile[1] - bucket.profile.front()) > 0) normal = -normal;
  normal_bucket_ = {normal.x(), normal.y()};
  floor_ = pile_.heights().front();

  density_ = material.density;
  unit_weight_ = material.density * gravity_;
  cohesion_ = material.cohesion;
  adhesion_ = options_.adhesion_fraction * material.cohesion;
  tan_phi_ = std::tan(material.friction_angle);
  k0_ = 1.0 - std::sin(material.friction_angle);  // Jaky
  delta_ = material.interface_friction_angle;
  tan_delta_ = std::tan(delta_);

  // McKyes' factors over the plant's rake-angle range (its table's 10°–90°), every degree,
  // interpolated smoothly; the fit error is measured half-way between the samples against the
  // direct search.
  const plant::ReeceTable table(material.friction_angle, material.interface_friction_angle);
  constexpr double kDeg = std::numbers::pi / 180;
  rake_min_ = 10 * kDeg;
  rake_max_ = 90 * kDeg;
  std::array<std::vector<double>, 4> samples;
  for (double a = 10; a <= 90 + 1e-9; a += 1) {
    const plant::ReeceFactors f = table.At(a * kDeg);
    samples[0].push_back(f.n_gamma);
    samples[1].push_back(f.n_c);
    samples[2].push_back(f.n_q);
    samples[3].push_back(f.n_a);
  }
  for (int c = 0; c < 4; ++c) factor_curves_[c] = SampledCurve(rake_min_, kDeg, samples[c]);
  for (double a = 10.5; a < 90; a += 1) {
    const plant::ReeceFactors f = plant::ComputeReeceFactors(a * kDeg, material.friction_angle,
                                                             material.interface_friction_angle);
    const double exact[4] = {f.n_gamma, f.n_c, f.n_q, f.n_a};
    for (int c = 0; c < 4; ++c) {
      const double scale = std::max(std::abs(exact[c]), 1.0);
      factor_fit_error_ = std::max(factor_fit_error_,
                                   std::abs(factor_curves_[c].Height(a * kDeg) - exact[c]) / scale);
    }
  }
}

template <typename T>
void ScoopModel::ArmPose(const T* q, T* pose, T* d_pose) const {
  T angles[8] = {};
  T params[8] = {};
  for (std::size_t k = 0; k < params_.size(); ++k) params[k] = T(params_[k]);
  // Inverse of Eq. (1) with θ_cab = 0: θ_k = φ_k − α_k, φ_k the sum of the joints up to k.
  T phi(0.0);
  for (int k = 0; k < kJoints; ++k) {
    phi = phi + q[k];
    angles[k + 1] = phi - params_[kJoints + k];
  }
  generated::FindTemplatedArm<T>(machine_name_)->kinematics(angles, params, pose, d_pose);
}

template <typename T>
void ScoopModel::Tip(const T* q, const T& s, T* tip_x, T* tip_z, T* bucket_angle) const {
  T pose[4];
  T d_pose[4 * 8];
  ArmPose(q, pose, d_pose);
  *tip_x = s + pose[0];
  *tip_z = pose[2];
  *bucket_angle = pose[3];
}

template <typename T>
void ScoopModel::Evaluate(const T* x, const T* u, T* xdot, T* path) const {
  EvaluateDetailed(x, u, xdot, path, static_cast<T*>(nullptr));
}

template <typename T>
void ScoopModel::SoilForces(const T& depth, const T& depth_in, const T& bx, const T& bz,
                            const T& vpx, const T& vpz, T& soil_s, T& soil_z) const {
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const double eps_d = options_.depth_smoothing;
  // Reece's equation with McKyes' factors for the cut ahead of the edge (plant.cc
  // UpdateResistance): the opening's rise is the blade, the material above it surcharge.
  const T rake_raw = atan2(bz, T(-bx));
  const T rake = SmoothMin(SmoothMax(rake_raw, T(rake_min_), 0.02), T(rake_max_), 0.02);
  const T blade_height = SmoothMax(bz, T(0.3), 0.01);
  const T cut_depth = SmoothMin(depth_in, blade_height, eps_d);
  const T surcharge = unit_weight_ * Positive(T(depth - blade_height), eps_d);
  const T n_gamma = factor_curves_[0].Height(rake);
  const T n_c = factor_curves_[1].Height(rake);
  const T n_q = factor_curves_[2].Height(rake);
  const T n_a = factor_curves_[3].Height(rake);
  const T reece =
      width_ * (unit_weight_ * cut_depth * cut_depth * n_gamma + cohesion_ * cut_depth * n_c +
                surcharge * cut_depth * n_q + adhesion_ * cut_depth * n_a);
  const T cut = reece * sin(rake + delta_);
  const T press = reece * cos(rake + delta_);
  const T column = sqrt(bx * bx + 1e-4) + 0.1;
  const T lift = 2.0 * column *
                 (0.5 * k0_ * unit_weight_ * depth_in * depth_in * tan_phi_ + cohesion_ * depth_in);
  const T withdraw = tan_delta_ * unit_weight_ * depth_in * column * width_;
  const double eps_v = options_.resistance_speed;
  const T sigma_s = SmoothSign(vpx, eps_v), sigma_z = SmoothSign(vpz, eps_v);
  const T forward = 0.5 * (1.0 + sigma_s), rising = 0.5 * (1.0 + sigma_z);
  soil_s = -sigma_s * (forward * cut + (1.0 - forward) * withdraw);
  soil_z = -sigma_z * (rising * lift + (1.0 - rising) * cut) -
           press * 0.5 * (sigma_s + sqrt(sigma_s * sigma_s + 1e-4));
}

template <typename T>
void ScoopModel::EvaluateDetailed(const T* x, const T* u, T* xdot, T* path, T* extras) const {
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const generated::TemplatedArm<T>* arm = generated::FindTemplatedArm<T>(machine_name_);
  const T& s = x[kS];
  const T& v = x[kV];
  const T q[kJoints] = {x[kQ], x[kQ + 1]};
  const T qd[kJoints] = {x[kQd], x[kQd + 1]};
  const T& volume = x[kVolume];
  const T payload = density_ * volume;

  // Kinematics and its Jacobian in the joints: ∂/∂q_j = Σ_{k ≥ j} ∂/∂θ_k (θ_k sums q up to k).
  T pose[4];
  T d_pose[4 * 8];
  ArmPose(q, pose, d_pose);
  T jx[kJoints], jz[kJoints], jphi[kJoints];
  for (int j = 0; j < kJoints; ++j) {
    jx[j] = jz[j] = jphi[j] = T(0.0);
    for (int k = j; k < kJoints; ++k) {
      jx[j] += d_pose[0 * num_angles_ + k + 1];
      jz[j] += d_pose[2 * num_angles_ + k + 1];
      jphi[j] += d_pose[3 * num_angles_ + k + 1];
    }
  }
  const T px = s + pose[0], pz = pose[2], bucket_angle = pose[3];
  T vpx = v, vpz(0.0), omega(0.0);
  for (int j = 0; j < kJoints; ++j) {
    vpx += jx[j] * qd[j];
    vpz += jz[j] * qd[j];
    omega += jphi[j] * qd[j];
  }
  const T c = cos(bucket_angle), sn = sin(bucket_angle);
  const double ex = rim_bucket_[0] - tip_bucket_[0], ez = rim_bucket_[1] - tip_bucket_[1];
  const T bx = c * ex - sn * ez, bz = sn * ex + c * ez;  // opening, edge P to rim R
  const T nx = c * normal_bucket_[0] - sn * normal_bucket_[1];
  const T nz = sn * normal_bucket_[0] + c * normal_bucket_[1];

  // Depths below the free surface.
  const T depth = DepthBelowSurface(px, pz);
  const T rim_depth = DepthBelowSurface(T(px + bx), T(pz + bz));
  const double eps_d = options_.depth_smoothing;
  const T depth_in = Positive(depth, eps_d);
  const T rim_out = Positive(T(-rim_depth), eps_d);

  // Intake: the submerged part of the opening sweeping into the soil.
  const T submerged = depth_in / (depth_in + rim_out + 1e-6);
  const T half = 0.5 * submerged;
  const T vmx = vpx - omega * half * bz, vmz = vpz + omega * half * bx;
  const T opening_length = sqrt(bx * bx + bz * bz);
  const T gap = capacity_ - volume;
  const double closing = options_.fill_closing * capacity_;
  const T open_fraction =
      Positive(gap, 1e-3 * capacity_) / (Positive(gap, 1e-3 * capacity_) + closing);
  const T intake =
      width_ * submerged * opening_length * Positive(T(vmx * nx + vmz * nz), 0.02) * open_fraction;

  T soil_s, soil_z;
  SoilForces(depth, depth_in, bx, bz, vpx, vpz, soil_s, soil_z);

  // The arm by inverse dynamics: the joint accelerations are the controls, the cylinder forces
  // follow from M q̈ + bias + b q̇ − J_tipᵀ F = Gᵀ f, G the cylinders' length gradients.
  T mass[kJoints * kJoints], bias[kJoints];
  arm->dynamics(q, qd, payload, T(0.0), mass, bias);
  const T qdd[kJoints] = {u[1], u[2]};
  T torque[kJoints];
  for (int j = 0; j < kJoints; ++j) {
    torque[j] = bias[j] + friction_[j] * qd[j] - jx[j] * soil_s - jz[j] * soil_z;
    for (int k = 0; k < kJoints; ++k) torque[j] += mass[j * kJoints + k] * qdd[k];
  }
  T gradient[kActuators][kJoints], rate[kActuators];
  for (int a = 0; a < kActuators; ++a) {
    T length;
    arm->cylinder(a, q, &length, gradient[a]);
    rate[a] = T(0.0);
    for (int j = 0; j < kJoints; ++j) rate[a] += gradient[a][j] * qd[j];
  }
  // Gᵀ f = τ: column a of Gᵀ is actuator a's gradient.
  const T det = gradient[0][0] * gradient[1][1] - gradient[1][0] * gradient[0][1];
  const T force[kActuators] = {(gradient[1][1] * torque[0] - gradient[1][0] * torque[1]) / det,
                               (gradient[0][0] * torque[1] - gradient[0][1] * torque[0]) / det};

  // The drive.
  const T total_mass = mass_ + payload;
  const T normal = total_mass * gravity_ - soil_z;
  const T rolling = rolling_ * normal * SmoothSign(v, 0.05);
  const T traction = u[0];

  // Energy: the travel motor's and the pump's draw.
  const double eps_f = options_.flow_smoothing;
  T flow[kActuators], pressure[kActuators];
  T total_flow(0.0);
  for (int a = 0; a < kActuators; ++a) {
    const T extend = Positive(rate[a], eps_f), retract = Positive(T(-rate[a]), eps_f);
    const T push = Positive(force[a], 1e4), pull = Positive(T(-force[a]), 1e4);
    flow[a] = area_cap_[a] * extend + area_rod_[a] * retract;
    pressure[a] = (push * extend + pull * retract) / (flow[a] + 1e-9);
    total_flow += flow[a];
  }
  // The pump at the highest need among the moving sections (a smooth maximum of each
  // section's p + Δp weighted by how much it moves).
  T pump_pressure(0.0);
  for (int a = 0; a < kActuators; ++a) {
    const T active = flow[a] / (flow[a] + 2e-4);  // half at 12 l/min
    pump_pressure = SmoothMax(pump_pressure, T(active * (pressure[a] + margin_[a])), 1e5);
  }
  const T hydraulic = hydraulic_losses_.Drawn(pump_pressure, total_flow);
  const T travel = travel_losses_.Evaluate(T(traction * wheel_radius_), T(v / wheel_radius_)).drawn;

  xdot[kS] = v;
  xdot[kV] = (traction - rolling + soil_s) / total_mass;
  xdot[kQ] = qd[0];
  xdot[kQ + 1] = qd[1];
  xdot[kQd] = qdd[0];
  xdot[kQd + 1] = qdd[1];
  xdot[kVolume] = intake;
  xdot[kEnergy] = travel + hydraulic;

  path[kTractionForward] = traction_coefficient_ * normal - traction;
  path[kTractionBackward] = traction_coefficient_ * normal + traction;
  path[kDrivePower] = drive_power_ - traction * v;
  for (int a = 0; a < kActuators; ++a) {
    path[kFlowExtend + a] = rated_flow_[a] - area_cap_[a] * rate[a];
    path[kFlowRetract + a] = rated_flow_[a] + area_rod_[a] * rate[a];
    path[kForceBelowMax + a] = force_max_[a] - force[a];
    path[kForceAboveMin + a] = force[a] - force_min_[a];
  }
  path[kPumpFlow] = pump_max_flow_ > 0 ? T(pump_max_flow_ - total_flow) : T(1.0);
  path[kTipAboveFloor] = pz - floor_;
  if (extras != nullptr) {
    extras[0] = px, extras[1] = pz, extras[2] = depth, extras[3] = rim_depth;
    extras[4] = bucket_angle, extras[5] = travel, extras[6] = hydraulic;
    extras[7] = soil_s, extras[8] = soil_z, extras[9] = intake;
    extras[10] = force[0], extras[11] = force[1];
  }
}

ScoopModelProbe ScoopModel::Probe(const double* x, const double* u) const {
  double xdot[kStates], path[kNumPath], extras[12];
  EvaluateDetailed(x, u, xdot, path, extras);
  ScoopModelProbe probe;
  probe.tip_x = extras[0], probe.tip_z = extras[1], probe.depth = extras[2];
  probe.rim_depth = extras[3], probe.bucket_angle = extras[4];
  probe.travel_power = extras[5], probe.hydraulic_power = extras[6];
  probe.soil_force_s = extras[7], probe.soil_force_z = extras[8], probe.intake = extras[9];
  probe.cylinder_force = {extras[10], extras[11]};
  return probe;
}

namespace {
template <int N>
using Jet1 = ceres::Jet<double, N>;
}  // namespace

#define AUTOSHOVEL_INSTANTIATE_EVALUATE(T)                                 \
  template void ScoopModel::Evaluate<T>(const T*, const T*, T*, T*) const; \
  template void ScoopModel::Tip<T>(const T*, const T&, T*, T*, T*) const;
AUTOSHOVEL_INSTANTIATE_EVALUATE(double)
AUTOSHOVEL_INSTANTIATE_EVALUATE(Jet1<kNodeVariables>)
AUTOSHOVEL_INSTANTIATE_EVALUATE(Jet1<2 * kNodeVariables + 1>)
#undef AUTOSHOVEL_INSTANTIATE_EVALUATE

}  // namespace autoshovel::optimal
