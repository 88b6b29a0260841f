#include "runtime/app/describe_command.h"

#include <cmath>
#include <iomanip>
#include <numbers>
#include <ostream>
#include <sstream>

#include "generated/registry.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/strings.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"
#include "runtime/model/machine_summary.h"
#include "runtime/model/spec_sheet.h"
#include "runtime/plant/hydraulic_cycle_times.h"

namespace autoshovel::app {
namespace {

using core::Fixed;

double Deg(double radians) { return radians * 180.0 / std::numbers::pi; }

// The machine's functions for the cycle-time simulation, as every command finds them
// (runtime/machines/machine_code.h: compiled in, its machine library, or interpreted); nullptr
// when it has none it may run (the "generated" line says why).
const generated::MachineFunctions* CycleTimeCode(const model::MachineDescription& m) {
  try {
    return machines::ResolveMachineCode(m, machines::ResolveOptions{}).functions;
  } catch (const machines::MachineCodeError&) {
    return nullptr;
  }
}

// Thousands separated by commas, as spec sheets print masses.
std::string Grouped(double value) {
  std::string digits = Fixed(std::round(value), 0);
  const bool negative = !digits.empty() && digits[0] == '-';
  if (negative) digits.erase(0, 1);
  for (int i = static_cast<int>(digits.size()) - 3; i > 0; i -= 3) digits.insert(i, ",");
  return (negative ? "-" : "") + digits;
}

// Spec-sheet figures of a wheel loader (docs/spec_sheet.md, "Spec-sheet figures").
void PrintSpecSheet(const model::MachineDescription& m, std::ostream& out) {
  const model::SpecSheet sheet = model::ComputeSpecSheet(m);
  const std::string indent(33, ' ');
  const model::BreakoutForce& b = sheet.breakout;
  out << "\nSpec sheet (definitions: docs/spec_sheet.md, \"Spec-sheet figures\")\n";
  out << "  breakout force (ISO 14397-2)   by tilt " << Fixed(b.by_tilt / 1e3, 1) << " kN, by lift "
      << Fixed(b.by_lift / 1e3, 1) << " kN, 100 mm behind the tip\n"
      << indent << "bucket bottom level, cutting edge on the ground (boom "
      << Fixed(Deg(b.pose[0]), 1) << ", bucket " << Fixed(Deg(b.pose[1]), 1) << " deg)"
      << (b.pose_in_range
              ? ""
              : "; beyond the joint limits: clamped, tip " + Fixed(b.p_base_tip.y() * 1000, 0) +
                    " mm above the ground, bottom " + Fixed(Deg(b.bottom_slope), 1) +
                    " deg off level")
      << '\n';
  if (std::isfinite(b.tipping_limit)) {
    out << indent << "unanchored, the rear wheels lift at " << Fixed(b.tipping_limit / 1e3, 1)
        << " kN there (straight, empty)\n";
  }
  const model::TippingLoad& t = sheet.tipping;
  out << "  static tipping load            straight " << Grouped(t.straight) << " kg, full turn ("
      << Fixed(Deg(t.articulation), 0) << " deg) " << Grouped(t.full_turn) << " kg (ISO 14397-1)\n"
      << indent << "boom horizontal, bucket racked back, load " << Fixed(t.p_base_load.x(), 2)
      << " m ahead of the hinge;\n"
      << indent << "full turn tips over the " << t.full_turn_edge << "; rated load "
      << Grouped(m.bucket.rated_load)
      << " kg = " << Fixed(100 * m.bucket.rated_load / t.full_turn, 0)
      << " % of it (ISO 14397-1: <= 50 %)\n";
  const model::TurningRadius& r = sheet.turning;
  out << "  turning radius at " << std::left << std::setw(13)
      << (Fixed(Deg(r.articulation), 0) + " deg") << std::right << "outside tyre "
      << Fixed(r.outside_tyre, 2) << " m, bucket corner in carry " << Fixed(r.bucket_corner, 2)
      << " m\n"
      << indent << "(tyre width " << Fixed(r.tyre_width, 2) << " m "
      << (r.tyre_width_assumed ? "assumed: 0.37 x tyre diameter" : "as described")
      << "; front axle centre " << Fixed(r.front_axle_centre, 2) << " m)\n";
  const model::HeapedCapacity& c = sheet.capacity;
  out << "  heaped capacity (SAE J742)     " << Fixed(c.heaped, 2) << " m3 = struck "
      << Fixed(c.struck, 2) << " + heap " << Fixed(c.heap, 2) << " (strike line "
      << Fixed(c.strike_length, 2) << " m); rated " << Fixed(c.rated, 2) << " m3 ("
      << (c.heaped >= c.rated ? "+" : "") << Fixed(100 * (c.heaped - c.rated) / c.rated, 1)
      << " %)\n";
  const model::Actuator& boom = m.hydraulics.actuators[m.ActuatorOfJoint(0)];
  const model::Actuator& tilt = m.hydraulics.actuators[m.ActuatorOfJoint(1)];
  out << "  hydraulic cycle (plant, empty) ";
  if (const generated::MachineFunctions* code = CycleTimeCode(m); code == nullptr) {
    out << "raise, dump, lower: n/a (run autoshovel gen " << m.source_file << ")\n";
  } else {
    const plant::HydraulicCycleTimes times = plant::SimulateHydraulicCycleTimes(m, *code);
    const auto time_text = [](double seconds) {
      return seconds < 0 ? std::string("not reached in 30 s") : Fixed(seconds, 1) + " s";
    };
    out << "raise " << time_text(times.raise) << ", dump " << time_text(times.dump) << ", lower "
        << time_text(times.lower);
    if (times.raise >= 0 && times.dump >= 0 && times.lower >= 0) {
      out << ", total " << Fixed(times.total(), 1) << " s";
    }
    out << "\n"
        << indent << "full valve, from the command: valve delay "
        << Fixed(boom.valve.transport_delay, 2) << " s boom, "
        << Fixed(tilt.valve.transport_delay, 2) << " s tilt, spool lag included; "
        << (m.hydraulics.pump_max_flow > 0
                ? "pump delivers at most " + Fixed(m.hydraulics.pump_max_flow * 60000, 0) +
                      " l/min (valves rated " + Fixed(boom.valve.rated_flow * 60000, 0) + " + " +
                      Fixed(tilt.valve.rated_flow * 60000, 0) + ")"
                : std::string("no pump flow limit (hydraulics.pump_max_flow_lpm)"))
        << "\n";
    if (times.bucket_past_dump_limit > 10 * std::numbers::pi / 180) {
      out << indent << "warning: the bucket went " << Fixed(Deg(times.bucket_past_dump_limit), 0)
          << " deg past its dumped limit: no tilt cylinder end holds that limit (the plant has"
             " no other stop)\n";
    }
  }
  const double needed = sheet.boom_pressure_for_rated_load;
  const double available = m.hydraulics.pump_pressure - boom.valve.rated_pressure_drop;
  out << indent << "rated load in carry needs " << Fixed(needed / 1e5, 0)
      << " bar in the boom cylinders, pump " << Fixed(m.hydraulics.pump_pressure / 1e5, 0)
      << " bar: "
      << (needed < available ? "raised loaded as fast (flow-limited)"
                             : "raised loaded slower (pressure-limited)")
      << '\n';
}

// The machine, its description file, the code it runs on, overlays and plausibility.
void PrintIdentity(const model::MachineDescription& m, bool show_estimated, std::ostream& out) {
  out << m.name << " — " << model::ToString(m.kind) << ", " << model::ToString(m.drive)
      << " drive\n";
  out << "  description   " << m.source_file << "\n  sha256        " << m.sha256 << '\n';
  // The code every other command would run this machine on (runtime/machines/machine_code.h).
  try {
    machines::ResolveOptions resolve;  // the interpreted fallback is said on this line instead
    const machines::MachineCode code = machines::ResolveMachineCode(m, resolve);
    switch (code.source) {
      case machines::CodeSource::kCompiledIn:
        out << "  generated     up to date (" << code.where << ")\n";
        break;
      case machines::CodeSource::kLibrary:
        out << "  generated     machine library " << code.where << '\n';
        break;
      case machines::CodeSource::kInterpreted:
        out << "  generated     none: the interpreted model runs it (" << code.where << ")\n";
        break;
    }
  } catch (const machines::MachineCodeError& e) {
    out << "  generated     none: " << e.what() << '\n';
  }
  for (const std::string& overlay : m.overlays) out << "  overlay       " << overlay << '\n';
  out << "  plausibility  "
      << (m.warnings.empty() ? "every value within physical ranges"
                             : std::to_string(m.warnings.size()) + " warning(s):")
      << '\n';
  for (const core::Diagnostic& warning : m.warnings) out << "    " << warning.ToString() << '\n';
  out << "  estimated     " << m.estimated.size() << " values"
      << (show_estimated ? ":" : " (--estimated lists them)") << '\n';
  if (show_estimated) {
    for (const auto& path : m.estimated) out << "                  " << path << '\n';
  }
}

// Links, joints and what drives them.
void PrintArm(const model::MachineDescription& m, std::ostream& out) {
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
  // The chain's topology: which joints an actuator drives, which are passive (closed in the
  // generated code), and what each cylinder connects.
  out << "  joints    driven:";
  for (std::size_t j = 0; j < m.num_joints(); ++j) {
    const int a = m.ActuatorOfJoint(j);
    out << (j ? ", " : " ") << (j < m.links.size() ? m.links[j].name : std::string("swing"))
        << (a >= 0 ? " by " + m.hydraulics.actuators[a].name : std::string(" (no actuator)"));
  }
  out << '\n';
  for (const auto& link : m.links) {
    if (!link.linkage) continue;
    out << "            passive: rocker and coupler of " << link.name
        << "'s four-bar (closed form)\n";
  }
  for (const auto& a : m.hydraulics.actuators) {
    if (a.kind != model::ActuatorKind::kCylinder) continue;
    const bool own = (a.base_mount.body == "chassis" && m.LinkIndex(a.joint) == 0) ||
                     a.base_mount.body != "chassis";
    out << "            " << a.name << ": " << a.base_mount.body << " -> " << a.rod_mount.body
        << (own ? "" : " (moves with every joint from the chassis to " + a.joint + ")") << '\n';
  }
}

void PrintReach(const model::MachineDescription& m, const model::MachineSummary& s,
                std::ostream& out) {
  out << "\nReach and heights (bucket tip B, base frame, ground at z = 0)\n";
  out << "  max reach                 " << Fixed(s.max_reach, 2) << " m from the base origin\n";
  out << "  max reach at ground level " << Fixed(s.max_reach_at_ground, 2) << " m\n";
  out << "  max tip height            " << Fixed(s.max_tip_height, 2) << " m\n";
  out << "  max bucket pivot height   " << Fixed(s.max_hinge_pin_height, 2) << " m\n";
  if (m.kind == model::MachineKind::kExcavator) {
    out << "  max digging depth         " << Fixed(s.dig_depth, 2) << " m\n";
  } else if (s.dump_pose_reachable) {
    out << "  dump clearance at 45 deg  " << Fixed(s.dump_clearance, 2)
        << " m to the cutting edge (SAE J732: boom fully up, bucket floor 45 deg down; bucket "
        << Fixed(Deg(s.dump_pose[1]), 1) << " deg)\n";
    out << "  dump reach at 45 deg      " << Fixed(s.dump_reach, 2)
        << " m from the front of the tyres to the cutting edge\n";
  } else {
    out << "  dump at 45 deg            not reachable: the bucket floor dumps to "
        << Fixed(Deg(s.dump_floor_at_limit), 1)
        << " deg at full lift (SAE J732: floor 45 deg down; joint range or tilt stroke too "
           "small)\n";
  }
  out << "\nBucket-tip workspace: x " << Fixed(s.tip_x_min, 2) << " .. " << Fixed(s.tip_x_max, 2)
      << " m, z " << Fixed(s.tip_z_min, 2) << " .. " << Fixed(s.tip_z_max, 2)
      << " m ('#' reachable, '-' ground)\n";
  for (const auto& row : s.workspace_map) out << "  |" << row << "|\n";
}

void PrintCylinders(const model::MachineSummary& s, std::ostream& out) {
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
    if (a.moves_with_earlier_joints) {
      // Frame-mounted: the stroke slides a window over the joint as the boom moves.
      out << "  " << std::left << std::setw(16) << a.name << std::right
          << " on the frame: " << a.joint << " reached " << Fixed(Deg(a.window_bottom_min), 1)
          << " .. " << Fixed(Deg(a.window_bottom_max), 1) << " deg with the boom down, "
          << Fixed(Deg(a.window_carry_min), 1) << " .. " << Fixed(Deg(a.window_carry_max), 1)
          << " at carry, " << Fixed(Deg(a.window_top_min), 1) << " .. "
          << Fixed(Deg(a.window_top_max), 1) << " fully up\n";
      out << "  " << std::string(16, ' ') << " uses " << Fixed(a.stroke_used, 3) << " of "
          << Fixed(a.stroke, 3) << " m (" << Fixed(100 * a.stroke_used / a.stroke, 1)
          << "%) posing the " << a.joint << " within its limits; "
          << (Deg(a.overrun_below_min) > 0.5 || Deg(a.overrun_above_max) > 0.5
                  ? "its ends let the " + a.joint + " pass its limits by up to " +
                        Fixed(Deg(a.overrun_below_min), 1) + " / " +
                        Fixed(Deg(a.overrun_above_max), 1) + " deg (no stop holds them)"
                  : "its ends stop the " + a.joint + " within its limits at every boom angle")
          << "; lever " << Fixed(a.lever_min, 3) << " .. " << Fixed(a.lever_max, 3)
          << " m/rad; delay " << Fixed(a.transport_delay, 2) << " s\n";
      continue;
    }
    out << "  " << std::left << std::setw(16) << a.name << std::right << " uses "
        << Fixed(a.stroke_used, 3) << " of " << Fixed(a.stroke, 3) << " m ("
        << Fixed(100 * a.stroke_used / a.stroke, 1) << "%), margins "
        << Fixed((low - a.retracted_length) * 1000, 0) << " / "
        << Fixed((a.retracted_length + a.stroke - high) * 1000, 0) << " mm; lever "
        << Fixed(a.lever_min, 3) << " .. " << Fixed(a.lever_max, 3) << " m/rad; delay "
        << Fixed(a.transport_delay, 2) << " s\n";
  }
}

void PrintValvesAndSensors(const model::MachineDescription& m, std::ostream& out) {
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
}

void PrintCarryAndBucket(const model::MachineDescription& m, const model::MachineSummary& s,
                         std::ostream& out) {
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
}

}  // namespace

int RunDescribe(const DescribeOptions& options, std::ostream& out, std::ostream& err) {
  model::MachineDescription m;
  try {
    model::LoadOptions load;
    load.overlays = options.overlays;
    load.models_dir = options.models_dir;
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

  PrintIdentity(m, options.show_estimated, out);
  PrintArm(m, out);
  PrintReach(m, s, out);
  PrintCylinders(s, out);
  PrintValvesAndSensors(m, out);
  PrintCarryAndBucket(m, s, out);
  if (m.kind == model::MachineKind::kWheelLoader) {
    try {
      PrintSpecSheet(m, out);
    } catch (const std::exception& e) {
      err << "autoshovel describe: spec-sheet figures: " << e.what() << '\n';
      return 1;
    }
  }
  return 0;
}

}  // namespace autoshovel::app
