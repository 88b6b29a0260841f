#include "runtime/results/plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

namespace autoshovel::results {

using plot::Color;
using plot::kBlue;
using plot::kGreen;
using plot::kGrey;
using plot::kOrange;
using plot::kRed;
using plot::LinePlot;
using plot::PlotSeries;
using plot::WriteLinePlotPng;

void WriteVolumePlotPng(const CycleRecord& cycle, double target_volume_m3,
                        const std::filesystem::path& path) {
  LinePlot plot;
  plot.title = "Cycle " + std::to_string(cycle.cycle) + ": bucket volume while crowding";
  plot.x_label = "time since cycle start [s]";
  plot.y_label = "volume [m^3]";
  plot.y_from_zero = true;
  PlotSeries v1{"V1 (estimated, Eq. 19)", {}, {}, kBlue, 2, false, false};
  PlotSeries v1v2{"V1 + V2 x intake factor (predicted)", {}, {}, kOrange, 2, true, false};
  for (const CycleSample& s : cycle.samples) {
    v1.x.push_back(s.t);
    v1.y.push_back(s.v1);
    v1v2.x.push_back(s.t);
    v1v2.y.push_back(s.v1v2);
  }
  plot.series = {v1, v1v2};
  char label[64];
  if (std::isfinite(cycle.trigger_time_s)) {
    std::snprintf(label, sizeof(label), "trigger %.2f s", cycle.trigger_time_s);
    plot.vertical.push_back({cycle.trigger_time_s, label, kRed, true});
  }
  if (std::isfinite(target_volume_m3)) {
    std::snprintf(label, sizeof(label), "target %.2f m^3", target_volume_m3);
    plot.horizontal.push_back({target_volume_m3, label, kGreen, true});
  }
  WriteLinePlotPng(plot, path);
}

void WriteTipPathPlotPng(const CycleRecord& cycle, const std::filesystem::path& path) {
  LinePlot plot;
  plot.title = "Cycle " + std::to_string(cycle.cycle) + ": bucket tip path";
  plot.x_label = "x, vehicle frame [m]";
  plot.y_label = "z [m]";
  plot.equal_aspect = true;
  PlotSeries predicted{"predicted", {}, {}, kOrange, 2, true, false};
  PlotSeries actual{"actual", {}, {}, kBlue, 2, false, false};
  for (const CycleSample& s : cycle.samples) {
    predicted.x.push_back(s.predicted_tip_x);
    predicted.y.push_back(s.predicted_tip_z);
    actual.x.push_back(s.actual_tip_x);
    actual.y.push_back(s.actual_tip_z);
  }
  plot.series = {actual, predicted};
  WriteLinePlotPng(plot, path);
}

void WriteFillRatePlotPng(const std::vector<CycleRecord>& cycles,
                          const std::filesystem::path& path) {
  LinePlot plot;
  plot.title = "Fill rate per cycle";
  plot.x_label = "cycle";
  plot.y_label = "fill rate [%]";
  plot.y_from_zero = true;
  plot.horizontal.push_back({100.0, "rated capacity", kGrey, true});
  std::map<std::string, PlotSeries> by_strategy;
  const Color palette[] = {kBlue, kOrange, kGreen, kRed, kGrey};
  for (const CycleRecord& c : cycles) {
    auto [it, inserted] = by_strategy.try_emplace(c.strategy);
    PlotSeries& s = it->second;
    if (inserted) {
      s.name = c.strategy.empty() ? "(no strategy)" : c.strategy;
      s.color = palette[(by_strategy.size() - 1) % std::size(palette)];
      s.markers = true;
    }
    s.x.push_back(c.cycle);
    s.y.push_back(100.0 * c.fill_rate);
  }
  for (auto& [name, s] : by_strategy) plot.series.push_back(std::move(s));
  WriteLinePlotPng(plot, path);
}

bool WriteTravelPredictionPlotPng(const std::vector<CrowdingSample>& samples,
                                  const std::filesystem::path& path) {
  // A NaN after each point breaks the line: dots only.
  PlotSeries dots{"", {}, {}, kBlue, 2, false, true};
  double lo = INFINITY, hi = -INFINITY;
  int n = 0;
  for (const CrowdingSample& c : samples) {
    if (!std::isfinite(c.predicted_penetration) || !std::isfinite(c.penetration)) continue;
    dots.x.insert(dots.x.end(), {c.predicted_penetration, NAN});
    dots.y.insert(dots.y.end(), {c.penetration, NAN});
    lo = std::min({lo, c.predicted_penetration, c.penetration});
    hi = std::max({hi, c.predicted_penetration, c.penetration});
    ++n;
  }
  if (n == 0) return false;
  dots.name = "cycles (" + std::to_string(n) + ")";
  // The reference lines span the data and a margin, from 0 when no travel is negative.
  lo = lo >= 0 ? std::max(0.0, lo - 0.25) : lo - 0.25;
  hi += 0.25;
  LinePlot plot;
  plot.title = kTravelPredictionTitle;
  plot.x_label = "predicted at the trigger [m]";
  plot.y_label = "actual travel [m]";
  plot.equal_aspect = true;
  plot.series.push_back({"y = x", {lo, hi}, {lo, hi}, kGrey, 1, false, false});
  for (const double band : {0.10, 0.20}) {
    const Color color = band < 0.15 ? kGreen : kOrange;
    char name[32];
    std::snprintf(name, sizeof(name), "+/- %.2f m", band);
    plot.series.push_back({name, {lo, hi}, {lo + band, hi + band}, color, 1, true, false});
    plot.series.push_back({"", {lo, hi}, {lo - band, hi - band}, color, 1, true, false});
  }
  plot.series.push_back(std::move(dots));
  WriteLinePlotPng(plot, path);
  return true;
}

}  // namespace autoshovel::results
