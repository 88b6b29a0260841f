#include "identification/hydraulics/identify_hydraulics_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "generated/registry.h"
#include "identification/common/overlay_file.h"
#include "identification/hydraulics/chain_report.h"
#include "identification/hydraulics/hydraulic_identification.h"
#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/plant_logs.h"
#include "identification/hydraulics/plant_replay.h"
#include "identification/hydraulics/residual_plot.h"
#include "identification/hydraulics/valve_chain_fit.h"
#include "runtime/core/diagnostics.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {

namespace {

constexpr const char* kName = "autoshovel identify hydraulics";
constexpr double kLpm = 1e-3 / 60;  // m³/s per l/min
constexpr double kMs = 1e-3;

std::string Sidecar(const std::string& log) {
  std::filesystem::path path(log);
  return (path.parent_path() / (path.stem().string() + ".columns.yaml")).string();
}

// The explicit options that change how a log is read, as written on the command line.
std::vector<std::string> ExplicitReadingOptions(const IdentifyHydraulicsOptions& options) {
  std::vector<std::string> given;
  const std::pair<const char*, bool> all[] = {
      {"--column-map", !options.column_map.empty()},
      {"--columns", !options.columns.empty()},
      {"--command-units", !options.command_units.empty()},
      {"--spool-units", !options.spool_units.empty()},
      {"--angle-units", !options.angle_units.empty()},
      {"--pressure-units", !options.pressure_units.empty()},
      {"--time-units", !options.time_units.empty()},
      {"--header-lines", options.header_lines >= 0},
      {"--actuator", !options.actuator.empty()},
  };
  for (const auto& [name, set] : all) {
    if (set) given.push_back(name);
  }
  return given;
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  }
  return text;
}

// What the user typed beats a file they may not know is there: an explicit column map replaces
// a sibling `X.columns.yaml`, other explicit options override its fields. Either way one line
// on `err` says so, since the sibling used to win silently.
LogFormat FormatFor(const std::string& log, const IdentifyHydraulicsOptions& options,
                    std::ostream& err) {
  const std::string sidecar = Sidecar(log);
  const bool has_sidecar = std::filesystem::is_regular_file(sidecar);
  const bool explicit_map = !options.columns.empty() || !options.column_map.empty();
  const std::vector<std::string> given = ExplicitReadingOptions(options);
  LogFormat format;
  if (has_sidecar && explicit_map) {
    err << kName << ": note: " << sidecar << " ignored for " << log << ": "
        << (options.columns.empty() ? "--column-map" : "--columns") << " given\n";
  } else if (has_sidecar) {
    format = ReadLogFormatYaml(sidecar);
    if (!given.empty()) {
      err << kName << ": note: " << log << " read with " << sidecar << ", " << JoinNames(given)
          << " overriding it\n";
    }
  }
  if (!options.column_map.empty()) {
    format = ReadLogFormatYaml(options.column_map);
    for (auto& [key, source] : format.column_sources) source = "--column-map " + source;
  }
  if (!options.columns.empty()) format = ParseColumnsSpec(options.columns, format);
  if (!options.command_units.empty()) {
    format.command_units = format.spool_units = ParseCommandUnits(options.command_units);
  }
  if (!options.spool_units.empty()) format.spool_units = ParseCommandUnits(options.spool_units);
  if (!options.angle_units.empty()) format.angle_units = ParseAngleUnits(options.angle_units);
  if (!options.pressure_units.empty()) {
    format.pressure_units = ParsePressureUnits(options.pressure_units);
  }
  if (!options.time_units.empty()) format.time_units = ParseTimeUnits(options.time_units);
  if (options.header_lines >= 0) format.header_lines = options.header_lines;
  if (!options.actuator.empty()) format.actuator = options.actuator;
  return format;
}

using Clock = std::chrono::steady_clock;

// Logs of at least this many rows in all (about 15 minutes at 100 Hz) report progress.
constexpr std::size_t kProgressRows = 100000;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Progress of a long identification on stderr: whole lines with the elapsed time, never `\r`
// rewrites (stderr is often a log file or a pipe, where those pile up into one endless line).
struct ProgressLine {
  std::ostream& err;
  Clock::time_point start;
  bool enabled = false;
  void operator()(const std::string& line) const {
    if (!enabled) return;
    char elapsed[32];
    std::snprintf(elapsed, sizeof elapsed, "%7.1f s  ", Seconds(start));
    err << kName << ": " << elapsed << line << "\n" << std::flush;
  }
};

// "1000001 rows: read 1.9 s, fitted 12.3 s; 70000 rows/s": the cost of a log, which grows
// linearly with its length.
std::string Throughput(std::size_t rows, double read_seconds, double fit_seconds) {
  char line[160];
  std::snprintf(line, sizeof line, "%zu rows: read %.2f s, fitted %.2f s; %.0f rows/s\n", rows,
                read_seconds, fit_seconds, rows / std::max(read_seconds + fit_seconds, 1e-9));
  return line;
}

[[noreturn]] void FailFile(const std::string& file, const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add({file, 0, 0}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

std::string ActuatorList(const model::MachineDescription& machine) {
  std::string list;
  for (const auto& act : machine.hydraulics.actuators) {
    list += (list.empty() ? "" : ", ") + act.name + " (joint " + act.joint + ")";
  }
  return list;
}

// "0.0812 ± 0.0011" columns of the table.
void PrintTable(const ActuatorIdentification& r, std::ostream& out) {
  char line[256];
  std::snprintf(line, sizeof line,
                "%s: %zu files, %zu samples (%zu at end stops left out), spool feedback %s\n",
                r.actuator.c_str(), r.files.size(), r.samples, r.excluded,
                r.has_spool ? "used" : "not logged");
  out << line;
  out << "  parameter                 description   identified     1-sigma     95 % interval\n";
  struct Row {
    const char* name;
    double nominal, value, sigma, scale;
    const char* format;
  };
  const Row rows[] = {
      {"dead zone [%]", r.nominal.dead_zone, r.params.dead_zone, r.std_dev.dead_zone, 100, "%9.2f"},
      {"transport delay [ms]", r.nominal.transport_delay, r.params.transport_delay,
       r.std_dev.transport_delay, 1 / kMs, "%9.1f"},
      {"spool time const. [ms]", r.nominal.spool_time_constant, r.params.spool_time_constant,
       r.std_dev.spool_time_constant, 1 / kMs, "%9.1f"},
      {"rated flow [l/min]", r.nominal.rated_flow, r.params.rated_flow, r.std_dev.rated_flow,
       1 / kLpm, "%9.1f"},
  };
  for (std::size_t i = 0; i < 4; ++i) {
    const Row& row = rows[i];
    char cells[5][40];
    std::snprintf(cells[0], sizeof cells[0], row.format, row.nominal * row.scale);
    std::snprintf(cells[1], sizeof cells[1], row.format, row.value * row.scale);
    std::snprintf(cells[2], sizeof cells[2], row.format, row.sigma * row.scale);
    std::snprintf(cells[3], sizeof cells[3], row.format,
                  (row.value - 1.96 * row.sigma) * row.scale);
    std::snprintf(cells[4], sizeof cells[4], row.format,
                  (row.value + 1.96 * row.sigma) * row.scale);
    std::snprintf(line, sizeof line, "  %-24s %s    %s   %s   [%s, %s]%s\n", row.name, cells[0],
                  cells[1], cells[2], cells[3], cells[4], r.at_bound[i] ? "  (at its bound)" : "");
    out << line;
  }
  std::snprintf(
      line, sizeof line, "  residual RMS: joint angle %.3f deg%s; %d iterations, %.2f s\n",
      r.angle_sigma * 180 / std::numbers::pi,
      r.has_spool ? (", spool " + std::to_string(r.spool_sigma * 100).substr(0, 5) + " %").c_str()
                  : "",
      r.iterations, r.seconds);
  out << line;
  if (r.cross_validation.empty()) {
    out << "  cross-validation: needs logs at two or more duty levels\n";
    return;
  }
  out << "  cross-validation (fit on the other duty levels, predict this one):\n"
      << "    held out  files  dead zone  delay    tau_s    flow       angle RMS        "
         "spool RMS\n";
  for (const CrossValidationFold& fold : r.cross_validation) {
    std::snprintf(
        line, sizeof line,
        "    %5.0f %%   %5zu  %7.2f %%  %5.0f ms %5.1f ms %6.1f l/min  %.3f deg "
        "(%.1f %%)  %s\n",
        fold.level * 100, fold.files.size(), fold.params.dead_zone * 100,
        fold.params.transport_delay / kMs, fold.params.spool_time_constant / kMs,
        fold.params.rated_flow / kLpm, fold.angle_rms * 180 / std::numbers::pi,
        100 * fold.angle_rms / std::max(fold.angle_range, 1e-9),
        r.has_spool ? (std::to_string(fold.spool_rms * 100).substr(0, 4) + " %").c_str() : "-");
    out << line;
  }
}

std::string OverlayText(const model::MachineDescription& machine,
                        const std::vector<ActuatorIdentification>& results,
                        const std::string& command_line) {
  std::ostringstream text;
  text << OverlayHeader(machine, command_line) << "hydraulics:\n  actuators:\n";
  char line[200];
  for (const ActuatorIdentification& r : results) {
    text << "    - name: " << r.actuator << "\n";
    std::snprintf(line, sizeof line,
                  "      dead_zone: %.4f            # fraction of full command, +/- %.4f\n",
                  r.params.dead_zone, r.std_dev.dead_zone);
    text << line;
    std::snprintf(line, sizeof line, "      transport_delay: %.4f      # s, +/- %.4f\n",
                  r.params.transport_delay, r.std_dev.transport_delay);
    text << line;
    std::snprintf(line, sizeof line, "      spool_time_constant: %.4f  # s, +/- %.4f\n",
                  r.params.spool_time_constant, r.std_dev.spool_time_constant);
    text << line;
    std::snprintf(line, sizeof line, "      rated_flow_lpm: %.1f         # l/min, +/- %.1f\n",
                  r.params.rated_flow / kLpm, r.std_dev.rated_flow / kLpm);
    text << line;
  }
  return text.str();
}

// "MIN:MAX" → the pair, in the given scale; throws std::invalid_argument naming the option.
std::pair<double, double> ParseRange(const std::string& text, const char* option, double scale) {
  const auto colon = text.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument("");
    std::size_t used = 0;
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    const double low = std::stod(a, &used);
    if (used != a.size()) throw std::invalid_argument("");
    const double high = std::stod(b, &used);
    if (used != b.size() || !(low < high) || !std::isfinite(low) || !std::isfinite(high)) {
      throw std::invalid_argument("");
    }
    return {low * scale, high * scale};
  } catch (const std::exception&) {
    throw std::invalid_argument(std::string(option) + ": expected MIN:MAX with MIN < MAX, got '" +
                                text + "'");
  }
}

double PressureScale(PressureUnits units) {
  switch (units) {
    case PressureUnits::kBar:
      return 1e5;
    case PressureUnits::kMegapascal:
      return 1e6;
    default:
      return 1.0;
  }
}

// The plant's convention: a positive command extends the cylinder. Whether that raises or
// lowers the joint angle is the sign of the description's lever dL/dq (mid-range); a motor: +1.
int JointSense(const model::MachineDescription& machine,
               const generated::MachineFunctions& functions, int actuator) {
  const ActuatorKinematics kinematics(machine, functions, actuator);
  const int joint = functions.actuator_joint[actuator];
  double mid = 0;
  if (joint < static_cast<int>(machine.num_links())) {
    const model::Link& link = machine.links[static_cast<std::size_t>(joint)];
    mid = 0.5 * (link.joint_min + link.joint_max);
  }
  return kinematics.Lever(mid) < 0 ? -1 : 1;
}

template <typename ProgressFn>
int RunChain(const IdentifyHydraulicsOptions& options, const model::MachineDescription& machine,
             const generated::MachineFunctions& functions,
             const std::map<int, std::vector<HydraulicLog>>& by_actuator, std::size_t rows,
             double read_seconds, Clock::time_point start, ProgressFn& progress,
             std::ostream& out) {
  std::string command_line = kName;
  // Name a few logs; a campaign of many would make the comment unreadable.
  for (std::size_t i = 0; i < options.logs.size() && i < 3; ++i) {
    command_line += " " + options.logs[i];
  }
  if (options.logs.size() > 3) {
    command_line += " … (" + std::to_string(options.logs.size()) + " logs)";
  }
  command_line += " --machine " + machine.name + " --model chain";
  ChainFitOptions fit;
  fit.bootstrap = options.bootstrap;
  fit.seed = options.seed;
  fit.validate = options.cross_validate;
  const LogFormat format = [&] {
    std::ostringstream ignored;
    return FormatFor(options.logs.front(), options, ignored);
  }();
  fit.events.relief = options.relief * PressureScale(format.pressure_units);
  const double angle_scale =
      format.angle_units == AngleUnits::kDegrees ? std::numbers::pi / 180 : 1.0;
  if (!options.joint_range.empty()) {
    std::tie(fit.events.joint_min, fit.events.joint_max) =
        ParseRange(options.joint_range, "--joint-range", angle_scale);
  }
  if (!options.window.empty()) {
    std::tie(fit.events.window_begin, fit.events.window_end) =
        ParseRange(options.window, "--window", 1.0);
  }
  std::vector<NamedChain> results;
  for (const auto& [a, group] : by_actuator) {
    const model::Actuator& actuator = machine.hydraulics.actuators[a];
    fit.progress = [&](const std::string& line) { progress(actuator.name + ": " + line); };
    if (actuator.kind == model::ActuatorKind::kCylinder && actuator.bore > 0) {
      const double cap = actuator.bore * actuator.bore;
      fit.area_ratio = (cap - actuator.rod * actuator.rod) / cap;
    }
    fit.events.joint_sense = JointSense(machine, functions, a);
    NamedChain named{actuator.name, IdentifyValveChain(group, fit), 0.0, "", {}};
    AssignPlantFlow(named, machine, functions, a);
    results.push_back(std::move(named));
  }
  const double fit_seconds = Seconds(start) - read_seconds;
  progress("fitted");
  out << "valve chain identification of " << machine.name << " from " << options.logs.size()
      << " log" << (options.logs.size() == 1 ? "" : "s") << "\n";
  for (const NamedChain& r : results) PrintChainTable(r, out);
  out << Throughput(rows, read_seconds, fit_seconds);
  const std::string png =
      options.png.empty() ? options.logs.front() + ".residuals.png" : options.png;
  const std::string overlay =
      options.overlay.empty() ? options.logs.front() + ".overlay.yaml" : options.overlay;
  WriteChainPlot(results, png);
  WriteFileAtomically(overlay, ChainOverlayText(OverlayHeader(machine, command_line), results));
  out << "overlay: " << overlay << "\nresiduals: " << png << "\n";
  return 0;
}

}  // namespace

int RunIdentifyHydraulics(const IdentifyHydraulicsOptions& options, std::ostream& out,
                          std::ostream& err) {
  try {
    const model::MachineDescription machine = model::LoadMachineDescription(
        model::ResolveMachineDescription(options.machine, options.models_dir));
    const generated::MachineFunctions* functions = nullptr;
    try {
      functions = &machines::MachineFunctionsFor(machine);
    } catch (const machines::MachineCodeError& e) {
      err << kName << ": " << e.what() << "\n";
      return 2;
    }
    if (!options.actuator.empty() && FindActuator(machine, options.actuator) < 0) {
      err << kName << ": machine '" << machine.name << "' has no actuator '" << options.actuator
          << "'; it has: " << ActuatorList(machine) << "\n";
      return 2;
    }

    if (!options.simulate.empty() && options.simulate_format == "controldesk") {
      std::vector<int> actuators;
      if (!options.actuator.empty()) {
        actuators.push_back(FindActuator(machine, options.actuator));
      } else {
        for (int link : {0, 1}) actuators.push_back(machine.ActuatorOfJoint(link));
      }
      const auto start = Clock::now();
      const std::vector<std::string> paths =
          WriteControlDeskCampaign(machine, *functions, actuators, options.simulate, options.seed);
      char took[64];
      std::snprintf(took, sizeof took, " in %.1f s", Seconds(start));
      out << "simulated " << paths.size() << " ControlDesk step tests of " << machine.name << " in "
          << options.simulate << took << " (seed " << options.seed
          << "); their valve chain: " << options.simulate << "/truth.overlay.yaml\n";
      for (const std::string& p : paths) out << "  " << p << "\n";
      return 0;
    }
    if (!options.simulate.empty()) {
      std::vector<int> actuators;
      if (!options.actuator.empty()) {
        actuators.push_back(FindActuator(machine, options.actuator));
      } else {
        for (std::size_t a = 0; a < machine.hydraulics.actuators.size(); ++a) {
          actuators.push_back(static_cast<int>(a));
        }
      }
      std::vector<std::string> paths;
      for (int a : actuators) {
        for (const std::string& p :
             WriteSimulatedCampaign(machine, *functions, a, options.simulate, options.seed)) {
          paths.push_back(p);
        }
      }
      out << "simulated " << paths.size() << " plant logs of " << machine.name << " in "
          << options.simulate << " (steps at 30, 60, 100 % both ways, a 60 % chirp; seed "
          << options.seed << "):\n";
      for (const std::string& p : paths) out << "  " << p << "\n";
      out << "try: autoshovel identify hydraulics " << options.simulate << "/*.csv --machine "
          << machine.name << "\n";
      return 0;
    }

    if (options.logs.empty()) {
      err << kName << ": give one or more logs (or --simulate DIR)\n";
      return 2;
    }
    // Read everything first.
    const Clock::time_point start = Clock::now();
    ProgressLine progress(err, start);
    std::vector<HydraulicLog> logs;
    std::size_t rows = 0;
    for (const std::string& path : options.logs) {
      logs.push_back(ReadHydraulicLog(path, FormatFor(path, options, err)));
      rows += logs.back().size();
      // Only a big campaign is worth the lines: a few seconds pass silently.
      if (rows >= kProgressRows) progress.enabled = true;
      progress("read " + path + " (" + std::to_string(logs.back().size()) + " rows)");
    }
    const double read_seconds = Seconds(start);
    std::map<int, std::vector<HydraulicLog>> by_actuator;
    for (HydraulicLog& log : logs) {
      if (log.actuator.empty()) {
        FailFile(log.file, "the log does not name its actuator: give --actuator (" +
                               ActuatorList(machine) + ")");
      }
      const int a = FindActuator(machine, log.actuator);
      if (a < 0) {
        FailFile(log.file, "no actuator '" + log.actuator + "' on " + machine.name + " (it has " +
                               ActuatorList(machine) + ")");
      }
      by_actuator[a].push_back(std::move(log));
    }
    if (!options.replay.empty()) {
      model::LoadOptions load;
      load.models_dir = options.models_dir;
      load.overlays = {options.replay};
      const model::MachineDescription replayed = model::LoadMachineDescription(
          model::ResolveMachineDescription(options.machine, options.models_dir), load);
      const generated::MachineFunctions& replay_functions = machines::MachineFunctionsFor(replayed);
      std::vector<ReplayResult> replays;
      out << "plant replay of " << replayed.name << " with " << options.replay << "\n"
          << "  log                                 angle RMS  2 s after onset  start\n";
      double worst = 0;
      for (const auto& [a, group] : by_actuator) {
        for (const HydraulicLog& log : group) {
          progress("replaying " + log.file);
          StepEventOptions events;
          events.joint_sense = JointSense(replayed, replay_functions, a);
          replays.push_back(ReplayOnPlant(replayed, replay_functions, a, log, events));
          const ReplayResult& r = replays.back();
          char onset[32] = "           -";  // no motion onset in the command's direction
          if (!std::isnan(r.angle_rms_onset)) {
            std::snprintf(onset, sizeof onset, "%8.2f deg",
                          r.angle_rms_onset * 180 / std::numbers::pi);
          }
          char line[256];
          std::snprintf(line, sizeof line, "  %-34s %7.2f deg  %12s    %s\n",
                        std::filesystem::path(r.file).filename().string().c_str(),
                        r.angle_rms * 180 / std::numbers::pi, onset,
                        r.start_clamped ? "clamped into the joint range" : "as logged");
          out << line;
          if (r.opposite_sense) {
            out << "    the plant's joint moves the other way: the log's angle runs against "
                   "the description's joint (negate joint_angle, or the command, for it)\n";
          }
          worst = std::max(worst, r.angle_rms);
        }
      }
      const std::string png =
          options.png.empty() ? options.logs.front() + ".replay.png" : options.png;
      WriteReplayPlot(replays, png);
      out << "worst angle RMS " << worst * 180 / std::numbers::pi << " deg\nfigure: " << png
          << "\n";
      return 0;
    }
    if (options.model == "chain") {
      return RunChain(options, machine, *functions, by_actuator, rows, read_seconds, start,
                      progress, out);
    }
    HydraulicIdentificationOptions fit_options;
    fit_options.cross_validate = options.cross_validate;
    fit_options.exclude_end_stops = options.exclude_end_stops;
    std::vector<ActuatorIdentification> results;
    for (const auto& [a, group] : by_actuator) {
      const std::string actuator = machine.hydraulics.actuators[a].name;
      fit_options.progress = [&](const std::string& line) { progress(actuator + ": " + line); };
      results.push_back(IdentifyActuator(machine, *functions, a, group, fit_options));
    }
    const double fit_seconds = Seconds(start) - read_seconds;
    progress("fitted");

    out << "hydraulic identification of " << machine.name << " from " << options.logs.size()
        << " log" << (options.logs.size() == 1 ? "" : "s") << "\n";
    for (const ActuatorIdentification& r : results) PrintTable(r, out);
    out << Throughput(rows, read_seconds, fit_seconds);

    std::string command_line = kName;
    // Name a few logs; a campaign of many would make the comment unreadable.
    for (std::size_t i = 0; i < options.logs.size() && i < 3; ++i) {
      command_line += " " + options.logs[i];
    }
    if (options.logs.size() > 3) {
      command_line += " … (" + std::to_string(options.logs.size()) + " logs)";
    }
    command_line += " --machine " + machine.name;
    const std::string overlay =
        options.overlay.empty() ? options.logs.front() + ".overlay.yaml" : options.overlay;
    const std::string png =
        options.png.empty() ? options.logs.front() + ".residuals.png" : options.png;
    WriteResidualPlot(results, png);
    WriteFileAtomically(overlay, OverlayText(machine, results, command_line));
    out << "overlay: " << overlay << "\nresiduals: " << png << "\n";
    return 0;
  } catch (const core::InputError& e) {
    // The located refusal alone: a refused input never writes anything, so saying so is noise.
    err << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    err << kName << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << kName << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace autoshovel::identification
