#include "identification/hydraulics/chain_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <sstream>
#include <vector>

#include "identification/hydraulics/residual_plot.h"
#include "identification/hydraulics/valve_chain_model.h"
#include "identification/hydraulics/valve_model.h"
#include "runtime/plot/line_plot.h"

namespace autoshovel::identification {

namespace {

constexpr double kDeg = 180 / 3.141592653589793;
constexpr double kMs = 1e3;

// A direction's identified joint rate at duty u [rad/s]: its flow characteristic up to the
// highest level logged; beyond it, not known, extended along its last secant (from the previous
// knot, or the dead band) rather than held flat, which would claim a saturation nobody saw.
double Characteristic(const DirectionFit& d, double u) {
  std::vector<double> rates;
  for (const Estimate& e : d.rates) rates.push_back(e.value);
  if (rates.empty()) return 0.0;
  const double last = d.levels.back();
  if (u <= last) return Opening<double>(u, d.dead_band.value, d.levels, rates);
  const double before = d.levels.size() > 1 ? d.levels[d.levels.size() - 2] : d.dead_band.value;
  const double rate_before = d.levels.size() > 1 ? rates[rates.size() - 2] : 0.0;
  const double slope = last > before ? (rates.back() - rate_before) / (last - before) : 0.0;
  return rates.back() + slope * (u - last);
}

}  // namespace

double FullOpeningRate(const DirectionFit& direction) {
  if (direction.rates.empty() || !(direction.rates.back().value > 0)) return 0.0;
  return Characteristic(direction, 1.0);
}

void AssignPlantFlow(NamedChain& result, const model::MachineDescription& machine,
                     const generated::MachineFunctions& functions, int actuator) {
  constexpr double kLpm = 1e-3 / 60;  // m³/s per l/min
  const ActuatorKinematics kinematics(machine, functions, actuator);
  std::vector<double> flows;
  std::string note = "l/min at full duty:";
  for (const DirectionFit& d : result.chain.directions) {
    const double lever = std::abs(kinematics.Lever(d.angle_center));
    const double area = d.sign > 0 ? kinematics.area_extend() : kinematics.area_retract();
    const double rate = FullOpeningRate(d);
    flows.push_back(rate * area * lever / kLpm);
    char part[200];
    std::snprintf(part, sizeof part,
                  "%s %s %.2f deg/s x %s area x lever %.3f m/rad at %.1f deg = %.1f",
                  flows.size() > 1 ? ";" : "", d.sign > 0 ? "extending" : "retracting", rate * kDeg,
                  d.sign > 0 ? "cap" : "annulus", lever, d.angle_center * kDeg, flows.back());
    note += part;
  }
  result.rated_flow_lpm = 0;
  result.opening_scale.clear();
  if (flows.empty()) return;
  result.rated_flow_lpm = *std::max_element(flows.begin(), flows.end());
  for (const double q : flows) {
    result.opening_scale.push_back(result.rated_flow_lpm > 0 ? q / result.rated_flow_lpm : 1.0);
  }
  result.rated_flow_note = note;
}

namespace {

// "  71 ms [ 64,  80]" or "at bound" / "held".
std::string Cell(const Estimate& e, double scale, const char* format) {
  char text[96];
  if (e.fixed) {
    std::snprintf(text, sizeof text, format, e.value * scale);
    return std::string(text) + "  (held)";
  }
  std::snprintf(text, sizeof text, format, e.value * scale);
  std::string cell = text;
  if (e.at_bound) return cell + "  AT BOUND (no interval)";
  char interval[128];
  char f2[64];
  std::snprintf(f2, sizeof f2, "  [%s, %s]", format, format);
  std::snprintf(interval, sizeof interval, f2, e.low * scale, e.high * scale);
  cell += interval;
  if (e.sigma > 0) {
    char sigma[64];
    std::snprintf(sigma, sizeof sigma, "  J-sigma %.3g", e.sigma * scale);
    cell += sigma;
  }
  return cell;
}

std::string Base(const std::string& file) {
  return std::filesystem::path(file).filename().string();
}

}  // namespace

void PrintChainTable(const NamedChain& result, std::ostream& out) {
  char line[256];
  for (const DirectionFit& d : result.chain.directions) {
    out << result.actuator << ", " << (d.sign > 0 ? "positive" : "negative")
        << " commands: " << d.files.size() << " logs, duty levels";
    for (double level : d.levels) out << " " << std::lround(level * 100);
    out << " %  (" << d.seconds << " s)\n";
    out << "  parameter                value  [bootstrap 5-95 %]\n";
    if (d.has_pilot) {
      out << "  command -> pilot delay   " << Cell(d.pilot_delay, kMs, "%6.1f") << " ms\n";
      out << "  pilot lag                " << Cell(d.pilot_time_constant, kMs, "%6.1f") << " ms\n";
      out << "  pilot gain               " << Cell(d.pilot_gain, 1, "%6.2f") << " bar/unit\n";
      out << "  pilot threshold          " << Cell(d.pilot_threshold, 100, "%6.1f") << " %\n";
    } else {
      out << "  pilot lag (no pilot log) " << Cell(d.pilot_time_constant, kMs, "%6.1f") << " ms\n";
    }
    out << "  pilot -> motion delay    " << Cell(d.motion_delay, kMs, "%6.1f") << " ms\n";
    out << "  motion lag               " << Cell(d.motion_lag, kMs, "%6.1f") << " ms\n";
    out << "  motion lag growth        " << Cell(d.motion_lag_slope, kMs, "%6.1f")
        << " ms at full opening\n";
    out << "  dead band                " << Cell(d.dead_band, 100, "%6.1f") << " %\n";
    out << "  load coefficient kappa   " << Cell(d.load_coefficient, 1, "%6.3f") << "\n";
    out << "  first supply capacity    " << Cell(d.supply_capacity, kDeg, "%6.2f") << " deg/s\n";
    out << "  late supply delay, lag   " << Cell(d.supply_delay, kMs, "%6.0f") << " ms;  "
        << Cell(d.supply_lag, kMs, "%6.0f") << " ms\n";
    out << "  angle gain c1, c2        " << Cell(d.gain_linear, 1, "%6.3f") << ";  "
        << Cell(d.gain_quadratic, 1, "%6.3f") << "\n";
    out << "  flow characteristic (steady joint rate at the centre angle, mean load):\n";
    for (std::size_t j = 0; j < d.levels.size(); ++j) {
      std::snprintf(line, sizeof line, "    %4.0f %%  ", d.levels[j] * 100);
      out << line << Cell(d.rates[j], kDeg, "%7.3f") << " deg/s\n";
    }
    std::snprintf(line, sizeof line, "  residual RMS: angle %.3f deg%s", d.angle_sigma * kDeg,
                  d.has_pilot ? "" : "\n");
    out << line;
    if (d.has_pilot) {
      std::snprintf(line, sizeof line, ", pilot %.2f bar\n", d.pilot_sigma);
      out << line;
    }
    for (const std::string& note : d.notes) out << "  note: " << note << "\n";
    out << "  delay per duty level (each stage refitted on that level alone, the rest held):\n"
           "     level  logs  cmd->pilot  cmd->motion  threshold 0.3 deg\n";
    for (const LevelDelay& l : d.level_delays) {
      char pilot[32];
      if (std::isnan(l.pilot_delay)) {
        std::snprintf(pilot, sizeof pilot, "%10s", "-");
      } else {
        std::snprintf(pilot, sizeof pilot, "%7.0f ms", l.pilot_delay * kMs);
      }
      std::snprintf(line, sizeof line, "    %4.0f %%  %4zu  %s  %8.0f ms  %10.0f ms\n",
                    l.level * 100, l.files, pilot, l.motion_delay * kMs, l.threshold_motion * kMs);
      out << line;
    }
    out << "  per log:                          used/rows  stalled  relief seen  angle RMS  "
           "2 s after onset  rate R2  pilot RMS\n";
    for (const FileReport& f : d.files) {
      std::snprintf(
          line, sizeof line,
          "    %-30s %6zu/%-6zu %6zu  %7.0f bar  %6.3f deg  %9.3f deg  %7.3f  %6.2f bar\n",
          Base(f.file).c_str(), f.used, f.samples, f.stalled, f.relief_seen / 1e5,
          f.angle_rms * kDeg, f.angle_rms_onset * kDeg, f.rate_r2, f.pilot_rms);
      out << line;
    }
    if (!d.leave_one_level_out.empty()) {
      out << "  leave one duty level out (fit the others, predict this level from its start "
             "angle):\n";
      for (const Prediction& p : d.leave_one_level_out) {
        std::snprintf(line, sizeof line,
                      "    %-6s  %zu logs  angle RMS 2 s after onset %.3f deg (worst log), "
                      "whole motion %.3f deg\n",
                      p.label.c_str(), p.files.size(), p.angle_rms_onset * kDeg,
                      p.angle_rms * kDeg);
        out << line;
      }
    }
    for (const Prediction& p : d.load_transfer) {
      std::snprintf(line, sizeof line,
                    "  %s: %zu logs predicted, angle RMS 2 s after onset %.3f deg (worst), "
                    "whole motion %.3f deg\n",
                    p.label.c_str(), p.files.size(), p.angle_rms_onset * kDeg, p.angle_rms * kDeg);
      out << line;
    }
  }
}

void WriteChainPlot(const std::vector<NamedChain>& results, const std::string& path) {
  std::vector<plot::LinePlot> panels;
  auto series = [](const std::string& name, const std::vector<double>& t,
                   const std::vector<double>& y, double scale, plot::Color color) {
    plot::PlotSeries s{name, {}, {}, color, 1, false, false};
    for (std::size_t i = 0; i < t.size() && i < y.size(); ++i) {
      if (std::isnan(y[i])) continue;
      s.x.push_back(t[i]);
      s.y.push_back(y[i] * scale);
    }
    return s;
  };
  for (const NamedChain& r : results) {
    for (const DirectionFit& d : r.chain.directions) {
      for (const FileReport& f : d.files) {
        char title[160];
        std::snprintf(title, sizeof title, "%s: %s, RMS %.2f deg, R2 %.3f", r.actuator.c_str(),
                      Base(f.file).c_str(), f.angle_rms * kDeg, f.rate_r2);
        plot::LinePlot angle = TimePanel(title, "joint angle [deg]");
        angle.series = {series("measured", f.time, f.angle, kDeg, plot::kGrey),
                        series("chain model", f.time, f.angle_fit, kDeg, plot::kRed)};
        plot::PlotSeries left{"left out (stall, override)", {}, {}, plot::kOrange, 1, false, true};
        for (std::size_t i = 0; i < f.excluded.size(); ++i) {
          if (!f.excluded[i]) continue;
          left.x.push_back(f.time[i]);
          left.y.push_back(f.angle[i] * kDeg);
        }
        if (!left.x.empty()) angle.series.push_back(left);
        panels.push_back(angle);
        plot::LinePlot pilot = TimePanel("pilot pressure", "pilot [bar]");
        if (!f.pilot.empty()) {
          pilot.series = {series("measured", f.time, f.pilot, 1, plot::kGrey),
                          series("chain model", f.time, f.pilot_fit, 1, plot::kRed)};
        }
        panels.push_back(pilot);
      }
    }
  }
  if (!panels.empty()) plot::WriteLinePlotGridPng(panels, 2, path);
}

std::string ChainOverlayText(const std::string& header, const std::vector<NamedChain>& results) {
  std::ostringstream text;
  text << header << "hydraulics:\n  actuators:\n";
  char line[256];
  for (const NamedChain& r : results) {
    const auto& dirs = r.chain.directions;
    if (dirs.empty()) continue;
    text << "    - name: " << r.actuator << "\n";
    auto mean = [&](auto member) {
      double sum = 0;
      for (const DirectionFit& d : dirs) sum += (d.*member).value;
      return sum / static_cast<double>(dirs.size());
    };
    auto each = [&](auto member, double scale) {
      std::string s;
      for (const DirectionFit& d : dirs) {
        std::snprintf(line, sizeof line, "%s%s %.1f", s.empty() ? "" : ", ",
                      d.sign > 0 ? "positive" : "negative", (d.*member).value * scale);
        s += line;
      }
      return s;
    };
    const bool pilot =
        std::all_of(dirs.begin(), dirs.end(), [](const DirectionFit& d) { return d.has_pilot; });
    if (pilot) {
      std::snprintf(
          line, sizeof line, "      pilot_delay: %.4f          # s, command -> pilot (ms: %s)\n",
          mean(&DirectionFit::pilot_delay), each(&DirectionFit::pilot_delay, 1e3).c_str());
      text << line;
    }
    std::snprintf(line, sizeof line, "      pilot_time_constant: %.4f  # s (ms: %s)\n",
                  mean(&DirectionFit::pilot_time_constant),
                  each(&DirectionFit::pilot_time_constant, 1e3).c_str());
    text << line;
    std::snprintf(
        line, sizeof line, "      transport_delay: %.4f      # s, pilot -> motion (ms: %s)\n",
        mean(&DirectionFit::motion_delay), each(&DirectionFit::motion_delay, 1e3).c_str());
    text << line;
    std::snprintf(line, sizeof line, "      spool_time_constant: %.4f  # s, motion lag (ms: %s)\n",
                  std::max(1e-3, mean(&DirectionFit::motion_lag)),
                  each(&DirectionFit::motion_lag, 1e3).c_str());
    text << line;
    if (r.rated_flow_lpm > 0) {
      std::snprintf(line, sizeof line, "      rated_flow_lpm: %.1f         # %s\n",
                    r.rated_flow_lpm, r.rated_flow_note.c_str());
      text << line;
    }
    if (dirs.size() == 2)
      text << "      dead_zone: 0                # the opening curves hold the dead bands\n";
    for (std::size_t k = 0; k < dirs.size(); ++k) {
      const DirectionFit& d = dirs[k];
      const double top = FullOpeningRate(d);
      if (!(top > 0)) continue;
      const double share = k < r.opening_scale.size() ? r.opening_scale[k] : 1.0;
      text << "      opening_curve_" << (d.sign > 0 ? "extend" : "retract") << ": [";
      std::vector<double> duties = {d.dead_band.value};
      for (double u = std::floor(d.dead_band.value * 20 + 1) / 20; u <= 1.0 + 1e-9; u += 0.05) {
        if (u > duties.back() + 1e-6) duties.push_back(std::min(u, 1.0));
      }
      double previous = 0;
      for (std::size_t i = 0; i < duties.size(); ++i) {
        const double opening =
            i == 0 ? 0.0 : std::max(previous, share * Characteristic(d, duties[i]) / top);
        previous = opening;
        std::snprintf(line, sizeof line, "%s[%.3f, %.4f]", i == 0 ? "" : ", ", duties[i],
                      std::min(opening, 1.0));
        text << line;
      }
      text << "]\n";
      std::snprintf(line, sizeof line,
                    "      # %s commands, not in the plant: joint rate at the highest level logged "
                    "%.2f deg/s; first "
                    "supply %.2f deg/s, the rest %.0f ms late (lag %.0f ms); motion lag + %.0f ms "
                    "at full opening; angle gain c1 %.3f "
                    "c2 %.3f; load coefficient %.3f\n",
                    d.sign > 0 ? "positive" : "negative", d.rates.back().value * kDeg,
                    d.supply_capacity.value * kDeg, d.supply_delay.value * kMs,
                    d.supply_lag.value * kMs, d.motion_lag_slope.value * kMs, d.gain_linear.value,
                    d.gain_quadratic.value, d.load_coefficient.value);
      text << line;
    }
  }
  return text.str();
}

}  // namespace autoshovel::identification
