#include "runtime/perception/scan/scan_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "runtime/plot/image_file.h"

namespace autoshovel::perception {

namespace {

// 1, 2 or 5 times a power of ten, near a fifth of `span`.
double RoundLength(double span) {
  const double target = span / 5.0;
  const double power = std::pow(10.0, std::floor(std::log10(target)));
  for (const double m : {5.0, 2.0, 1.0}) {
    if (m * power <= target) return m * power;
  }
  return power;
}

std::string LengthText(double metres) {
  char text[32];
  if (metres >= 1) {
    std::snprintf(text, sizeof text, "%g m", metres);
  } else {
    std::snprintf(text, sizeof text, "%g cm", metres * 100);
  }
  return text;
}

}  // namespace

void WriteLayerPng(const std::string& path, const GridMap& map, const LayerPicture& picture) {
  const Eigen::MatrixXf& layer = map[picture.layer];
  const int nx = static_cast<int>(layer.rows()), ny = static_cast<int>(layer.cols());
  const int px = std::max(1, (picture.min_pixels + std::max(nx, ny) - 1) / std::max(nx, ny));
  const int map_w = nx * px, map_h = ny * px;
  const int margin = 40, bar_w = 110;
  cv::Mat canvas(map_h + 2 * margin + 30, map_w + 2 * margin + bar_w, CV_8UC3,
                 cv::Scalar(255, 255, 255));
  auto value_of = [&](int x, int y) {
    double v = layer(x, y);
    if (picture.square_root) v = std::sqrt(std::max(0.0, v));
    return v * picture.scale;
  };
  // The colour bar spans the 0.5–99.5 % of the values (all of them for labels): one stray cell
  // must not squeeze the rest of the map into a single colour. Cells beyond are drawn in the
  // end colours, and the bar's end says so (">=", "<=").
  std::vector<double> values;
  for (int x = 0; x < nx; ++x) {
    for (int y = 0; y < ny; ++y) {
      const double v = value_of(x, y);
      if (std::isfinite(v)) values.push_back(v);
    }
  }
  double lo = 0, hi = 1;
  bool clipped_lo = false, clipped_hi = false;
  if (!values.empty()) {
    std::sort(values.begin(), values.end());
    const std::size_t cut = picture.categorical ? 0 : values.size() / 200;
    lo = values[cut];
    hi = values[values.size() - 1 - cut];
    clipped_lo = values.front() < lo;
    clipped_hi = values.back() > hi;
  }
  if (hi <= lo) hi = lo + 1e-9;
  cv::Mat ramp(1, 256, CV_8U), colours;
  for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
  cv::applyColorMap(ramp, colours, picture.categorical ? cv::COLORMAP_HSV : cv::COLORMAP_VIRIDIS);
  auto colour = [&](double v) {
    int i = 0;
    if (picture.categorical) {
      i = (static_cast<int>(std::lround(v)) * 67) % 256;  // spread neighbouring labels apart
    } else {
      i = std::clamp(static_cast<int>(255.0 * (v - lo) / (hi - lo)), 0, 255);
    }
    const cv::Vec3b c = colours.at<cv::Vec3b>(0, i);
    return cv::Scalar(c[0], c[1], c[2]);
  };
  // Cells: x right, y up (row 0 at the top is the largest y).
  for (int x = 0; x < nx; ++x) {
    for (int y = 0; y < ny; ++y) {
      const double v = value_of(x, y);
      if (!std::isfinite(v)) continue;
      const cv::Point corner(margin + x * px, margin + (ny - 1 - y) * px);
      cv::rectangle(canvas, corner, corner + cv::Point(px - 1, px - 1), colour(v), cv::FILLED);
    }
  }
  cv::rectangle(canvas, {margin - 1, margin - 1}, {margin + map_w, margin + map_h},
                {120, 120, 120});
  cv::putText(canvas, picture.title, {margin, 26}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 0, 0}, 1,
              cv::LINE_AA);
  // Scale bar under the map.
  const double length = RoundLength(map.length().x());
  const int bar_px = static_cast<int>(std::lround(length / map.resolution() * px));
  const int y_bar = margin + map_h + 18;
  cv::line(canvas, {margin, y_bar}, {margin + bar_px, y_bar}, {0, 0, 0}, 3);
  cv::putText(canvas, LengthText(length), {margin + bar_px + 8, y_bar + 5},
              cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
  // Colour bar (continuous layers) with its ends and unit.
  const int x_bar = margin + map_w + 20;
  if (!picture.categorical) {
    for (int i = 0; i < map_h; ++i) {
      const double v = hi - (hi - lo) * i / std::max(1, map_h - 1);
      cv::line(canvas, {x_bar, margin + i}, {x_bar + 20, margin + i}, colour(v));
    }
    char text[64];
    std::snprintf(text, sizeof text, "%s%.3g %s", clipped_hi ? ">= " : "", hi,
                  picture.unit.c_str());
    cv::putText(canvas, text, {x_bar + 24, margin + 10}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0},
                1, cv::LINE_AA);
    std::snprintf(text, sizeof text, "%s%.3g %s", clipped_lo ? "<= " : "", lo,
                  picture.unit.c_str());
    cv::putText(canvas, text, {x_bar + 24, margin + map_h}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                {0, 0, 0}, 1, cv::LINE_AA);
  } else {
    const int labels = std::isfinite(hi) ? static_cast<int>(std::lround(hi)) : 0;
    for (int k = 1; k <= std::min(labels, 20); ++k) {
      const int y = margin + (k - 1) * 22;
      cv::rectangle(canvas, {x_bar, y}, {x_bar + 16, y + 16}, colour(k), cv::FILLED);
      cv::putText(canvas, std::to_string(k), {x_bar + 24, y + 13}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                  {0, 0, 0}, 1, cv::LINE_AA);
    }
  }
  plot::WriteImageFile(path, canvas);
}

}  // namespace autoshovel::perception
