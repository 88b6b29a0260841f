#include "runtime/plot/bar_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "runtime/plot/image_file.h"

namespace autoshovel::plot {

namespace {

cv::Mat DrawBarChart(const BarChart& chart) {
  const int width = std::max(
      480, 90 + 60 * static_cast<int>(chart.groups.size()) * std::max<int>(1, chart.series.size()));
  const int height = 360, left = 70, right = 20, top = 50, bottom = 70;
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  double lo = 0, hi = 0;
  for (const BarSeries& s : chart.series) {
    for (double v : s.values) {
      if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    }
  }
  if (hi - lo < 1e-12) hi = lo + 1;
  const double span = hi - lo;
  lo -= 0.05 * span, hi += 0.05 * span;
  const int plot_h = height - top - bottom;
  auto y_of = [&](double v) { return top + static_cast<int>((hi - v) / (hi - lo) * plot_h); };
  const cv::Scalar ink(40, 40, 40), grid(225, 225, 225);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  // Horizontal grid with values.
  for (int k = 0; k <= 4; ++k) {
    const double v = lo + (hi - lo) * k / 4;
    const int y = y_of(v);
    cv::line(image, {left, y}, {width - right, y}, grid, 1);
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    cv::putText(image, text, {4, y + 4}, font, 0.4, ink, 1, cv::LINE_AA);
  }
  cv::line(image, {left, y_of(0)}, {width - right, y_of(0)}, ink, 1);
  cv::putText(image, chart.title, {left, 22}, font, 0.55, ink, 1, cv::LINE_AA);
  cv::putText(image, chart.unit, {4, top - 10}, font, 0.4, ink, 1, cv::LINE_AA);
  const int groups = std::max<int>(1, chart.groups.size());
  const int series = std::max<int>(1, chart.series.size());
  const double group_w = static_cast<double>(width - left - right) / groups;
  const double bar_w = 0.8 * group_w / series;
  for (int g = 0; g < static_cast<int>(chart.groups.size()); ++g) {
    const double x0 = left + g * group_w + 0.1 * group_w;
    for (int s = 0; s < static_cast<int>(chart.series.size()); ++s) {
      const BarSeries& bars = chart.series[s];
      if (g >= static_cast<int>(bars.values.size()) || !std::isfinite(bars.values[g])) continue;
      const int xa = static_cast<int>(x0 + s * bar_w),
                xb = static_cast<int>(x0 + (s + 1) * bar_w) - 1;
      const int ya = y_of(std::max(0.0, bars.values[g])), yb = y_of(std::min(0.0, bars.values[g]));
      cv::rectangle(image, {xa, ya}, {xb, std::max(ya + 1, yb)},
                    cv::Scalar(bars.bgr[0], bars.bgr[1], bars.bgr[2]), cv::FILLED);
    }
    cv::putText(image, chart.groups[g], {static_cast<int>(x0), height - bottom + 16}, font, 0.38,
                ink, 1, cv::LINE_AA);
  }
  // Legend.
  int x = left;
  for (const BarSeries& s : chart.series) {
    cv::rectangle(image, {x, height - 26}, {x + 12, height - 14},
                  cv::Scalar(s.bgr[0], s.bgr[1], s.bgr[2]), cv::FILLED);
    cv::putText(image, s.name, {x + 16, height - 15}, font, 0.42, ink, 1, cv::LINE_AA);
    x += 24 + 9 * static_cast<int>(s.name.size());
  }
  return image;
}

}  // namespace

void WriteBarChartPng(const BarChart& chart, const std::string& path) {
  WriteBarChartsPng({chart}, path);
}

void WriteBarChartsPng(const std::vector<BarChart>& charts, const std::string& path) {
  std::vector<cv::Mat> panels;
  int width = 0;
  for (const BarChart& chart : charts) {
    panels.push_back(DrawBarChart(chart));
    width = std::max(width, panels.back().cols);
  }
  for (cv::Mat& panel : panels) {
    if (panel.cols < width) {
      cv::copyMakeBorder(panel, panel, 0, 0, 0, width - panel.cols, cv::BORDER_CONSTANT,
                         cv::Scalar(255, 255, 255));
    }
  }
  cv::Mat image;
  cv::vconcat(panels, image);
  WriteImageFile(path, image);
}

}  // namespace autoshovel::plot
