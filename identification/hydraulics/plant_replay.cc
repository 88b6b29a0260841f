#include "identification/hydraulics/plant_replay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "identification/hydraulics/plant_logs.h"
#include "identification/hydraulics/residual_plot.h"
#include "runtime/plot/line_plot.h"

namespace autoshovel::identification {

namespace {
constexpr double kDeg = 180 / 3.141592653589793;
constexpr double kOnsetWindow = 2.0;  // [s], as the fit's validation
}  // namespace

ReplayResult ReplayOnPlant(const model::MachineDescription& machine,
                           const generated::MachineFunctions& functions, int actuator,
                           const HydraulicLog& log, const StepEventOptions& event_options) {
  ReplayResult result;
  result.file = log.file;
  if (log.size() < 2) return result;
  const double t0 = log.time.front();
  // The command held from row to row, as the controller that logged it held it.
  auto command = [&](double t) {
    const double at = t0 + t;
    const auto it = std::upper_bound(log.time.begin(), log.time.end(), at + 1e-9);
    const std::size_t k =
        it == log.time.begin() ? 0 : static_cast<std::size_t>(it - log.time.begin()) - 1;
    return log.command[k];
  };
  PlantLogOptions options;
  options.rate = (static_cast<double>(log.size()) - 1) / (log.time.back() - t0);
  options.noise = false;
  options.start_angle = log.joint_angle.front();
  const int joint = functions.actuator_joint[actuator];
  if (joint < static_cast<int>(machine.num_links())) {
    const model::Link& link = machine.links[static_cast<std::size_t>(joint)];
    result.start_clamped =
        log.joint_angle.front() < link.joint_min || log.joint_angle.front() > link.joint_max;
  }
  const HydraulicLog simulated =
      SimulatePlantLog(machine, functions, actuator, command, log.time.back() - t0, options);
  const LogEvents events = DetectStepEvents(log, event_options);
  const std::size_t n = std::min(log.size(), simulated.size());
  double all = 0, onset = 0;
  std::size_t n_all = 0, n_onset = 0;
  for (std::size_t k = 0; k < n; ++k) {
    result.time.push_back(log.time[k] - t0);
    result.measured.push_back(log.joint_angle[k] - log.joint_angle.front());
    result.simulated.push_back(simulated.joint_angle[k] - simulated.joint_angle.front());
    result.excluded.push_back(events.excluded[k]);
    if (events.excluded[k]) continue;
    const double e = result.simulated.back() - result.measured.back();
    all += e * e, ++n_all;
    for (const CommandStep& step : events.steps) {
      if (step.onset == static_cast<std::size_t>(-1)) continue;
      if (k >= step.onset && log.time[k] - log.time[step.onset] <= kOnsetWindow) {
        onset += e * e, ++n_onset;
        break;
      }
    }
  }
  for (const CommandStep& step : events.steps) {
    const std::size_t last = std::min(step.off, n) - 1;
    const double measured = log.joint_angle[last] - log.joint_angle[step.on];
    const double replayed = simulated.joint_angle[last] - simulated.joint_angle[step.on];
    if (std::abs(measured) > 0.02 && std::abs(replayed) > 0.02) {
      result.opposite_sense = measured * replayed < 0;
      break;
    }
  }
  result.angle_rms = n_all ? std::sqrt(all / n_all) : 0.0;
  result.angle_rms_onset =
      n_onset ? std::sqrt(onset / n_onset) : std::numeric_limits<double>::quiet_NaN();
  return result;
}

void WriteReplayPlot(const std::vector<ReplayResult>& results, const std::string& path) {
  std::vector<plot::LinePlot> panels;
  for (const ReplayResult& r : results) {
    char title[200];
    std::snprintf(title, sizeof title, "%s: RMS %.2f deg (2 s after onset %.2f)",
                  std::filesystem::path(r.file).filename().string().c_str(), r.angle_rms * kDeg,
                  r.angle_rms_onset * kDeg);
    plot::LinePlot p = TimePanel(title, "angle change [deg]");
    plot::PlotSeries measured{"measured", r.time, {}, plot::kGrey, 1, false, false};
    plot::PlotSeries simulated{"plant replay", r.time, {}, plot::kRed, 1, false, false};
    plot::PlotSeries left{"left out (stall)", {}, {}, plot::kOrange, 1, false, true};
    for (std::size_t k = 0; k < r.time.size(); ++k) {
      measured.y.push_back(r.measured[k] * kDeg);
      simulated.y.push_back(r.simulated[k] * kDeg);
      if (r.excluded[k]) {
        left.x.push_back(r.time[k]);
        left.y.push_back(r.measured[k] * kDeg);
      }
    }
    p.series = {measured, simulated};
    if (!left.x.empty()) p.series.push_back(left);
    panels.push_back(p);
  }
  if (!panels.empty()) plot::WriteLinePlotGridPng(panels, 2, path);
}

}  // namespace autoshovel::identification
