#include "identification/hydraulics/plant_logs.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>

#include "runtime/core/file_output.h"
#include "runtime/plant/plant.h"

namespace autoshovel::identification {

namespace {

constexpr double kDeg = std::numbers::pi / 180;

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
    initial.q[joint] = link.joint_min + options.start_fraction * (link.joint_max - link.joint_min);
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

}  // namespace autoshovel::identification
