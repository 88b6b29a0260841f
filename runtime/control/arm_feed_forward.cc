// Attitude-holding feed-forward from the boom valve's demand; see arm_feed_forward.h.
#include "runtime/control/arm_feed_forward.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace autoshovel::control {
namespace {

double ValveLag(const model::Valve& valve) {
  return valve.transport_delay + valve.spool_time_constant;
}

// Flow at full spool [m³/s]: K_v·√Δp with Δp the load-sensing margin, the largest rated drop of
// the machine's valves (the drop at which a valve is rated is the margin it is sized for).
double FullOpeningFlow(const model::MachineDescription& machine, const model::Valve& valve) {
  double margin = 0;
  for (const model::Actuator& act : machine.hydraulics.actuators) {
    margin = std::max(margin, act.valve.rated_pressure_drop);
  }
  if (!(valve.rated_pressure_drop > 0) || !(margin > 0)) return valve.rated_flow;
  return valve.rated_flow * std::sqrt(margin / valve.rated_pressure_drop);
}

}  // namespace

AttitudeHoldFeedForward::AttitudeHoldFeedForward(const model::MachineDescription& machine,
                                                 const generated::MachineFunctions& functions)
    : functions_(functions) {
  if (machine.links.size() != 2 || functions.num_joints != 2) {
    throw std::invalid_argument("attitude feed-forward: machine '" + machine.name +
                                "' is not a two-link loader arm");
  }
  for (int joint : {0, 1}) {
    const int a = machine.ActuatorOfJoint(joint);
    if (a < 0) {
      throw std::invalid_argument("attitude feed-forward: machine '" + machine.name +
                                  "' has no actuator on the boom or bucket joint");
    }
    const model::Actuator& act = machine.hydraulics.actuators[a];
    if (act.kind != model::ActuatorKind::kCylinder || !(act.bore > act.rod) || !(act.rod >= 0) ||
        !(act.valve.rated_flow > 0) || act.count < 1) {
      throw std::invalid_argument("attitude feed-forward: actuator '" + act.name +
                                  "' needs a cylinder with bore > rod and a positive rated flow");
    }
    Cylinder& cylinder = joint == 0 ? boom_ : bucket_;
    cylinder.actuator = a;
    cylinder.cap_area = act.count * std::numbers::pi / 4 * act.bore * act.bore;
    cylinder.rod_area =
        act.count * std::numbers::pi / 4 * (act.bore * act.bore - act.rod * act.rod);
    cylinder.full_flow = FullOpeningFlow(machine, act.valve);
    cylinder.dead_zone = act.valve.dead_zone;
  }
  boom_lag_ = std::max(0.0, ValveLag(machine.hydraulics.actuators[boom_.actuator].valve) -
                                ValveLag(machine.hydraulics.actuators[bucket_.actuator].valve));
}

const AttitudeHoldFeedForward::Cylinder& AttitudeHoldFeedForward::CylinderOf(int joint) const {
  if (joint != 0 && joint != 1) throw std::out_of_range("attitude feed-forward: joint 0 or 1");
  return joint == 0 ? boom_ : bucket_;
}

double AttitudeHoldFeedForward::LengthGradient(int actuator, int joint,
                                               const std::vector<double>& q) const {
  // Central difference of the generated closed-form length: 1e-6 rad keeps the truncation
  // error (~h²·L''') and the rounding error (~ε·L/h) both near 1e-10 m/rad.
  constexpr double kStep = 1e-6;
  std::vector<double> plus = q, minus = q;
  plus[joint] += kStep;
  minus[joint] -= kStep;
  return (functions_.cylinder_length(actuator, plus.data()) -
          functions_.cylinder_length(actuator, minus.data())) /
         (2 * kStep);
}

double AttitudeHoldFeedForward::LengthRateOfOpening(const Cylinder& cylinder, double opening) {
  const double x = std::clamp(opening, -1.0, 1.0);
  return x * cylinder.full_flow / (x >= 0 ? cylinder.cap_area : cylinder.rod_area);
}

double AttitudeHoldFeedForward::OpeningOfLengthRate(const Cylinder& cylinder, double length_rate) {
  const double area = length_rate >= 0 ? cylinder.cap_area : cylinder.rod_area;
  return std::clamp(length_rate * area / cylinder.full_flow, -1.0, 1.0);
}

double AttitudeHoldFeedForward::JointRate(int joint, double demand,
                                          const std::vector<double>& q) const {
  const Cylinder& cylinder = CylinderOf(joint);
  const double gradient = LengthGradient(cylinder.actuator, joint, q);
  if (!std::isfinite(gradient) || std::abs(gradient) < 1e-6) return 0.0;
  return LengthRateOfOpening(cylinder, demand) / gradient;
}

double AttitudeHoldFeedForward::JointTravel(int joint, const std::deque<double>& openings,
                                            const std::vector<double>& q, double dt) const {
  const Cylinder& cylinder = CylinderOf(joint);
  const double gradient = LengthGradient(cylinder.actuator, joint, q);
  if (!std::isfinite(gradient) || std::abs(gradient) < 1e-6) return 0.0;
  double length = 0;
  for (double opening : openings) length += LengthRateOfOpening(cylinder, opening) * dt;
  return length / gradient;
}

double AttitudeHoldFeedForward::PassiveBucketPerBoom(const std::vector<double>& q) const {
  const double own = LengthGradient(bucket_.actuator, 1, q);
  if (!std::isfinite(own) || std::abs(own) < 1e-6) return 0.0;
  return -LengthGradient(bucket_.actuator, 0, q) / own;
}

double AttitudeHoldFeedForward::OpeningOfDuty(int joint, double duty) const {
  const double dead_zone = CylinderOf(joint).dead_zone;
  if (!std::isfinite(duty)) return 0.0;
  const double magnitude = std::min(std::abs(duty), 1.0);
  if (magnitude <= dead_zone) return 0.0;
  return std::copysign((magnitude - dead_zone) / (1 - dead_zone), duty);
}

double AttitudeHoldFeedForward::BucketDemand(double boom_demand,
                                             const std::vector<double>& q) const {
  if (!std::isfinite(boom_demand) || q.size() != 2 || !std::isfinite(q[0]) ||
      !std::isfinite(q[1])) {
    return 0.0;
  }
  const double boom_rate = JointRate(0, boom_demand, q);
  // Constant attitude: q̇_bucket = −q̇_boom; the tilt cylinder's length moves with both joints.
  const double length_rate = LengthGradient(bucket_.actuator, 0, q) * boom_rate +
                             LengthGradient(bucket_.actuator, 1, q) * -boom_rate;
  if (!std::isfinite(length_rate)) return 0.0;
  return OpeningOfLengthRate(bucket_, length_rate);
}

}  // namespace autoshovel::control
