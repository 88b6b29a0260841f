#include "runtime/plot/line_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "runtime/plot/axis_ticks.h"
#include "runtime/plot/drawing.h"
#include "runtime/plot/image_file.h"

namespace autoshovel::plot {
namespace {

constexpr int kLeft = 90, kRight = 25, kTop = 50, kBottom = 65;  // margins [px]
const cv::Scalar kBlack(0, 0, 0);

using internal::DrawSegment;
using internal::DrawXGridTick;
using internal::DrawYGridTick;
using internal::NiceStep;
using internal::PutText;
using internal::PutVerticalText;
using internal::TextSize;
using internal::TickLabel;
using internal::ToScalar;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool Valid() const { return lo <= hi; }
  double Span() const { return hi - lo; }
};

void Widen(Range& r) {
  if (!r.Valid()) {
    r.lo = 0.0;
    r.hi = 1.0;
  } else if (r.Span() <= 0.0) {
    const double pad = r.lo == 0.0 ? 1.0 : 0.1 * std::abs(r.lo);
    r.lo -= pad;
    r.hi += pad;
  }
}

cv::Mat DrawLinePlot(const LinePlot& plot) {
  Range xr, yr;
  for (const PlotSeries& s : plot.series) {
    if (s.x.size() != s.y.size()) {
      throw std::invalid_argument("plot '" + plot.title + "': series '" + s.name + "' has " +
                                  std::to_string(s.x.size()) + " x and " +
                                  std::to_string(s.y.size()) + " y values");
    }
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        xr.Add(s.x[i]);
        yr.Add(s.y[i]);
      }
    }
  }
  const bool has_data = xr.Valid();
  for (const MarkerLine& m : plot.vertical) xr.Add(m.value);
  for (const MarkerLine& m : plot.horizontal) yr.Add(m.value);
  if (plot.y_from_zero) yr.Add(0.0);
  Widen(xr);
  Widen(yr);

  const int width = std::max(plot.width_px, kLeft + kRight + 100);
  const int height = std::max(plot.height_px, kTop + kBottom + 100);
  const double plot_w = width - kLeft - kRight;
  const double plot_h = height - kTop - kBottom;

  double x_step = NiceStep(xr.Span()), y_step = NiceStep(yr.Span());
  if (plot.equal_aspect) {
    // Pad 5 %, then widen the tighter axis so that one metre is as long on both.
    const double pad = 0.05 * std::max(xr.Span(), yr.Span());
    xr.lo -= pad, xr.hi += pad, yr.lo -= pad, yr.hi += pad;
    const double scale = std::max(xr.Span() / plot_w, yr.Span() / plot_h);  // [unit/px]
    const double xc = 0.5 * (xr.lo + xr.hi), yc = 0.5 * (yr.lo + yr.hi);
    xr = {xc - 0.5 * scale * plot_w, xc + 0.5 * scale * plot_w};
    yr = {yc - 0.5 * scale * plot_h, yc + 0.5 * scale * plot_h};
    x_step = NiceStep(xr.Span());
    y_step = NiceStep(yr.Span());
  } else {
    // Headroom so that markers and lines on the data's extremes are not drawn on the frame,
    // then snap the range outwards to whole ticks.
    const double x_pad = 0.03 * xr.Span(), y_pad = 0.04 * yr.Span();
    if (xr.lo != 0.0) xr.lo -= x_pad;  // an axis starting at 0 (time, cycle) stays there
    xr.hi += x_pad;
    if (yr.lo != 0.0) yr.lo -= y_pad;
    yr.hi += y_pad;
    x_step = NiceStep(xr.Span());
    xr = {std::floor(xr.lo / x_step) * x_step, std::ceil(xr.hi / x_step) * x_step};
    y_step = NiceStep(yr.Span());
    yr = {std::floor(yr.lo / y_step) * y_step, std::ceil(yr.hi / y_step) * y_step};
    if (yr.hi - std::max(yr.lo, 0.0) < 1e-12) yr.hi += y_step;
  }

  auto to_px = [&](double x, double y) {
    return cv::Point2d(kLeft + (x - xr.lo) / xr.Span() * plot_w,
                       kTop + (yr.hi - y) / yr.Span() * plot_h);
  };

  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect area(kLeft, kTop, static_cast<int>(plot_w), static_cast<int>(plot_h));

  // Grid, ticks and tick labels.
  const double eps_x = 1e-9 * x_step, eps_y = 1e-9 * y_step;
  for (double x = std::ceil((xr.lo - eps_x) / x_step) * x_step; x <= xr.hi + eps_x; x += x_step) {
    DrawXGridTick(image, to_px(x, yr.lo), kTop, TickLabel(x, x_step));
  }
  for (double y = std::ceil((yr.lo - eps_y) / y_step) * y_step; y <= yr.hi + eps_y; y += y_step) {
    DrawYGridTick(image, to_px(xr.lo, y), kLeft + plot_w, TickLabel(y, y_step));
  }

  // Data, clipped to the plot area.
  cv::Mat inner = image(area);
  const cv::Point2d offset(kLeft, kTop);
  for (const PlotSeries& s : plot.series) {
    const cv::Scalar color = ToScalar(s.color);
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const bool here = std::isfinite(s.x[i]) && std::isfinite(s.y[i]);
      if (!here) continue;
      const cv::Point2d p = to_px(s.x[i], s.y[i]) - offset;
      if (i + 1 < s.x.size() && std::isfinite(s.x[i + 1]) && std::isfinite(s.y[i + 1])) {
        DrawSegment(inner, p, to_px(s.x[i + 1], s.y[i + 1]) - offset, color, s.thickness, s.dashed);
      }
      if (s.markers) cv::circle(inner, p, s.thickness + 2, color, cv::FILLED, cv::LINE_AA);
    }
  }
  for (const MarkerLine& m : plot.vertical) {
    if (!std::isfinite(m.value)) continue;
    const double x = to_px(m.value, yr.lo).x;
    DrawSegment(image, cv::Point2d(x, kTop), cv::Point2d(x, kTop + plot_h), ToScalar(m.color), 2,
                m.dashed);
    PutText(image, m.label, cv::Point(static_cast<int>(x) + 5, kTop + 16), 0.45, ToScalar(m.color));
  }
  for (const MarkerLine& m : plot.horizontal) {
    if (!std::isfinite(m.value)) continue;
    const double y = to_px(xr.lo, m.value).y;
    DrawSegment(image, cv::Point2d(kLeft, y), cv::Point2d(kLeft + plot_w, y), ToScalar(m.color), 2,
                m.dashed);
    PutText(image, m.label, cv::Point(kLeft + 6, static_cast<int>(y) - 6), 0.45, ToScalar(m.color));
  }
  if (!has_data) {
    const cv::Size size = TextSize("no data", 0.8);
    PutText(image, "no data",
            cv::Point(kLeft + static_cast<int>(plot_w) / 2 - size.width / 2,
                      kTop + static_cast<int>(plot_h) / 2),
            0.8, ToScalar(kGrey));
  }
  cv::rectangle(image, area, kBlack, 1);

  // Title and axis labels.
  const cv::Size title_size = TextSize(plot.title, 0.65, 2);
  PutText(image, plot.title, cv::Point(width / 2 - title_size.width / 2, 32), 0.65, kBlack, 2);
  const cv::Size x_size = TextSize(plot.x_label, 0.55);
  PutText(image, plot.x_label,
          cv::Point(kLeft + static_cast<int>(plot_w) / 2 - x_size.width / 2, height - 14), 0.55);
  PutVerticalText(image, plot.y_label, 6, kTop + static_cast<int>(plot_h) / 2, 0.55);

  // Legend, top right inside the plot area.
  std::vector<const PlotSeries*> entries;
  for (const PlotSeries& s : plot.series) {
    if (!s.name.empty()) entries.push_back(&s);
  }
  if (!entries.empty()) {
    int text_w = 0;
    for (const PlotSeries* s : entries) text_w = std::max(text_w, TextSize(s->name, 0.45).width);
    const int row = 20, box_w = text_w + 50, box_h = row * static_cast<int>(entries.size()) + 8;
    const cv::Rect box(kLeft + static_cast<int>(plot_w) - box_w - 8, kTop + 8, box_w, box_h);
    cv::rectangle(image, box, cv::Scalar(255, 255, 255), cv::FILLED);
    cv::rectangle(image, box, ToScalar(kGrey), 1);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const int y = box.y + 4 + row * static_cast<int>(i) + row / 2;
      const cv::Scalar color = ToScalar(entries[i]->color);
      DrawSegment(image, cv::Point2d(box.x + 8, y), cv::Point2d(box.x + 36, y), color,
                  entries[i]->thickness, entries[i]->dashed);
      if (entries[i]->markers) {
        cv::circle(image, cv::Point(box.x + 22, y), entries[i]->thickness + 2, color, cv::FILLED,
                   cv::LINE_AA);
      }
      PutText(image, entries[i]->name, cv::Point(box.x + 42, y + 5), 0.45);
    }
  }

  return image;
}

// Checked and atomic (image_file.h): a failed write leaves no half image.
void WriteImage(const cv::Mat& image, const std::filesystem::path& path) {
  WriteImageFile(path, image);
}

}  // namespace

void WriteLinePlotPng(const LinePlot& plot, const std::filesystem::path& path) {
  WriteImage(DrawLinePlot(plot), path);
}

void WriteLinePlotGridPng(const std::vector<LinePlot>& plots, int columns,
                          const std::filesystem::path& path) {
  if (plots.empty() || columns < 1) {
    throw std::invalid_argument(path.string() + ": a plot grid needs plots and columns >= 1");
  }
  std::vector<cv::Mat> panels;
  int cell_w = 0, cell_h = 0;
  for (const LinePlot& plot : plots) {
    panels.push_back(DrawLinePlot(plot));
    cell_w = std::max(cell_w, panels.back().cols);
    cell_h = std::max(cell_h, panels.back().rows);
  }
  const int rows = (static_cast<int>(panels.size()) + columns - 1) / columns;
  cv::Mat image(rows * cell_h, columns * cell_w, CV_8UC3, cv::Scalar(255, 255, 255));
  for (std::size_t i = 0; i < panels.size(); ++i) {
    const int r = static_cast<int>(i) / columns, c = static_cast<int>(i) % columns;
    panels[i].copyTo(image(cv::Rect(c * cell_w, r * cell_h, panels[i].cols, panels[i].rows)));
  }
  WriteImage(image, path);
}

}  // namespace autoshovel::plot
