#include "identification/hydraulics/residual_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace autoshovel::identification {

namespace {

constexpr int kPanelWidth = 420, kPanelHeight = 170, kMargin = 46, kTitle = 22;
const cv::Scalar kMeasured(150, 150, 150), kFitted(30, 30, 220), kResidual(200, 90, 20),
    kExcluded(0, 200, 255), kText(20, 20, 20), kAxis(90, 90, 90);

struct Series {
  const std::vector<double>* y;
  cv::Scalar color;
};

// One panel: series against time in a box at (x0, y0), with the y range and a label.
void Panel(cv::Mat& image, int x0, int y0, const std::vector<double>& t,
           const std::vector<Series>& series, const std::vector<char>& excluded,
           const std::string& label, double scale) {
  const int w = kPanelWidth - kMargin - 8, h = kPanelHeight - kTitle - 18;
  const int left = x0 + kMargin, top = y0 + kTitle;
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const Series& s : series) {
    for (double v : *s.y) {
      if (std::isfinite(v)) low = std::min(low, v * scale), high = std::max(high, v * scale);
    }
  }
  if (!std::isfinite(low)) low = -1, high = 1;
  if (high - low < 1e-9) low -= 0.5, high += 0.5;
  const double pad = 0.05 * (high - low);
  low -= pad, high += pad;
  const double t0 = t.front(), t1 = std::max(t.back(), t.front() + 1e-9);
  auto px = [&](double time) { return left + static_cast<int>((time - t0) / (t1 - t0) * w); };
  auto py = [&](double v) { return top + static_cast<int>((high - v) / (high - low) * h); };
  cv::rectangle(image, {left, top}, {left + w, top + h}, kAxis, 1);
  for (std::size_t i = 0; i < excluded.size(); ++i) {
    if (excluded[i]) cv::line(image, {px(t[i]), top + h - 4}, {px(t[i]), top + h}, kExcluded, 2);
  }
  if (low < 0 && high > 0) {
    cv::line(image, {left, py(0)}, {left + w, py(0)}, cv::Scalar(220, 220, 220), 1);
  }
  for (const Series& s : series) {
    std::vector<cv::Point> run;
    auto flush = [&] {
      if (run.size() > 1) cv::polylines(image, run, false, s.color, 1, cv::LINE_AA);
      run.clear();
    };
    for (std::size_t i = 0; i < t.size() && i < s.y->size(); ++i) {
      const double v = (*s.y)[i];
      if (!std::isfinite(v)) {
        flush();
        continue;
      }
      run.emplace_back(px(t[i]), py(v * scale));
    }
    flush();
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.3g", high);
  cv::putText(image, text, {x0 + 2, top + 10}, cv::FONT_HERSHEY_PLAIN, 0.8, kText);
  std::snprintf(text, sizeof text, "%.3g", low);
  cv::putText(image, text, {x0 + 2, top + h}, cv::FONT_HERSHEY_PLAIN, 0.8, kText);
  std::snprintf(text, sizeof text, "%.2f s", t1);
  cv::putText(image, text, {left + w - 40, top + h + 14}, cv::FONT_HERSHEY_PLAIN, 0.8, kText);
  cv::putText(image, label, {left, y0 + kTitle - 6}, cv::FONT_HERSHEY_PLAIN, 0.9, kText);
}

}  // namespace

void WriteResidualPlot(const std::vector<ActuatorIdentification>& results,
                       const std::string& path) {
  int rows = 0;
  bool any_spool = false;
  for (const auto& r : results) {
    rows += static_cast<int>(r.files.size());
    any_spool |= r.has_spool;
  }
  const int columns = any_spool ? 3 : 2;
  cv::Mat image(std::max(rows, 1) * kPanelHeight + 30, columns * kPanelWidth, CV_8UC3,
                cv::Scalar(255, 255, 255));
  cv::putText(image,
              "grey: measured, red: fitted, blue: angle residual, orange ticks: end stop "
              "(left out)",
              {8, 18}, cv::FONT_HERSHEY_PLAIN, 1.0, kText);
  const double deg = 180 / std::numbers::pi;
  int row = 0;
  for (const auto& r : results) {
    for (const FileFit& f : r.files) {
      const int y0 = 30 + row * kPanelHeight;
      const std::string name = std::filesystem::path(f.file).filename().string();
      std::vector<double> residual(f.angle.size());
      for (std::size_t i = 0; i < residual.size(); ++i) residual[i] = f.angle_fit[i] - f.angle[i];
      char label[200];
      std::snprintf(label, sizeof label, "%s: %s [deg]", r.actuator.c_str(), name.c_str());
      Panel(image, 0, y0, f.time, {{&f.angle, kMeasured}, {&f.angle_fit, kFitted}}, f.excluded,
            label, deg);
      std::snprintf(label, sizeof label, "angle residual [deg], RMS %.3f", f.angle_rms * deg);
      Panel(image, (columns - 1) * kPanelWidth, y0, f.time, {{&residual, kResidual}}, f.excluded,
            label, deg);
      if (!f.spool.empty()) {
        std::snprintf(label, sizeof label, "spool [%%], RMS %.2f %%", f.spool_rms * 100);
        Panel(image, kPanelWidth, y0, f.time, {{&f.spool, kMeasured}, {&f.spool_fit, kFitted}}, {},
              label, 100);
      }
      ++row;
    }
  }
  const std::string temporary = path + ".tmp.png";
  if (!cv::imwrite(temporary, image)) throw std::runtime_error("cannot write " + temporary);
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    throw std::runtime_error("cannot replace " + path);
  }
}

}  // namespace autoshovel::identification
