#include "runtime/plot/box_plot.h"

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

// Linear interpolation between closest ranks (NumPy's default "linear" method).
double Quantile(const std::vector<double>& sorted, double p) {
  const double position = p * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  return sorted[below] + (position - static_cast<double>(below)) * (sorted[above] - sorted[below]);
}

cv::Mat DrawBoxPlot(const BoxPlot& plot) {
  const int groups = std::max<int>(1, plot.groups.size());
  const int width = std::max(420, 90 + 90 * groups), height = 400;
  const int left = 70, right = 20, top = 50, bottom = 60;
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<BoxStatistics> stats;
  double lo = INFINITY, hi = -INFINITY;
  for (const BoxGroup& g : plot.groups) {
    stats.push_back(ComputeBoxStatistics(g.samples));
    for (const double v : g.samples) {
      if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    }
  }
  if (!std::isfinite(lo)) lo = 0, hi = 1;
  if (hi - lo < 1e-12) hi = lo + 1;
  const double span = hi - lo;
  lo -= 0.05 * span, hi += 0.05 * span;
  const int plot_h = height - top - bottom;
  auto y_of = [&](double v) { return top + static_cast<int>((hi - v) / (hi - lo) * plot_h); };
  const cv::Scalar ink(40, 40, 40), grid(225, 225, 225), box(180, 110, 30), median(40, 40, 210);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (int k = 0; k <= 5; ++k) {
    const double v = lo + (hi - lo) * k / 5;
    const int y = y_of(v);
    cv::line(image, {left, y}, {width - right, y}, grid, 1);
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    cv::putText(image, text, {4, y + 4}, font, 0.4, ink, 1, cv::LINE_AA);
  }
  cv::putText(image, plot.title, {left, 22}, font, 0.55, ink, 1, cv::LINE_AA);
  cv::putText(image, plot.unit, {4, top - 10}, font, 0.4, ink, 1, cv::LINE_AA);
  const double slot = static_cast<double>(width - left - right) / groups;
  for (int g = 0; g < static_cast<int>(plot.groups.size()); ++g) {
    const int cx = static_cast<int>(left + (g + 0.5) * slot);
    const int half = static_cast<int>(0.25 * slot);
    const BoxStatistics& s = stats[g];
    if (s.count > 0) {
      cv::line(image, {cx, y_of(s.low_whisker)}, {cx, y_of(s.q1)}, ink, 1);
      cv::line(image, {cx, y_of(s.q3)}, {cx, y_of(s.high_whisker)}, ink, 1);
      for (const double w : {s.low_whisker, s.high_whisker}) {
        cv::line(image, {cx - half / 2, y_of(w)}, {cx + half / 2, y_of(w)}, ink, 1);
      }
      cv::rectangle(image, {cx - half, y_of(s.q3)},
                    {cx + half, std::max(y_of(s.q1), y_of(s.q3) + 1)}, box, 2);
      cv::line(image, {cx - half, y_of(s.median)}, {cx + half, y_of(s.median)}, median, 2);
      for (const double o : s.outliers) cv::circle(image, {cx, y_of(o)}, 2, ink, 1, cv::LINE_AA);
    }
    int baseline = 0;
    const std::string& name = plot.groups[g].name;
    const cv::Size size = cv::getTextSize(name, font, 0.4, 1, &baseline);
    cv::putText(image, name, {cx - size.width / 2, height - bottom + 18}, font, 0.4, ink, 1,
                cv::LINE_AA);
    const std::string n = "n=" + std::to_string(s.count);
    const cv::Size n_size = cv::getTextSize(n, font, 0.36, 1, &baseline);
    cv::putText(image, n, {cx - n_size.width / 2, height - bottom + 36}, font, 0.36, ink, 1,
                cv::LINE_AA);
  }
  return image;
}

}  // namespace

BoxStatistics ComputeBoxStatistics(std::vector<double> samples) {
  samples.erase(
      std::remove_if(samples.begin(), samples.end(), [](double v) { return !std::isfinite(v); }),
      samples.end());
  BoxStatistics s;
  s.count = static_cast<int>(samples.size());
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  s.q1 = Quantile(samples, 0.25);
  s.median = Quantile(samples, 0.5);
  s.q3 = Quantile(samples, 0.75);
  const double reach = 1.5 * (s.q3 - s.q1);
  s.low_whisker = s.q1, s.high_whisker = s.q3;
  for (const double v : samples) {
    if (v < s.q1 - reach || v > s.q3 + reach) {
      s.outliers.push_back(v);
    } else {
      s.low_whisker = std::min(s.low_whisker, v);
      s.high_whisker = std::max(s.high_whisker, v);
    }
  }
  return s;
}

void WriteBoxPlotsPng(const std::vector<BoxPlot>& panels, const std::filesystem::path& path) {
  std::vector<cv::Mat> images;
  for (const BoxPlot& p : panels) {
    images.push_back(DrawBoxPlot(p));
  }
  cv::Mat image;
  if (!images.empty()) cv::hconcat(images, image);
  WriteImageFile(path, image);
}

}  // namespace autoshovel::plot
