#include "runtime/control/excavator/joint_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "runtime/model/interpreted_model.h"

namespace autoshovel::control {
namespace {

void RequirePositive(double value, const std::string& joint, const char* field) {
  if (!(std::isfinite(value) && value > 0)) {
    throw std::invalid_argument("joint model of " + joint + ": " + field +
                                " must be finite and positive, got " + std::to_string(value));
  }
}

}  // namespace

void Validate(const JointModelParams& params, const std::string& joint_name) {
  if (!(std::isfinite(params.latency) && params.latency >= 0)) {
    throw std::invalid_argument("joint model of " + joint_name +
                                ": latency must be finite and >= 0, got " +
                                std::to_string(params.latency));
  }
  RequirePositive(params.max_velocity_up, joint_name, "max_velocity_up");
  RequirePositive(params.max_velocity_down, joint_name, "max_velocity_down");
  RequirePositive(params.max_acceleration, joint_name, "max_acceleration");
  RequirePositive(params.time_constant, joint_name, "time_constant");
  if (std::isnan(params.position_min) || std::isnan(params.position_max) ||
      !(params.position_min < params.position_max)) {
    throw std::invalid_argument("joint model of " + joint_name +
                                ": position_min must be below position_max");
  }
}

void Validate(const ExcavatorJointModels& models) {
  for (ExcavatorJoint joint : kAllExcavatorJoints) {
    Validate(models[JointIndex(joint)], std::string(JointName(joint)));
  }
}

JointMotion StepJoint(const JointModelParams& params, const JointMotion& motion, double target,
                      bool stop, double dt) {
  const double a = params.max_acceleration;
  double wanted = 0;
  if (!stop) {
    const double error = target - motion.position;
    // Brake so as to arrive: v² = 2 a |e| is the rate from which braking at a ends at the target;
    // the step's own travel is taken off so that the discrete braking does not overshoot.
    const double braking_room =
        std::max(std::abs(error) - 0.5 * std::abs(motion.velocity) * dt, 0.0);
    const double speed =
        std::min(std::abs(error) / params.time_constant, std::sqrt(2.0 * a * braking_room));
    wanted =
        std::clamp(std::copysign(speed, error), -params.max_velocity_down, params.max_velocity_up);
  }
  JointMotion next;
  next.velocity = motion.velocity + std::clamp(wanted - motion.velocity, -a * dt, a * dt);
  next.position = motion.position + 0.5 * (motion.velocity + next.velocity) * dt;
  if (next.position > params.position_max) {
    next.position = params.position_max;
    next.velocity = std::min(next.velocity, 0.0);
  } else if (next.position < params.position_min) {
    next.position = params.position_min;
    next.velocity = std::max(next.velocity, 0.0);
  }
  return next;
}

namespace {

template <typename Visit>
void RunFromRest(const JointModelParams& params, double from, double to, double dt, double max_time,
                 Visit visit) {
  JointMotion motion{from, 0.0};
  double t = 0;
  while (t < max_time) {
    if (t + 1e-12 >= params.latency) motion = StepJoint(params, motion, to, false, dt);
    t += dt;
    if (!visit(t, motion)) return;
  }
}

}  // namespace

double TimeToReach(const JointModelParams& params, double from, double to, double tolerance,
                   double dt) {
  if (!(dt > 0) || !(tolerance > 0)) {
    throw std::invalid_argument("TimeToReach: dt and tolerance must be positive");
  }
  if (std::abs(to - from) <= tolerance) return 0.0;
  constexpr double kMaxTime = 60.0;
  double reached = -1;
  RunFromRest(params, from, to, dt, kMaxTime, [&](double t, const JointMotion& m) {
    if (std::abs(m.position - to) <= tolerance) {
      reached = t;
      return false;
    }
    return true;
  });
  if (reached < 0) {
    throw std::invalid_argument("joint model never reaches " + std::to_string(to) + " rad from " +
                                std::to_string(from) + " rad (joint limit in the way?)");
  }
  return reached;
}

double PositionAfter(const JointModelParams& params, double from, double to, double elapsed,
                     double dt) {
  double position = from;
  RunFromRest(params, from, to, dt, elapsed - 0.5 * dt, [&](double, const JointMotion& m) {
    position = m.position;
    return true;
  });
  return position;
}

double StoppingDistance(const JointModelParams& params, double speed) {
  const double v = std::abs(speed);
  return v * params.latency + v * v / (2.0 * params.max_acceleration);
}

double StoppingTime(const JointModelParams& params, double speed) {
  return params.latency + std::abs(speed) / params.max_acceleration;
}

JointVector DefaultReferencePose() {
  constexpr double kDeg = std::numbers::pi / 180.0;
  return JointVector(30 * kDeg, -90 * kDeg, -120 * kDeg, 0.0);
}

ExcavatorModelDerivation DeriveJointModels(const model::MachineDescription& machine,
                                           const generated::MachineFunctions& functions,
                                           const JointVector& reference_pose, double payload) {
  if (machine.kind != model::MachineKind::kExcavator || !machine.swing ||
      machine.links.size() != 3 || machine.links[0].name != "boom" ||
      machine.links[1].name != "stick" || machine.links[2].name != "bucket") {
    throw std::invalid_argument("DeriveJointModels: " + machine.name +
                                " is not an excavator with links boom, stick, bucket and a swing");
  }
  if (functions.num_joints != kNumExcavatorJoints || functions.lever_arm == nullptr) {
    throw std::invalid_argument("DeriveJointModels: generated code of " +
                                std::string(functions.name) + " does not have 4 joints");
  }
  if (FirstNonFinite(reference_pose) >= 0 || !(std::isfinite(payload) && payload >= 0)) {
    throw std::invalid_argument("DeriveJointModels: reference pose and payload must be finite");
  }
  const int J = kNumExcavatorJoints;
  const model::InterpretedModel model(machine);
  const model::ModelSizes sizes = model.sizes();

  // Inertia about each joint as the plant sees it: the acceleration a unit external torque adds
  // to the plant's right-hand side at rest (the same probe as InterpretedModel::GravityTorques).
  std::vector<double> x(sizes.num_states, 0.0), u(sizes.num_inputs, 0.0);
  for (int j = 0; j < J; ++j) x[j] = reference_pose[j];
  u[2 * J] = payload;
  for (int j = 0; j < J; ++j) u[2 * J + 2 + j] = machine.hydraulics.pump_pressure;
  std::vector<double> rest(sizes.num_states), probe(sizes.num_states);
  model.PlantRhs(x.data(), u.data(), rest.data());
  const std::vector<double> gravity = model.GravityTorques(reference_pose.data(), payload, 0.0);

  ExcavatorModelDerivation out;
  out.reference_pose = reference_pose;
  out.payload = payload;
  for (int j = 0; j < J; ++j) {
    const ExcavatorJoint joint = kAllExcavatorJoints[j];
    const std::string name(JointName(joint));
    u[J + j] = 1.0;
    model.PlantRhs(x.data(), u.data(), probe.data());
    u[J + j] = 0.0;
    const double inverse_inertia = probe[J + j] - rest[J + j];
    const int actuator = machine.ActuatorOfJoint(static_cast<std::size_t>(j));
    if (actuator < 0 || !(inverse_inertia > 0)) {
      throw std::invalid_argument("DeriveJointModels: no actuator or inertia for joint " + name);
    }
    const model::Actuator& act = machine.hydraulics.actuators[actuator];
    const model::Valve& valve = act.valve;
    const double relief_dp = act.relief_pressure - machine.hydraulics.tank_pressure;

    JointModelDerivation d;
    d.joint = name;
    d.rated_flow = valve.rated_flow;
    d.inertia = 1.0 / inverse_inertia;
    d.gravity_torque = std::abs(gravity[j]);
    JointModelParams& p = d.params;
    p.latency = valve.transport_delay + valve.spool_time_constant;
    p.time_constant = 2.0 * p.latency;
    if (act.kind == model::ActuatorKind::kMotor) {
      d.lever = 1.0;
      d.area_up = d.area_down = act.displacement;
      d.drive_torque = relief_dp * act.displacement;
      p.max_velocity_up = p.max_velocity_down = valve.rated_flow / act.displacement;
      p.max_acceleration = d.drive_torque / d.inertia;
    } else {
      d.lever = functions.lever_arm(actuator, reference_pose.data());
      const double cap = act.count * std::numbers::pi / 4.0 * act.bore * act.bore;
      const double annulus =
          act.count * std::numbers::pi / 4.0 * (act.bore * act.bore - act.rod * act.rod);
      // A positive dL/dq extends the cylinder as the angle grows: the cap side is fed.
      d.area_up = d.lever > 0 ? cap : annulus;
      d.area_down = d.lever > 0 ? annulus : cap;
      const double lever = std::abs(d.lever);
      p.max_velocity_up = valve.rated_flow / (d.area_up * lever);
      p.max_velocity_down = valve.rated_flow / (d.area_down * lever);
      d.drive_torque = relief_dp * annulus * lever;
      const double torque_limited = (d.drive_torque - d.gravity_torque) / d.inertia;
      const double spool_limited =
          std::min(p.max_velocity_up, p.max_velocity_down) / valve.spool_time_constant;
      p.max_acceleration = std::min(torque_limited, spool_limited);
      const model::Link& link = machine.links[j];
      p.position_min = link.joint_min;
      p.position_max = link.joint_max;
    }
    Validate(p, name);
    out.models[j] = p;
    out.joints[j] = d;
  }
  return out;
}

}  // namespace autoshovel::control
