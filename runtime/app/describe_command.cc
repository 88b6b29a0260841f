#include "runtime/app/describe_command.h"

#include <cmath>
#include <iomanip>
#include <numbers>
#include <ostream>
#include <sstream>

#include "generated/registry.h"
#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"
#include "runtime/model/machine_summary.h"

namespace autoshovel::app {
namespace {

std::string Fixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

double Deg(double radians) { return radians * 180.0 / std::numbers::pi; }

}  // namespace

int RunDescribe(const DescribeOptions& options, std::ostream& out, std::ostream& err) {
  model::MachineDescription m;
  try {
    model::LoadOptions load;
    load.overlays = options.overlays;
    m = model::LoadMachineDescription(
        model::ResolveMachineDescription(options.machine, options.models_dir), load);
  } catch (const core::InputError& e) {
    for (const auto& d : e.diagnostics()) err << d.ToString() << '\n';
    return 1;
  } catch (const std::exception& e) {
    err << "autoshovel describe: " << e.what() << '\n';
    return 1;
  }
  const model::MachineSummary s = model::Summarize(m);

  out << m.name << " — " << model::ToString(m.kind) << ", " << model::ToString(m.drive)
      << " drive\n";
  out << "  description   " << m.source_file << "\n  sha256        " << m.sha256 << '\n';
  const generated::MachineFunctions* gen = generated::FindMachine(m.name);
  if (gen == nullptr) {
    out << "  generated     none (run: autoshovel gen " << m.source_file << ")\n";
  } else if (m.sha256 != gen->source_sha256) {
    out << "  generated     STALE: built from sha256 " << gen->source_sha256
        << "; run: cmake --build build --target regen\n";
  } else {
    out << "  generated     up to date (generated/" << m.name << "/)\n";
  }
  for (const std::string& overlay : m.overlays) out << "  overlay       " << overlay << '\n';
  out << "  estimated     " << m.estimated.size() << " values"
      << (options.show_estimated ? ":" : " (--estimated lists them)") << '\n';
  if (options.show_estimated) {
    for (const auto& path : m.estimated) out << "                  " << path << '\n';
  }

  out << "\nArm (frame M at " << Fixed(m.arm_pivot.x(), 3) << ", " << Fixed(m.arm_pivot.y(), 3)
      << " m in the base frame)\n";
  for (const auto& link : m.links) {
    out << "  " << std::left << std::setw(8) << link.name << std::right
        << " l = " << Fixed(link.length, 3) << " m   joint " << Fixed(Deg(link.joint_min), 1)
        << " .. " << Fixed(Deg(link.joint_max), 1) << " deg   IMU offset "
        << Fixed(Deg(link.imu_offset), 2) << " deg" << (link.linkage ? "   (four-bar)" : "")
        << '\n';
  }
  if (m.swing) {
    out << "  swing    joint " << Fixed(Deg(m.swing->joint_min), 1) << " .. "
        << Fixed(Deg(m.swing->joint_max), 1) << " deg\n";
  }

  out << "\nReach and heights (bucket tip B, base frame, ground at z = 0)\n";
  out << "  max reach                 " << Fixed(s.max_reach, 2) << " m from the base origin\n";
  out << "  max reach at ground level " << Fixed(s.max_reach_at_ground, 2) << " m\n";
  out << "  max tip height            " << Fixed(s.max_tip_height, 2) << " m\n";
  out << "  max bucket pivot height   " << Fixed(s.max_hinge_pin_height, 2) << " m\n";
  if (m.kind == model::MachineKind::kExcavator) {
    out << "  max digging depth         " << Fixed(s.dig_depth, 2) << " m\n";
  } else if (s.dump_pose_reachable) {
    out << "  dump clearance at 45 deg  " << Fixed(s.dump_clearance, 2)
        << " m (boom fully up, bucket 45 deg down)\n";
    out << "  dump reach at 45 deg      " << Fixed(s.dump_reach, 2) << " m ahead of the tyres\n";
  } else {
    out << "  dump at 45 deg            not reachable: bucket joint range too small\n";
  }
  out << "\nBucket-tip workspace: x " << Fixed(s.tip_x_min, 2) << " .. " << Fixed(s.tip_x_max, 2)
      << " m, z " << Fixed(s.tip_z_min, 2) << " .. " << Fixed(s.tip_z_max, 2)
      << " m ('#' reachable, '-' ground)\n";
  for (const auto& row : s.workspace_map) out << "  |" << row << "|\n";

  out << "\nCylinders over the joint range (stroke used vs available)\n";
  for (const auto& a : s.actuators) {
    if (a.is_motor) {
      out << "  " << std::left << std::setw(16) << a.name << std::right << " motor on " << a.joint
          << "   delay " << Fixed(a.transport_delay, 2) << " s, spool "
          << Fixed(a.spool_time_constant, 3) << " s\n";
      continue;
    }
    const double low = std::min(a.length_at_joint_min, a.length_at_joint_max);
    const double high = std::max(a.length_at_joint_min, a.length_at_joint_max);
    out << "  " << std::left << std::setw(16) << a.name << std::right << " uses "
        << Fixed(a.stroke_used, 3) << " of " << Fixed(a.stroke, 3) << " m ("
        << Fixed(100 * a.stroke_used / a.stroke, 1) << "%), margins "
        << Fixed((low - a.retracted_length) * 1000, 0) << " / "
        << Fixed((a.retracted_length + a.stroke - high) * 1000, 0) << " mm; lever "
        << Fixed(a.lever_min, 3) << " .. " << Fixed(a.lever_max, 3) << " m/rad; delay "
        << Fixed(a.transport_delay, 2) << " s\n";
  }
  out << "\nValves (`autoshovel identify hydraulics` identifies these)\n";
  for (const model::Actuator& a : m.hydraulics.actuators) {
    out << "  " << std::left << std::setw(17) << a.name << std::right << " dead zone "
        << Fixed(100 * a.valve.dead_zone, 1) << " %, delay " << Fixed(a.valve.transport_delay, 3)
        << " s, spool lag " << Fixed(a.valve.spool_time_constant, 3) << " s, rated flow "
        << Fixed(a.valve.rated_flow * 60e3, 0) << " l/min\n";
  }
  const auto pose_text = [](const model::Pose3& pose) {
    return "xyz " + Fixed(pose.xyz.x(), 3) + " " + Fixed(pose.xyz.y(), 3) + " " +
           Fixed(pose.xyz.z(), 3) + " m, rpy " + Fixed(Deg(pose.rpy.x()), 2) + " " +
           Fixed(Deg(pose.rpy.y()), 2) + " " + Fixed(Deg(pose.rpy.z()), 2) + " deg";
  };
  out << "\nSensor poses in the base frame (`autoshovel calibrate camera-lidar` calibrates the "
         "camera)\n";
  out << "  camera            " << pose_text(m.sensors.camera.pose) << '\n';
  for (const model::Lidar& lidar : m.sensors.lidars) {
    out << "  " << std::left << std::setw(17) << lidar.name << std::right << " "
        << pose_text(lidar.pose) << '\n';
  }
  out << "\nCarry pose (" << s.carry_pose_definition << "):";
  for (double q : s.carry_pose) out << ' ' << Fixed(Deg(q), 1);
  out << " deg\n";
  for (const auto& a : s.actuators) {
    if (a.is_motor) continue;
    out << "  " << std::left << std::setw(16) << a.name << std::right << " lever arm "
        << Fixed(a.lever_at_carry, 3) << " m/rad, torque at relief "
        << Fixed(a.torque_at_relief / 1000, 1) << " kN m\n";
  }
  if (s.lift_capacity_at_carry > 0) {
    out << "  hydraulic lift capacity   " << Fixed(s.lift_capacity_at_carry, 0)
        << " kg at the bucket's payload centre (rated load " << Fixed(m.bucket.rated_load, 0)
        << " kg)\n";
  }
  out << "\nBucket\n  struck volume (profile)   " << Fixed(s.struck_volume, 2)
      << " m3, rated heaped " << Fixed(m.bucket.rated_capacity, 2) << " m3\n"
      << "  rated capacity of " << m.bucket.design_material << "  "
      << Fixed(s.payload_at_rated_capacity, 0) << " kg (rated load "
      << Fixed(m.bucket.rated_load, 0) << " kg)\n";
  return 0;
}

}  // namespace autoshovel::app
