#include "identification/hydraulics/plant_logs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>

#include "identification/common/overlay_file.h"
#include "runtime/core/file_output.h"
#include "runtime/model/interpreted_model.h"
#include "runtime/plant/plant.h"

namespace autoshovel::identification {

namespace {

constexpr double kDeg = std::numbers::pi / 180;
constexpr double kBar = 1e5;

// The ControlDesk layout (plant_logs.h): axes in column order Arm, Bkt, Boom; the description's
// links are boom, arm (stick), bucket.
constexpr int kAxisLink[3] = {1, 2, 0};
constexpr const char* kAxisName[3] = {"Arm", "Bkt", "Boom"};
constexpr const char* kExtendName[3] = {"in", "in", "up"};
constexpr const char* kRetractName[3] = {"out", "out", "dn"};

// One actuator's truth chain (ControlDeskTruthOverlay): delays and lags in s, curves as
// [duty, opening] fractions. The boom's valve is a little slower than the arm's and its down
// direction (assisted by gravity) passes less.
struct TruthChain {
  double pilot_delay, pilot_time_constant, transport_delay;
  std::vector<model::OpeningPoint> extend, retract;
};

TruthChain TruthChainOf(int link) {
  if (link == 0) {
    return {0.070,
            0.040,
            0.120,
            {{0.37, 0}, {0.45, 0.16}, {0.55, 0.40}, {0.65, 0.64}, {0.8, 0.92}, {1.0, 1.0}},
            {{0.39, 0}, {0.5, 0.20}, {0.6, 0.40}, {0.7, 0.60}, {0.8, 0.78}, {1.0, 0.85}}};
  }
  return {0.080,
          0.050,
          0.100,
          {{0.35, 0}, {0.45, 0.20}, {0.55, 0.45}, {0.65, 0.68}, {0.8, 0.93}, {1.0, 1.0}},
          {{0.36, 0}, {0.45, 0.18}, {0.55, 0.42}, {0.7, 0.75}, {0.8, 0.90}, {1.0, 0.95}}};
}

std::string CurveText(const std::vector<model::OpeningPoint>& curve) {
  std::string text = "[";
  char point[64];
  for (std::size_t i = 0; i < curve.size(); ++i) {
    std::snprintf(point, sizeof point, "%s[%.2f, %.2f]", i == 0 ? "" : ", ", curve[i].duty,
                  curve[i].opening);
    text += point;
  }
  return text + "]";
}

// The link a ControlDesk actuator drives (0 boom, 1 arm), checked.
int ControlDeskLink(const model::MachineDescription& machine,
                    const generated::MachineFunctions& functions, int actuator) {
  if (machine.kind != model::MachineKind::kExcavator || machine.num_links() != 3) {
    throw std::invalid_argument(
        "--format controldesk: the step-test layout has boom, arm and "
        "bucket channels; machine '" +
        machine.name + "' is not a three-link excavator");
  }
  const int joint = functions.actuator_joint[actuator];
  const model::Actuator& act = machine.hydraulics.actuators[actuator];
  if ((joint != 0 && joint != 1) || act.kind != model::ActuatorKind::kCylinder) {
    throw std::invalid_argument(
        "--format controldesk: the real step tests exist for the boom "
        "and the arm only (files B-… and A-…), not for '" +
        act.name + "'");
  }
  return joint;
}

// The joint position of `actuator` (the other joints as in `q`) where its cylinder is
// `fraction` of its stroke out, kept within the joint's limits.
double JointAtStroke(const model::MachineDescription& machine,
                     const generated::MachineFunctions& functions, int actuator,
                     std::vector<double> q, double fraction) {
  const model::Actuator& act = machine.hydraulics.actuators[actuator];
  const int joint = functions.actuator_joint[actuator];
  q[joint] = functions.joint_min[joint];
  const double at_min = functions.cylinder_length(actuator, q.data());
  q[joint] = functions.joint_max[joint];
  const double at_max = functions.cylinder_length(actuator, q.data());
  const double length = std::clamp(act.retracted_length + fraction * act.stroke,
                                   std::min(at_min, at_max), std::max(at_min, at_max));
  std::vector<double> out(q.size());
  if (functions.joint_from_cylinder_length(actuator, length, q.data(), out.data()) != 0) {
    return std::abs(length - at_min) < std::abs(length - at_max) ? functions.joint_min[joint]
                                                                 : functions.joint_max[joint];
  }
  return out[joint];
}

struct StepTest {
  int actuator = 0;
  int link = 0;  // 0 boom, 1 arm
  int duty = 0;  // [%]
  bool extend = true;
  bool high_load = true;
  bool from_stop = false;
  std::string name;  // file stem
};

// The 28 header lines of a ControlDesk CSV export with `rows` samples over `length` seconds.
std::string ControlDeskHeader(const model::MachineDescription& machine, const StepTest& test,
                              std::size_t rows, double length, unsigned long long seed) {
  std::ostringstream out;
  char line[256];
  out << "descriptions,General,User,autoshovel\n"
      << ",General,DateTime,2000-01-01 00:00:00\n"
      // A quoted cell with a comma and a literal \n, as the real exports have.
      << ",General,Origin,\"Software revision: autoshovel plant (simulated), machine "
      << machine.name << "\\nTruth: truth.overlay.yaml\"\n"
      << ",General,Description,simulated step test " << test.name << " (seed " << seed << ")\n"
      << ",Recording,StartCondition,None (Immediate Recording)\n"
      << ",Recording,StopCondition,None\n"
      << ",Measurement,XAxisOffset,0\n";
  std::snprintf(line, sizeof line, ",Measurement,Length,%.8f\n", length);
  out << line << ",Measurement,StartTimestamp,0\n";
  std::snprintf(line, sizeof line, ",Measurement,StopTimestamp,%.6f\n", length);
  out << line << ",MDF,Department,\n,MDF,Project,\n,MDF,MeasurementObject,\n\n";
  out << "trace_size," << rows << "\n";
  out << "trace_types,5";
  for (int i = 0; i < 27; ++i) out << (i >= 12 && i < 18 ? ",18" : ",4");
  out << "\ntrace_names,";
  for (int i = 0; i < 6; ++i) out << ",In1";
  out << ",Arm_in_duty,Arm_out_duty,Bkt_in_duty,Bkt_out_duty,Boom_dn_duty,Boom_up_duty";
  for (int i = 0; i < 15; ++i) out << ",In1";
  auto repeat = [&](const std::string& head, const std::string& cell, int count) {
    out << "\n" << head;
    for (int i = 0; i < count; ++i) out << "," << cell;
  };
  repeat("trace_units", "", 28);
  repeat("devices", "Platform", 28);
  repeat("raster", "10ms Additional", 28);
  repeat("description", "", 28);
  repeat("displayidentifier", "", 28);
  // Unique last path components, except the duty channels (named in trace_names), as exported.
  const std::string root = "Model Root/";
  out << "\npath,";
  for (const char* p : {"Arm_InH_Cyl_P", "Arm_OutR_Cyl_P", "Bkt_InH_Cyl_P", "Bkt_OutR_Cyl_P",
                        "Boom_DnR_Cyl_P", "Boom_UpH_Cyl_P"}) {
    out << "," << root << "Cylinder pressure/" << p;
  }
  for (int i = 0; i < 6; ++i) out << "," << root << "Valve driver";
  for (const char* p :
       {"Arm_in_FB", "Arm_out_FB", "Bkt_in_FB", "Bkt_out_FB", "Boom_dn_FB", "Boom_up_FB"}) {
    out << "," << root << "Valve driver/" << p;
  }
  for (const char* p : {"Arm_In_eppr_P", "Arm_Out_eppr_P", "Bkt_In_eppr_P", "Bkt_Out_eppr_P",
                        "Boom_Dn_eppr_P", "Boom_Up_eppr_P"}) {
    out << "," << root << "EPPR pressure/" << p;
  }
  for (const char* p : {"Arm_ang", "Bkt_ang", "Boom_ang"})
    out << "," << root << "Joint_Angles/" << p;
  repeat("flags,", "2", 27);
  for (const char* bound : {"min", "max", "minWeak", "maxWeak"}) {
    out << "\n" << bound << ",";
    const bool low = bound[1] == 'i';
    for (int i = 0; i < 27; ++i) {
      const bool counts = i >= 12 && i < 18;
      out << ","
          << (counts ? (low ? "0" : "4294967295")
                     : (low ? "-1.797693135e+308" : "1.797693135e+308"));
    }
  }
  out << "\n";
  return out.str();
}

// Simulates one step test and returns the file's text.
std::string SimulateStepTest(const model::MachineDescription& machine,
                             const generated::MachineFunctions& functions, const StepTest& test,
                             const ControlDeskOptions& options, unsigned long long seed) {
  const int J = static_cast<int>(machine.num_joints());
  // An empty yard far below the arm: the bucket never reaches the ground, each joint runs into
  // its cylinder's end stop (a machine standing on a high bench).
  plant::World world = plant::EmptyYard(machine);
  for (int iy = 0; iy < world.terrain.ny(); ++iy) {
    for (int ix = 0; ix < world.terrain.nx(); ++ix) world.terrain.SetHeight(ix, iy, -30.0);
  }
  // The pose: the other links placed so that gravity loads the tested joint more (H) or less
  // (L): of two placements of the other arm link, H is the one with the larger gravity torque.
  std::vector<double> q(J, 0.0);
  for (int a = 0; a < functions.num_actuators; ++a) {
    const int j = functions.actuator_joint[a];
    if (j < static_cast<int>(machine.num_links()))
      q[j] = JointAtStroke(machine, functions, a, q, 0.5);
  }
  const model::InterpretedModel reference(machine);
  const int other_link = test.link == 0 ? 1 : 2;
  const int other = machine.ActuatorOfJoint(other_link);
  std::vector<double> qa = q, qb = q;
  qa[other_link] = JointAtStroke(machine, functions, other, q, 0.15);
  qb[other_link] = JointAtStroke(machine, functions, other, q, 0.85);
  const double ga = std::abs(reference.GravityTorques(qa.data(), 0.0, 0.0)[test.link]);
  const double gb = std::abs(reference.GravityTorques(qb.data(), 0.0, 0.0)[test.link]);
  q = (ga > gb) == test.high_load ? qa : qb;
  const double start_fraction =
      test.from_stop ? (test.extend ? 0.001 : 0.999)
                     : (test.extend ? 1.0 - options.start_travel : options.start_travel);
  q[test.link] = JointAtStroke(machine, functions, test.actuator, q, start_fraction);
  plant::MachineState initial;
  initial.q = q;
  plant::Plant plant(machine, functions, world, initial);

  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  const double dt = 1.0 / options.rate;
  const double duty = test.duty / 100.0;
  const model::Actuator& act = machine.hydraulics.actuators[test.actuator];
  double stalled_for = 0, off_at = -1;
  std::ostringstream rows;
  std::size_t count = 0;
  char cell[64];
  for (long i = 0;; ++i) {
    const double t = i * dt;
    // The command: rest, the step until the joint has stalled at its stop for stall_hold (or
    // max_step), then off for `after`.
    const bool on = t >= options.rest - 1e-9 && off_at < 0;
    command.valve[test.actuator] = on ? (test.extend ? duty : -duty) : 0.0;
    std::string why;
    if (!plant.SetCommand(command, &why)) throw std::runtime_error("step test: " + why);
    const plant::MachineState& s = plant.state();
    // Row: time, pressures, duties, driver feedback, pilots, angles (ControlDeskOptions).
    rows << (count == 0 ? "trace_values," : ",");
    std::snprintf(cell, sizeof cell, "%.5f", t);
    rows << cell;
    const int act_of_axis[3] = {machine.ActuatorOfJoint(1), machine.ActuatorOfJoint(2),
                                machine.ActuatorOfJoint(0)};
    auto pressure = [&](double p) {
      std::snprintf(cell, sizeof cell, ",%.4f", (p + options.pressure_noise * gauss(rng)) / kBar);
      rows << cell;
    };
    for (int axis = 0; axis < 3; ++axis) {
      const int joint = kAxisLink[axis];
      // Boom: rod (down side) first, then head; arm and bucket: head first.
      if (axis == 2) {
        pressure(s.pressure_b[joint]);
        pressure(s.pressure_a[joint]);
      } else {
        pressure(s.pressure_a[joint]);
        pressure(s.pressure_b[joint]);
      }
    }
    // Per channel (Arm_in, Arm_out, Bkt_in, Bkt_out, Boom_dn, Boom_up): the commanded duty of
    // that direction [%].
    double channel_duty[6];
    double channel_pilot[6];
    for (int axis = 0; axis < 3; ++axis) {
      const int a = act_of_axis[axis];
      const double u = command.valve[a];
      const double pilot = plant.PilotSignal(a);
      const int extend = axis == 2 ? 5 : 2 * axis, retract = axis == 2 ? 4 : 2 * axis + 1;
      channel_duty[extend] = std::max(u, 0.0) * 100;
      channel_duty[retract] = std::max(-u, 0.0) * 100;
      channel_pilot[extend] = options.pilot_pressure_full * std::max(pilot, 0.0);
      channel_pilot[retract] = options.pilot_pressure_full * std::max(-pilot, 0.0);
    }
    for (double d : channel_duty) {
      std::snprintf(cell, sizeof cell, ",%g", d);
      rows << cell;
    }
    // Driver feedback: about 84 counts per % (coil current), a few counts at rest.
    for (double d : channel_duty)
      rows << "," << std::lround(84.0 * d) + static_cast<long>(rng() % 10);
    for (double p : channel_pilot) {
      std::snprintf(cell, sizeof cell, ",%.4f", (p + options.pilot_noise * gauss(rng)) / kBar);
      rows << cell;
    }
    for (int axis = 0; axis < 3; ++axis) {
      const double angle = s.q[kAxisLink[axis]] + options.angle_noise * gauss(rng);
      std::snprintf(cell, sizeof cell, ",%.6f", angle / kDeg);
      rows << cell;
    }
    rows << "\n";
    ++count;
    if (off_at >= 0 && t >= off_at + options.after - 1e-9) break;
    // Stall: the cylinder stands still at the end of its stroke with the command on (a slow
    // low-duty motion is not one: it is cut at max_step).
    if (on) {
      const double length = functions.cylinder_length(test.actuator, s.q.data());
      const double end = act.retracted_length + (test.extend ? act.stroke : 0.0);
      const bool at_stop = std::abs(length - end) < 0.01 * act.stroke;
      // Stalled: the driving chamber at the pump's limit (the joint may hunt by a few tenths of
      // a degree per second there: the compensator's band).
      const double driving = test.extend ? s.pressure_a[test.link] : s.pressure_b[test.link];
      const bool stalled = at_stop && std::abs(s.qd[test.link]) < 2 * kDeg &&
                           driving > 0.85 * machine.hydraulics.pump_pressure;
      stalled_for = stalled ? stalled_for + dt : 0.0;
      if (stalled_for >= options.stall_hold - 1e-9 || t >= options.rest + options.max_step - 1e-9) {
        off_at = t + dt;
      }
    }
    plant.Advance(dt);
  }
  return ControlDeskHeader(machine, test, count, (count - 1) * dt, seed) + rows.str();
}

}  // namespace

HydraulicLog SimulatePlantLog(const model::MachineDescription& machine,
                              const generated::MachineFunctions& functions, int actuator,
                              const std::function<double(double)>& command, double duration,
                              const PlantLogOptions& options) {
  plant::World world = plant::EmptyYard(machine);
  plant::MachineState initial;
  initial.q.assign(machine.num_joints(), 0.0);
  for (std::size_t j = 0; j < machine.num_links(); ++j) {
    const model::Link& link = machine.links[j];
    initial.q[j] = link.joint_min + 0.45 * (link.joint_max - link.joint_min);
  }
  const int joint = functions.actuator_joint[actuator];
  if (joint < static_cast<int>(machine.num_links())) {
    const model::Link& link = machine.links[joint];
    initial.q[joint] =
        std::isfinite(options.start_angle)
            ? std::clamp(options.start_angle, link.joint_min, link.joint_max)
            : link.joint_min + options.start_fraction * (link.joint_max - link.joint_min);
  }
  plant::Plant plant(machine, functions, world, initial);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double noise = options.noise ? 1.0 : 0.0;
  HydraulicLog log;
  log.actuator = machine.hydraulics.actuators[actuator].name;
  core::ActuatorCommand valves;
  valves.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  const double dt = 1.0 / options.rate;
  const long samples = std::lround(duration * options.rate);
  for (long i = 0; i <= samples; ++i) {
    const double t = plant.time();
    valves.valve[actuator] = std::clamp(command(t), -1.0, 1.0);
    std::string why;
    if (!plant.SetCommand(valves, &why)) {
      throw std::runtime_error("SimulatePlantLog: command refused at t = " + std::to_string(t) +
                               ": " + why);
    }
    const plant::MachineState& s = plant.state();
    log.row.push_back(static_cast<int>(i) + 1);
    log.time.push_back(t);
    log.command.push_back(valves.valve[actuator]);
    log.spool.push_back(s.spool[joint] + noise * options.spool_noise * gauss(rng));
    log.pressure_a.push_back(plant.ActuatorPressure(actuator, true) +
                             noise * options.pressure_noise * gauss(rng));
    log.pressure_b.push_back(plant.ActuatorPressure(actuator, false) +
                             noise * options.pressure_noise * gauss(rng));
    log.joint_angle.push_back(s.q[joint] + noise * options.angle_noise * gauss(rng));
    if (i < samples) plant.Advance(dt);
  }
  return log;
}

LogFormat DataLoggerFormat() {
  LogFormat format;
  format.columns = {{"time", "Time"},       {"command", "Valve cmd"}, {"joint_angle", "Angle"},
                    {"spool", "Spool pos"}, {"pressure_a", "P cap"},  {"pressure_b", "P rod"}};
  format.time_units = TimeUnits::kMilliseconds;
  format.command_units = format.spool_units = CommandUnits::kPercent;
  format.angle_units = AngleUnits::kDegrees;
  format.pressure_units = PressureUnits::kBar;
  return format;
}

void WriteLog(const HydraulicLog& log, const std::string& path, LogStyle style,
              const std::string& machine_name) {
  // Composed in memory, then one checked atomic write (core/file_output.h).
  std::ostringstream out;
  char line[256];
  if (style == LogStyle::kPlantStep) {
    out << "# simulated plant log: machine " << machine_name << ", actuator " << log.actuator
        << "\n# units: s, duty [-1,1], spool [-1,1], Pa, rad\n";
    out << "t,command,spool,pressure,joint_angle\n";
    for (std::size_t j = 0; j < log.size(); ++j) {
      std::snprintf(line, sizeof line, "%.4f,%.6f,%.6f,%.0f,%.7f\n", log.time[j], log.command[j],
                    log.spool[j], log.pressure_a[j], log.joint_angle[j]);
      out << line;
    }
    core::WriteFileAtomically(path, out.str());
    return;
  }
  // A data logger: its own banner, names then units, a different order, semicolons.
  out << "DataLogger DL-8 export;;;;;\n"
      << "Channel set: " << machine_name << " " << log.actuator << ";;;;;\n"
      << "Angle;Time;Spool pos;Valve cmd;P rod;P cap\n"
      << "deg;ms;%;%;bar;bar\n";
  for (std::size_t j = 0; j < log.size(); ++j) {
    std::snprintf(line, sizeof line, "%.3f;%.1f;%.2f;%.2f;%.2f;%.2f\n", log.joint_angle[j] / kDeg,
                  log.time[j] * 1e3, log.spool[j] * 100, log.command[j] * 100,
                  log.pressure_b[j] * 1e-5, log.pressure_a[j] * 1e-5);
    out << line;
  }
  core::WriteFileAtomically(path, out.str());
}

std::function<double(double)> StepCommand(double level, double t0, double t1) {
  return [=](double t) { return t >= t0 - 1e-9 && t < t1 - 1e-9 ? level : 0.0; };
}

std::function<double(double)> ChirpCommand(double level, double f0, double f1, double t0,
                                           double t1) {
  return [=](double t) {
    if (t < t0 - 1e-9 || t >= t1 - 1e-9) return 0.0;
    const double tau = t - t0;
    return level *
           std::sin(2 * std::numbers::pi * (f0 * tau + 0.5 * (f1 - f0) / (t1 - t0) * tau * tau));
  };
}

std::vector<std::string> WriteSimulatedCampaign(const model::MachineDescription& machine,
                                                const generated::MachineFunctions& functions,
                                                int actuator, const std::string& dir,
                                                unsigned long long seed) {
  core::CreateFolders(dir);
  const std::string name = machine.hydraulics.actuators[actuator].name;
  std::vector<std::string> paths;
  PlantLogOptions options;
  options.seed = seed;
  char file[128];
  for (double level : {0.3, 0.6, 1.0}) {
    for (double sign : {1.0, -1.0}) {
      ++options.seed;
      const HydraulicLog log = SimulatePlantLog(machine, functions, actuator,
                                                StepCommand(sign * level, 0.3, 1.5), 2.3, options);
      std::snprintf(file, sizeof file, "%s_step_%s_%03d.csv", name.c_str(),
                    sign > 0 ? "up" : "down", static_cast<int>(std::lround(level * 100)));
      paths.push_back((std::filesystem::path(dir) / file).string());
      WriteLog(log, paths.back(), LogStyle::kPlantStep, machine.name);
    }
  }
  ++options.seed;
  const HydraulicLog chirp = SimulatePlantLog(machine, functions, actuator,
                                              ChirpCommand(0.6, 0.2, 1.5, 0.3, 6.3), 6.6, options);
  const std::string stem = (std::filesystem::path(dir) / (name + "_chirp_060")).string();
  paths.push_back(stem + ".csv");
  WriteLog(chirp, paths.back(), LogStyle::kDataLogger, machine.name);
  std::ostringstream map;
  map << "# Column map of " << name << "_chirp_060.csv (autoshovel identify hydraulics)\n"
      << "columns:\n  time: Time\n  command: Valve cmd\n  spool: Spool pos\n"
      << "  joint_angle: Angle\n  pressure_a: P cap\n  pressure_b: P rod\n"
      << "units: {time: ms, command: percent, spool: percent, angle: deg, pressure: bar}\n"
      << "actuator: " << name << "\n";
  core::WriteFileAtomically(stem + ".columns.yaml", map.str());
  return paths;
}

std::string ControlDeskTruthOverlay(const model::MachineDescription& machine,
                                    const std::vector<int>& actuators,
                                    const std::string& command_line) {
  std::ostringstream text;
  text << OverlayHeader(machine, command_line)
       << "# The truth of a simulated step-test campaign: the valve chain of docs/simulation.md.\n"
       << "# spool_time_constant and rated_flow_lpm are the description's (they are compiled into\n"
       << "# the machine's code); a stalled joint holds the pump's limit, "
       << machine.hydraulics.pump_pressure / kBar << " bar.\n"
       << "hydraulics:\n  actuators:\n";
  char line[200];
  for (int a : actuators) {
    const model::Actuator& act = machine.hydraulics.actuators[a];
    const TruthChain chain = TruthChainOf(machine.ActuatorOfJoint(0) == a ? 0 : 1);
    text << "    - name: " << act.name << "\n      dead_zone: 0\n";
    std::snprintf(line, sizeof line,
                  "      pilot_delay: %.3f\n      pilot_time_constant: %.3f\n"
                  "      transport_delay: %.3f\n      spool_time_constant: %.3f\n"
                  "      rated_flow_lpm: %.1f\n",
                  chain.pilot_delay, chain.pilot_time_constant, chain.transport_delay,
                  act.valve.spool_time_constant, act.valve.rated_flow / (1e-3 / 60));
    text << line << "      opening_curve_extend: " << CurveText(chain.extend) << "\n"
         << "      opening_curve_retract: " << CurveText(chain.retract) << "\n";
  }
  return text.str();
}

std::vector<std::string> WriteControlDeskCampaign(const model::MachineDescription& machine,
                                                  const generated::MachineFunctions& functions,
                                                  const std::vector<int>& actuators,
                                                  const std::string& dir, unsigned long long seed,
                                                  const ControlDeskOptions& options) {
  std::vector<int> links;
  for (int a : actuators) links.push_back(ControlDeskLink(machine, functions, a));
  core::CreateFolders(dir);
  const std::string overlay = (std::filesystem::path(dir) / "truth.overlay.yaml").string();
  core::WriteFileAtomically(
      overlay, ControlDeskTruthOverlay(machine, actuators,
                                       "autoshovel identify hydraulics --simulate " + dir +
                                           " --format controldesk --seed " + std::to_string(seed)));
  // The machine with its truth chain, read back through the loader as any overlay would be.
  model::LoadOptions load;
  load.overlays = {overlay};
  const model::MachineDescription truth = model::LoadMachineDescription(machine.source_file, load);
  std::vector<std::string> paths;
  unsigned long long file_seed = seed;
  for (std::size_t k = 0; k < actuators.size(); ++k) {
    for (const bool extend : {true, false}) {
      for (const int duty : options.duties) {
        for (const bool high : {true, false}) {
          StepTest test;
          test.actuator = actuators[k];
          test.link = links[k];
          test.duty = duty;
          test.extend = extend;
          test.high_load = high;
          test.from_stop = duty == 100;
          const int axis = links[k] == 0 ? 2 : 0;
          test.name = std::string(links[k] == 0 ? "B" : "A") + "-" +
                      (extend ? kExtendName[axis] : kRetractName[axis]) + "-" +
                      std::to_string(duty) + "-" + (high ? "H" : "L") + "-S";
          paths.push_back((std::filesystem::path(dir) / (test.name + ".csv")).string());
          core::WriteFileAtomically(paths.back(),
                                    SimulateStepTest(truth, functions, test, options, ++file_seed));
        }
      }
    }
  }
  return paths;
}

}  // namespace autoshovel::identification
