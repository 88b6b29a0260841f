#include "identification/hydraulics/residual_plot.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "runtime/plot/line_plot.h"

namespace autoshovel::identification {

namespace {

constexpr double kDeg = 180 / std::numbers::pi;

plot::PlotSeries Series(const std::string& name, const std::vector<double>& t,
                        const std::vector<double>& y, double scale, plot::Color color) {
  plot::PlotSeries s{name, t, {}, color, 1, false, false};
  s.y.reserve(y.size());
  for (double v : y) s.y.push_back(v * scale);
  return s;
}

}  // namespace

plot::LinePlot TimePanel(const std::string& title, const std::string& y_label) {
  plot::LinePlot p;
  p.title = title;
  p.x_label = "t [s]";
  p.y_label = y_label;
  p.width_px = 560;
  p.height_px = 300;
  return p;
}

void WriteResidualPlot(const std::vector<ActuatorIdentification>& results,
                       const std::string& path) {
  bool any_spool = false;
  for (const auto& r : results) any_spool |= r.has_spool;
  const int columns = any_spool ? 3 : 2;
  std::vector<plot::LinePlot> panels;
  for (const auto& r : results) {
    for (const FileFit& f : r.files) {
      const std::string name = std::filesystem::path(f.file).filename().string();
      plot::LinePlot angle = TimePanel(r.actuator + ": " + name, "joint angle [deg]");
      angle.series = {Series("measured", f.time, f.angle, kDeg, plot::kGrey),
                      Series("fitted", f.time, f.angle_fit, kDeg, plot::kRed)};
      // Samples left out at an end stop: dots on the measured angle.
      plot::PlotSeries excluded{"end stop (left out)", {}, {}, plot::kOrange, 1, false, true};
      for (std::size_t i = 0; i < f.excluded.size() && i < f.angle.size(); ++i) {
        if (!f.excluded[i]) continue;
        excluded.x.push_back(f.time[i]);
        excluded.y.push_back(f.angle[i] * kDeg);
      }
      if (!excluded.x.empty()) angle.series.push_back(excluded);
      panels.push_back(angle);
      if (any_spool) {
        char title[96];
        std::snprintf(title, sizeof title, "spool, RMS %.2f %%", f.spool_rms * 100);
        plot::LinePlot spool = TimePanel(title, "spool [%]");
        if (!f.spool.empty()) {
          spool.series = {Series("measured", f.time, f.spool, 100, plot::kGrey),
                          Series("fitted", f.time, f.spool_fit, 100, plot::kRed)};
        }
        panels.push_back(spool);
      }
      std::vector<double> residual(f.angle.size());
      for (std::size_t i = 0; i < residual.size(); ++i) residual[i] = f.angle_fit[i] - f.angle[i];
      char title[96];
      std::snprintf(title, sizeof title, "angle residual, RMS %.3f deg", f.angle_rms * kDeg);
      plot::LinePlot residual_panel = TimePanel(title, "fitted - measured [deg]");
      residual_panel.series = {Series("", f.time, residual, kDeg, plot::kBlue)};
      panels.push_back(residual_panel);
    }
  }
  plot::WriteLinePlotGridPng(panels, columns, path);
}

}  // namespace autoshovel::identification
