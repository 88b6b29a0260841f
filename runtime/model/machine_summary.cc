#include "runtime/model/machine_summary.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "runtime/model/interpreted_model.h"
#include "runtime/model/spec_sheet.h"

namespace autoshovel::model {
namespace {

constexpr int kGrid = 121;  // samples per joint for workspace sweeps
constexpr int kMapColumns = 64, kMapRows = 20;

double Lerp(double a, double b, double t) { return a + (b - a) * t; }

// A loader's cylinder that slides a window over its joint with the boom (see ActuatorSummary):
// stroke use, levers and margins over what it reaches, the windows at the boom's limits and at
// carry, and how far its ends let the joint pass the joint's limits.
void SummarizeSlidingWindow(const MachineDescription& m, const InterpretedModel& model,
                            int actuator, int joint, const std::vector<double>& carry,
                            ActuatorSummary& summary) {
  constexpr int kBoomSamples = 41;
  constexpr double kSearch = std::numbers::pi / 2;  // how far past the limits overruns are sought
  const Link& link = m.links[joint];
  const Link& boom = m.links[0];
  summary.moves_with_earlier_joints = true;
  summary.lever_min = 1e300;
  summary.lever_max = 0;
  double shortest = 1e300, longest = -1e300;
  std::vector<double> q = carry;
  for (int i = 0; i < kBoomSamples; ++i) {
    q[0] = Lerp(boom.joint_min, boom.joint_max, double(i) / (kBoomSamples - 1));
    const JointWindow wide = ReachableJointWindow(m, joint, q.data(), kSearch);
    if (wide.empty) continue;
    summary.overrun_below_min = std::max(summary.overrun_below_min, link.joint_min - wide.min);
    summary.overrun_above_max = std::max(summary.overrun_above_max, wide.max - link.joint_max);
    const double low = std::max(wide.min, link.joint_min),
                 high = std::min(wide.max, link.joint_max);
    for (int k = 0; k < kGrid && low <= high; ++k) {
      q[joint] = Lerp(low, high, double(k) / (kGrid - 1));
      const double length = model.CylinderLength(actuator, q.data());
      shortest = std::min(shortest, length);
      longest = std::max(longest, length);
      const double lever = std::abs(model.LeverArms(actuator, q.data())[joint]);
      summary.lever_min = std::min(summary.lever_min, lever);
      summary.lever_max = std::max(summary.lever_max, lever);
    }
  }
  if (longest < shortest) {  // reaches nothing within the limits (the validator refuses that)
    summary.lever_min = 0;
    return;
  }
  summary.length_at_joint_min = shortest;
  summary.length_at_joint_max = longest;
  summary.stroke_used = longest - shortest;
  const auto window = [&](double boom_angle, double& low, double& high) {
    std::vector<double> at = carry;
    at[0] = boom_angle;
    const JointWindow w = ReachableJointWindow(m, joint, at.data());
    low = w.empty ? 0 : w.min;
    high = w.empty ? 0 : w.max;
  };
  window(carry[0], summary.window_carry_min, summary.window_carry_max);
  window(boom.joint_max, summary.window_top_min, summary.window_top_max);
  window(boom.joint_min, summary.window_bottom_min, summary.window_bottom_max);
}

// Dump pose (SAE J732, ISO 7131) of a loader: the clearance and reach at 45°, or why not.
void SummarizeDumpPose(const MachineDescription& m, const InterpretedModel& model,
                       MachineSummary& s) {
  // The boom at its upper limit, the bucket's discharge angle 45°,
  // the angle of the floor (the longest flat section of the inside bottom: the profile's edge
  // from the cutting edge, its first point, to the second) below horizontal. The floor runs
  // from the heel up to the tip at angle β above the pin-to-tip line in the bucket frame, so
  // the bucket frame is at φ₂ = −45° − β and the cutting edge is the bucket's lowest point.
  const Eigen::Vector2d floor = m.bucket.profile[0] - m.bucket.profile[1];
  s.dump_floor_to_edge_line = std::atan2(floor.y(), floor.x()) -
                              std::atan2(m.bucket.profile[0].y(), m.bucket.profile[0].x());
  const double phi2 = -std::numbers::pi / 4 - std::atan2(floor.y(), floor.x());
  std::vector<double> dump_q = {m.links[0].joint_max, phi2 - m.links[0].joint_max};
  double deepest = m.links[1].joint_min, shallowest = m.links[1].joint_max;
  if (CylinderMovesWithEarlierJoints(m, 1)) {
    const JointWindow w = ReachableJointWindow(m, 1, dump_q.data());
    deepest = w.empty ? shallowest : std::max(deepest, w.min);
    shallowest = w.empty ? deepest : std::min(shallowest, w.max);
  }
  s.dump_floor_at_limit = m.links[0].joint_max + deepest + std::atan2(floor.y(), floor.x());
  const bool reachable = dump_q[1] >= deepest - 1e-9 && dump_q[1] <= shallowest + 1e-9;
  if (reachable) {
    s.dump_pose_reachable = true;
    s.dump_pose = dump_q;
    const Eigen::Vector4d pose = model.TipFromJoints(dump_q.data());
    s.dump_clearance = pose[2];
    // Reach is measured from the foremost point of the machine without its bucket; of the
    // machine, a description knows the tyres: the front of the front tyres.
    const double tyre_front = m.chassis.hinge_to_front_axle + m.chassis.wheel_radius;
    s.dump_reach = pose[0] - tyre_front;
  }
}

}  // namespace

MachineSummary Summarize(const MachineDescription& m) {
  const InterpretedModel model(m);
  const int n = model.sizes().num_links, J = model.sizes().num_joints;
  MachineSummary s;
  s.tip_x_min = s.tip_z_min = 1e300;
  s.tip_x_max = s.tip_z_max = s.max_hinge_pin_height = -1e300;
  s.dig_depth = 0;

  // Sweep the planar joints (swing held at 0). For 3 links, a coarser grid keeps it fast.
  const int per_joint = n == 2 ? kGrid : 41;
  std::vector<Eigen::Vector2d> tips;
  std::vector<double> q(J, 0.0);
  std::vector<int> index(n, 0);
  while (true) {
    for (int k = 0; k < n; ++k) {
      q[k] = Lerp(m.links[k].joint_min, m.links[k].joint_max, double(index[k]) / (per_joint - 1));
    }
    const Eigen::Vector4d pose = model.TipFromJoints(q.data());
    tips.emplace_back(pose[0], pose[2]);
    double phi = 0, pin_x = 0, pin_z = 0;
    for (int k = 0; k < n - 1; ++k) {
      phi += q[k];
      pin_x += m.links[k].length * std::cos(phi);
      pin_z += m.links[k].length * std::sin(phi);
    }
    (void)pin_x;
    s.max_hinge_pin_height = std::max(s.max_hinge_pin_height, pin_z + m.arm_pivot.y());
    int k = 0;
    while (k < n && ++index[k] == per_joint) index[k++] = 0;
    if (k == n) break;
  }
  for (const auto& tip : tips) {
    s.tip_x_min = std::min(s.tip_x_min, tip.x());
    s.tip_x_max = std::max(s.tip_x_max, tip.x());
    s.tip_z_min = std::min(s.tip_z_min, tip.y());
    s.tip_z_max = std::max(s.tip_z_max, tip.y());
    s.max_reach = std::max(s.max_reach, tip.x());
    if (std::abs(tip.y()) < 0.05) s.max_reach_at_ground = std::max(s.max_reach_at_ground, tip.x());
  }
  s.max_tip_height = s.tip_z_max;
  s.dig_depth = std::max(0.0, -s.tip_z_min);

  s.workspace_map.assign(kMapRows, std::string(kMapColumns, ' '));
  for (const auto& tip : tips) {
    const int column =
        std::clamp(int((tip.x() - s.tip_x_min) / (s.tip_x_max - s.tip_x_min + 1e-9) * kMapColumns),
                   0, kMapColumns - 1);
    const int row =
        std::clamp(int((s.tip_z_max - tip.y()) / (s.tip_z_max - s.tip_z_min + 1e-9) * kMapRows), 0,
                   kMapRows - 1);
    s.workspace_map[row][column] = '#';
  }
  // Mark ground level where it crosses the map.
  if (s.tip_z_min < 0 && s.tip_z_max > 0) {
    const int row =
        std::clamp(int(s.tip_z_max / (s.tip_z_max - s.tip_z_min) * kMapRows), 0, kMapRows - 1);
    for (char& cell : s.workspace_map[row]) {
      if (cell == ' ') cell = '-';
    }
  }

  // Carry pose: loaders carry low with the bucket racked back; excavators are summarised in
  // the middle of every joint range.
  s.carry_pose = CarryPose(m);
  if (m.kind == MachineKind::kWheelLoader) {
    s.carry_pose_definition =
        "boom at 20% of its range from the bottom, bucket racked back fully (as far as its "
        "cylinder reaches there)";
    SummarizeDumpPose(m, model, s);
  } else {
    s.carry_pose_definition = "every joint in the middle of its range";
  }

  for (std::size_t i = 0; i < m.hydraulics.actuators.size(); ++i) {
    const Actuator& a = m.hydraulics.actuators[i];
    ActuatorSummary summary;
    summary.name = a.name;
    summary.joint = a.joint;
    summary.is_motor = a.kind == ActuatorKind::kMotor;
    summary.transport_delay = a.valve.transport_delay;
    summary.spool_time_constant = a.valve.spool_time_constant;
    const int actuator = static_cast<int>(i);
    if (!summary.is_motor) {
      const int joint = m.LinkIndex(a.joint);
      summary.retracted_length = a.retracted_length;
      summary.stroke = a.stroke;
      if (m.kind == MachineKind::kWheelLoader && joint > 0 &&
          CylinderMovesWithEarlierJoints(m, joint)) {
        SummarizeSlidingWindow(m, model, actuator, joint, s.carry_pose, summary);
      } else {
        std::vector<double> qs = s.carry_pose;
        qs[joint] = m.links[joint].joint_min;
        summary.length_at_joint_min = model.CylinderLength(actuator, qs.data());
        qs[joint] = m.links[joint].joint_max;
        summary.length_at_joint_max = model.CylinderLength(actuator, qs.data());
        summary.stroke_used = std::abs(summary.length_at_joint_max - summary.length_at_joint_min);
        summary.lever_min = 1e300;
        for (int k = 0; k < kGrid; ++k) {
          qs[joint] =
              Lerp(m.links[joint].joint_min, m.links[joint].joint_max, double(k) / (kGrid - 1));
          const double lever = std::abs(model.LeverArms(actuator, qs.data())[joint]);
          summary.lever_min = std::min(summary.lever_min, lever);
          summary.lever_max = std::max(summary.lever_max, lever);
        }
      }
      summary.lever_at_carry = model.LeverArms(actuator, s.carry_pose.data())[joint];
      const double piston_area = a.count * std::numbers::pi / 4 * a.bore * a.bore;
      summary.torque_at_relief = a.relief_pressure * piston_area * summary.lever_at_carry;
    }
    s.actuators.push_back(summary);
  }

  // Lift capacity at carry: boom torque at relief pressure against the gravity torque of the
  // links plus a payload at the bucket's payload centre (linear in the payload mass).
  {
    const ActuatorSummary& boom = s.actuators[m.ActuatorOfJoint(0)];
    const double links_torque = model.GravityTorques(s.carry_pose.data(), 0.0, 0.0)[0];
    const double per_kg = links_torque - model.GravityTorques(s.carry_pose.data(), 1.0, 0.0)[0];
    if (per_kg > 0 && boom.torque_at_relief > 0) {
      s.lift_capacity_at_carry = std::max(0.0, (boom.torque_at_relief + links_torque) / per_kg);
    }
  }

  s.struck_volume = BucketProfileArea(m) * m.bucket.width;
  if (const Material* material = m.FindMaterial(m.bucket.design_material)) {
    s.payload_at_rated_capacity = m.bucket.rated_capacity * material->density;
  }
  return s;
}

}  // namespace autoshovel::model
