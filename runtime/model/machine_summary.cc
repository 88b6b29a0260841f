#include "runtime/model/machine_summary.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "runtime/model/interpreted_model.h"

namespace autoshovel::model {
namespace {

constexpr int kGrid = 121;  // samples per joint for workspace sweeps
constexpr int kMapColumns = 64, kMapRows = 20;

double Lerp(double a, double b, double t) { return a + (b - a) * t; }

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
  s.carry_pose.assign(J, 0.0);
  if (m.kind == MachineKind::kWheelLoader) {
    s.carry_pose[0] = Lerp(m.links[0].joint_min, m.links[0].joint_max, 0.2);
    s.carry_pose[1] = m.links[1].joint_max;
    s.carry_pose_definition = "boom at 20% of its range from the bottom, bucket racked back fully";
    // Dump pose: boom at the top, bucket 45° below horizontal.
    const double q2 = -std::numbers::pi / 4 - m.links[0].joint_max;
    if (q2 >= m.links[1].joint_min && q2 <= m.links[1].joint_max) {
      s.dump_pose_reachable = true;
      const double dump_q[2] = {m.links[0].joint_max, q2};
      const Eigen::Vector4d pose = model.TipFromJoints(dump_q);
      s.dump_clearance = pose[2];
      const double tyre_front = m.chassis.hinge_to_front_axle + m.chassis.wheel_radius;
      s.dump_reach = pose[0] - tyre_front;
    }
  } else {
    for (int k = 0; k < n; ++k)
      s.carry_pose[k] = Lerp(m.links[k].joint_min, m.links[k].joint_max, 0.5);
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
      std::vector<double> qs = s.carry_pose;
      qs[joint] = m.links[joint].joint_min;
      summary.length_at_joint_min = model.CylinderLength(actuator, qs.data());
      qs[joint] = m.links[joint].joint_max;
      summary.length_at_joint_max = model.CylinderLength(actuator, qs.data());
      summary.retracted_length = a.retracted_length;
      summary.stroke = a.stroke;
      summary.stroke_used = std::abs(summary.length_at_joint_max - summary.length_at_joint_min);
      summary.lever_min = 1e300;
      for (int k = 0; k < kGrid; ++k) {
        qs[joint] =
            Lerp(m.links[joint].joint_min, m.links[joint].joint_max, double(k) / (kGrid - 1));
        const double lever = std::abs(model.LeverArms(actuator, qs.data())[joint]);
        summary.lever_min = std::min(summary.lever_min, lever);
        summary.lever_max = std::max(summary.lever_max, lever);
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
