#include "runtime/plot/stacked_area_plot.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "runtime/plot/axis_ticks.h"
#include "runtime/plot/drawing.h"
#include "runtime/plot/image_file.h"

namespace autoshovel::plot {
namespace {

using internal::DrawSegment;
using internal::DrawXGridTick;
using internal::DrawYGridTick;
using internal::NiceStep;
using internal::PutText;
using internal::PutVerticalText;
using internal::TextSize;
using internal::TickLabel;
using internal::ToScalar;

constexpr int kLeft = 90, kBottom = 65, kMinRight = 25;  // margins [px]
constexpr int kTitleBaseline = 30;                       // [px] from the top
constexpr int kLabelRow = 18;                            // marker label rows above the frame [px]
constexpr int kMaxLabelRows = 3;
constexpr int kLegendGap = 15, kSwatchW = 18, kSwatchH = 12, kLegendRow = 22;  // [px]
const cv::Scalar kBlack(0, 0, 0);
const cv::Vec3b kTotalColor(40, 40, 40);  // the stack's total line

// Header contract: negative and non-finite values are drawn as 0.
double Drawn(double v) { return std::isfinite(v) && v > 0.0 ? v : 0.0; }

void Validate(const StackedAreaPlot& plot) {
  const std::string where = "stacked area plot '" + plot.title + "'";
  for (std::size_t i = 0; i < plot.x.size(); ++i) {
    if (!std::isfinite(plot.x[i])) {
      throw std::invalid_argument(where + ": x[" + std::to_string(i) + "] is not finite");
    }
    if (i > 0 && !(plot.x[i] > plot.x[i - 1])) {
      throw std::invalid_argument(where + ": x is not increasing at x[" + std::to_string(i) +
                                  "] = " + std::to_string(plot.x[i]) + " after " +
                                  std::to_string(plot.x[i - 1]));
    }
  }
  for (const StackedSeries& s : plot.series) {
    if (s.values.size() != plot.x.size()) {
      throw std::invalid_argument(where + ": series '" + s.name + "' has " +
                                  std::to_string(s.values.size()) + " values for " +
                                  std::to_string(plot.x.size()) + " x values");
    }
  }
}

// One series, linear between the samples (values already as drawn, >= 0).
class PiecewiseLinear {
 public:
  PiecewiseLinear(const std::vector<double>& x, std::vector<double> v) : x_(x), v_(std::move(v)) {}

  // Mean over [a, b], x_.front() <= a <= b <= x_.back(), x_ of two samples or more: the exact
  // integral of the linear pieces (trapezoids) divided by b - a; the value at a when b == a.
  double MeanOver(double a, double b) const {
    std::size_t i = Segment(a);
    if (b <= a) return At(i, a);
    double sum = 0.0, lo = a;
    while (lo < b && i + 1 < x_.size()) {
      const double hi = std::min(b, x_[i + 1]);
      sum += (hi - lo) * 0.5 * (At(i, lo) + At(i, hi));
      lo = hi;
      ++i;
    }
    return sum / (b - a);
  }

 private:
  // The segment [x_[i], x_[i + 1]] holding x.
  std::size_t Segment(double x) const {
    const auto it = std::upper_bound(x_.begin(), x_.end(), x);
    const std::size_t i = it == x_.begin() ? 0 : static_cast<std::size_t>(it - x_.begin()) - 1;
    return std::min(i, x_.size() - 2);
  }
  double At(std::size_t i, double x) const {
    const double f = (x - x_[i]) / (x_[i + 1] - x_[i]);
    return v_[i] + (v_[i + 1] - v_[i]) * std::clamp(f, 0.0, 1.0);
  }

  const std::vector<double>& x_;
  std::vector<double> v_;
};

// Grid (under the areas), ticks and tick labels; `x_px`, `y_px` map values to pixels.
template <typename XPx, typename YPx>
void DrawGridAndTicks(cv::Mat& image, double x_lo, double x_hi, double x_span, double y_hi,
                      double y_step, int top, double plot_w, double plot_h, const XPx& x_px,
                      const YPx& y_px) {
  const double x_step = NiceStep(x_span);
  const double eps_x = 1e-9 * x_step, eps_y = 1e-9 * y_step;
  for (double x = std::ceil((x_lo - eps_x) / x_step) * x_step; x <= x_hi + eps_x; x += x_step) {
    DrawXGridTick(image, cv::Point2d(x_px(x), top + plot_h), top, TickLabel(x, x_step));
  }
  for (double y = 0.0; y <= y_hi + eps_y; y += y_step) {
    DrawYGridTick(image, cv::Point2d(kLeft, y_px(y)), kLeft + plot_w, TickLabel(y, y_step));
  }
}

// Areas, column by column: pixel row r belongs to a band when its centre r + 0.5 lies in
// [y_px(top of band), y_px(base of band)), so bands meet without gap or overlap and a band of
// zero height covers no pixel.
template <typename YPx>
void DrawStack(cv::Mat& image, const cv::Rect& area, const std::vector<StackedSeries>& series,
               const std::vector<double>& means, const std::vector<bool>& in_data,
               const YPx& y_px) {
  const int columns = area.width;
  const std::size_t k_count = series.size();
  auto first_row = [&](double y) {  // first pixel row at or below y [value]
    return std::clamp(static_cast<int>(std::ceil(y_px(y) - 0.5)), area.y, area.y + area.height);
  };
  std::vector<int> line_row(columns, -1);  // of the total, per column; -1: no data
  for (int c = 0; c < columns; ++c) {
    if (!in_data[c]) continue;
    double base = 0.0;
    for (std::size_t k = 0; k < k_count; ++k) {
      const double top_value = base + means[c * k_count + k];
      const cv::Vec3b color(series[k].color.b, series[k].color.g, series[k].color.r);
      for (int r = first_row(top_value); r < first_row(base); ++r) {
        image.at<cv::Vec3b>(r, area.x + c) = color;
      }
      base = top_value;
    }
    line_row[c] = std::max(area.y, first_row(base) - 1);
  }
  // The total: a thin dark staircase on the pixels just above the stack, each column drawn up
  // to one row below its neighbours' so that it is connected; it never covers an area's pixel.
  for (int c = 0; c < columns; ++c) {
    if (line_row[c] < 0) continue;
    int from = line_row[c];
    if (c > 0 && line_row[c - 1] >= 0) from = std::min(from, line_row[c - 1] + 1);
    if (c + 1 < columns && line_row[c + 1] >= 0) from = std::min(from, line_row[c + 1] + 1);
    for (int r = from; r <= line_row[c]; ++r) {
      image.at<cv::Vec3b>(r, area.x + c) = kTotalColor;
    }
  }
}

// Legend right of the plotting area, top of the stack first, as the areas are stacked.
void DrawLegend(cv::Mat& image, const std::vector<const StackedSeries*>& entries, int legend_x,
                int top) {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int y = top + kLegendRow * static_cast<int>(i) + kLegendRow / 2;
    const cv::Rect swatch(legend_x, y - kSwatchH / 2, kSwatchW, kSwatchH);
    cv::rectangle(image, swatch, ToScalar(entries[i]->color), cv::FILLED);
    cv::rectangle(image, swatch, ToScalar(kGrey), 1);
    PutText(image, entries[i]->name, cv::Point(legend_x + kSwatchW + 8, y + 5), 0.45);
  }
}

cv::Mat DrawStackedAreaPlot(const StackedAreaPlot& plot) {
  Validate(plot);
  const std::size_t n = plot.x.size();
  const bool has_data = n >= 2 && !plot.series.empty();

  // Legend size: it sits right of the plotting area, so it sets the right margin.
  std::vector<const StackedSeries*> entries;  // top of the stack first
  for (auto it = plot.series.rbegin(); it != plot.series.rend(); ++it) {
    if (!it->name.empty()) entries.push_back(&*it);
  }
  int legend_text_w = 0;
  for (const StackedSeries* s : entries) {
    legend_text_w = std::max(legend_text_w, TextSize(s->name, 0.45).width);
  }
  const int right =
      entries.empty() ? kMinRight : kLegendGap + kSwatchW + 8 + legend_text_w + kMinRight;
  const int width = std::max(plot.width_px, kLeft + right + 100);
  const double plot_w = width - kLeft - right;

  // x range: the samples' (an area plot fills its width) and the phase boundaries.
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo;
  if (n > 0) x_lo = plot.x.front(), x_hi = plot.x.back();
  for (const MarkerLine& m : plot.vertical) {
    if (std::isfinite(m.value)) x_lo = std::min(x_lo, m.value), x_hi = std::max(x_hi, m.value);
  }
  if (!(x_lo <= x_hi)) {
    x_lo = 0.0, x_hi = 1.0;
  } else if (x_hi - x_lo <= 0.0) {
    const double pad = x_lo == 0.0 ? 1.0 : 0.1 * std::abs(x_lo);
    x_lo -= pad, x_hi += pad;
  }
  const double x_span = x_hi - x_lo;
  auto x_px = [&](double x) { return kLeft + (x - x_lo) / x_span * plot_w; };

  // Phase boundary labels above the frame, centred on their line, in up to three rows so that
  // neighbours do not overlap.
  struct Label {
    const MarkerLine* marker;
    double x;  // [px]
    int left, row;
  };
  std::vector<Label> labels;
  std::vector<int> row_end(kMaxLabelRows, std::numeric_limits<int>::min());
  int label_rows = 0;
  for (const MarkerLine& m : plot.vertical) {
    if (!std::isfinite(m.value)) continue;
    const double x = x_px(m.value);
    const int w = TextSize(m.label, 0.45).width;
    const int left = std::clamp(static_cast<int>(x) - w / 2, 0, std::max(0, width - w));
    int row = 0;
    while (row < kMaxLabelRows && row_end[row] + 6 > left) ++row;
    if (row == kMaxLabelRows) {
      row = static_cast<int>(std::min_element(row_end.begin(), row_end.end()) - row_end.begin());
    }
    row_end[row] = left + w;
    if (!m.label.empty()) label_rows = std::max(label_rows, row + 1);
    labels.push_back({&m, x, left, row});
  }
  const int top = label_rows == 0 ? 50 : kTitleBaseline + kLabelRow * label_rows + 10;
  const int height = std::max(plot.height_px, top + kBottom + 100);
  const double plot_h = height - top - kBottom;

  // What each pixel column shows: the mean of each series over the column's x interval.
  const int columns = static_cast<int>(plot_w);
  const std::size_t k_count = plot.series.size();
  std::vector<double> means;  // [column * k_count + k]
  std::vector<bool> in_data(columns, false);
  double total_max = 0.0;
  if (has_data) {
    std::vector<PiecewiseLinear> curves;
    for (const StackedSeries& s : plot.series) {
      std::vector<double> v(n);
      std::transform(s.values.begin(), s.values.end(), v.begin(), Drawn);
      curves.emplace_back(plot.x, std::move(v));
    }
    means.assign(static_cast<std::size_t>(columns) * k_count, 0.0);
    for (int c = 0; c < columns; ++c) {
      const double a = std::max(x_lo + x_span * c / plot_w, plot.x.front());
      const double b = std::min(x_lo + x_span * (c + 1) / plot_w, plot.x.back());
      if (a > b) continue;
      in_data[c] = true;
      double total = 0.0;
      for (std::size_t k = 0; k < k_count; ++k) {
        means[c * k_count + k] = curves[k].MeanOver(a, b);
        total += means[c * k_count + k];
      }
      total_max = std::max(total_max, total);
    }
  }

  // y range: from 0 to the largest total drawn, 4 % headroom, snapped up to a whole tick.
  if (!(total_max > 0.0) || !std::isfinite(total_max)) total_max = 1.0;
  const double y_step = NiceStep(1.04 * total_max);
  const double y_hi = std::ceil(1.04 * total_max / y_step) * y_step;
  auto y_px = [&](double y) { return top + (y_hi - y) / y_hi * plot_h; };

  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect area(kLeft, top, columns, static_cast<int>(plot_h));

  DrawGridAndTicks(image, x_lo, x_hi, x_span, y_hi, y_step, top, plot_w, plot_h, x_px, y_px);

  if (has_data) DrawStack(image, area, plot.series, means, in_data, y_px);

  // Phase boundaries over the areas, labels above the frame.
  for (const Label& l : labels) {
    const cv::Scalar color = ToScalar(l.marker->color);
    DrawSegment(image, cv::Point2d(l.x, top), cv::Point2d(l.x, top + plot_h - 1), color, 2,
                l.marker->dashed);
    PutText(image, l.marker->label, cv::Point(l.left, kTitleBaseline + kLabelRow * (l.row + 1)),
            0.45, color);
  }
  if (!has_data) {
    const cv::Size size = TextSize("no data", 0.8);
    PutText(image, "no data",
            cv::Point(kLeft + static_cast<int>(plot_w) / 2 - size.width / 2,
                      top + static_cast<int>(plot_h) / 2),
            0.8, ToScalar(kGrey));
  }
  cv::rectangle(image, area, kBlack, 1);

  // Title and axis labels.
  const cv::Size title_size = TextSize(plot.title, 0.65, 2);
  PutText(image, plot.title, cv::Point(width / 2 - title_size.width / 2, kTitleBaseline), 0.65,
          kBlack, 2);
  const cv::Size x_size = TextSize(plot.x_label, 0.55);
  PutText(image, plot.x_label,
          cv::Point(kLeft + static_cast<int>(plot_w) / 2 - x_size.width / 2, height - 14), 0.55);
  PutVerticalText(image, plot.y_label, 6, top + static_cast<int>(plot_h) / 2, 0.55);

  DrawLegend(image, entries, area.x + area.width + kLegendGap, top);
  return image;
}

}  // namespace

Color PaletteColor(int k) {
  // Okabe & Ito (2008), as {b, g, r}: blue, orange, bluish green, vermillion, sky blue, reddish
  // purple, yellow (last: the least contrast on white).
  static constexpr Color kPalette[] = {{178, 114, 0},  {0, 159, 230},   {115, 158, 0}, {0, 94, 213},
                                       {233, 180, 86}, {167, 121, 204}, {66, 228, 240}};
  constexpr int kCount = static_cast<int>(std::size(kPalette));
  return kPalette[((k % kCount) + kCount) % kCount];
}

void WriteStackedAreaPlotPng(const StackedAreaPlot& plot, const std::filesystem::path& path) {
  WriteImageFile(path, DrawStackedAreaPlot(plot));
}

void WriteStackedAreaPlotsPng(const std::vector<StackedAreaPlot>& plots,
                              const std::filesystem::path& path) {
  if (plots.empty()) {
    throw std::invalid_argument(path.string() + ": stacked area plots: none given");
  }
  std::vector<cv::Mat> panels;
  int width = 0, height = 0;
  for (const StackedAreaPlot& plot : plots) {
    panels.push_back(DrawStackedAreaPlot(plot));
    width = std::max(width, panels.back().cols);
    height += panels.back().rows;
  }
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  int y = 0;
  for (const cv::Mat& panel : panels) {
    panel.copyTo(image(cv::Rect(0, y, panel.cols, panel.rows)));
    y += panel.rows;
  }
  WriteImageFile(path, image);
}

}  // namespace autoshovel::plot
