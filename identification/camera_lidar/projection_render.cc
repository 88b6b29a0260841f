#include "identification/camera_lidar/projection_render.h"

#include <algorithm>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "identification/camera_lidar/camera_model.h"
#include "runtime/plot/image_file.h"

namespace autoshovel::identification {

cv::Mat RenderProjection(const cv::Mat& image, const std::vector<Eigen::Vector3f>& points_lidar,
                         const Eigen::Matrix3d& K, const Eigen::Isometry3d& T_lidar_camera,
                         double max_depth) {
  cv::Mat out = image.channels() == 3 ? image.clone() : cv::Mat();
  if (out.empty()) cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  cv::Mat ramp(1, 256, CV_8U), colours;
  for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(255 - i);
  cv::applyColorMap(ramp, colours, cv::COLORMAP_JET);
  const Eigen::Isometry3d T = OpticalFromLidar(T_lidar_camera);
  const int radius = std::max(1, static_cast<int>(std::lround(out.cols / 640.0)));
  for (const auto& p : points_lidar) {
    Eigen::Vector2d uv;
    double depth = 0;
    if (!ProjectPoint(K, out.cols, out.rows, T, p.cast<double>(), uv, depth)) continue;
    const int index = std::clamp(static_cast<int>(255.0 * depth / max_depth), 0, 255);
    const cv::Vec3b c = colours.at<cv::Vec3b>(0, index);
    // Dots sized for the image: 1 px per 640 px of width (3 px at 1920), so that a full-size
    // picture shows the points and a thumbnail still does.
    cv::circle(out, {static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y()))},
               radius, cv::Scalar(c[0], c[1], c[2]), cv::FILLED, cv::LINE_8);
  }
  return out;
}

cv::Mat RenderEdges(const cv::Mat& image, const ScoreFrame& frame,
                    const Eigen::Isometry3d& T_lidar_camera, double max_depth) {
  cv::Mat out = image.channels() == 3 ? image * 0.5 : cv::Mat();
  if (out.empty()) {
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
    out *= 0.5;
  }
  if (!frame.boundary_distance.empty() && frame.boundary_distance.size() == out.size()) {
    out.setTo(cv::Scalar(255, 255, 255), frame.boundary_distance < 1.0f);
  }
  return RenderProjection(out, frame.edge_points, frame.K.cast<double>(), T_lidar_camera,
                          max_depth);
}

void WriteBeforeAfterPng(const std::string& path, const cv::Mat& image,
                         const std::vector<Eigen::Vector3f>& points_lidar, const Eigen::Matrix3d& K,
                         const Eigen::Isometry3d& before, const Eigen::Isometry3d& after) {
  cv::Mat left = RenderProjection(image, points_lidar, K, before);
  cv::Mat right = RenderProjection(image, points_lidar, K, after);
  cv::putText(left, "before", {8, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.7, {255, 255, 255}, 2);
  cv::putText(right, "after", {8, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.7, {255, 255, 255}, 2);
  cv::rectangle(right, {0, 0}, {right.cols - 1, right.rows - 1}, {0, 0, 255}, 3);  // Fig. 12
  cv::Mat both;
  cv::hconcat(left, right, both);
  plot::WriteImageFile(path, both);
}

void WriteScoreSurfacePng(const std::string& path, const std::vector<ScoreSlice>& slices,
                          const std::vector<Eigen::Vector2d>& residuals) {
  const int panel_w = 260, panel_h = 180, columns = 4;
  const int panels = static_cast<int>(slices.size()) + (residuals.empty() ? 0 : 1);
  const int rows = (panels + columns - 1) / columns;
  cv::Mat canvas(rows * panel_h, columns * panel_w, CV_8UC3, cv::Scalar(255, 255, 255));
  double lo = 1e9, hi = -1e9;
  for (const auto& s : slices) {
    for (const double r : s.rho) {
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
  }
  if (hi <= lo) hi = lo + 1e-9;
  char text[96];
  for (std::size_t k = 0; k < slices.size(); ++k) {
    const auto& s = slices[k];
    const cv::Point origin(static_cast<int>(k % columns) * panel_w,
                           static_cast<int>(k / columns) * panel_h);
    const int x0 = origin.x + 30, x1 = origin.x + panel_w - 10;
    const int y0 = origin.y + panel_h - 30, y1 = origin.y + 25;
    cv::rectangle(canvas, {x0, y1}, {x1, y0}, {180, 180, 180});
    const double a = s.offsets.front(), b = s.offsets.back();
    std::vector<cv::Point> line;
    for (std::size_t i = 0; i < s.rho.size(); ++i) {
      const int x = x0 + static_cast<int>((s.offsets[i] - a) / (b - a) * (x1 - x0));
      const int y = y0 - static_cast<int>((s.rho[i] - lo) / (hi - lo) * (y0 - y1));
      line.emplace_back(x, y);
    }
    cv::polylines(canvas, line, false, {200, 60, 0}, 2);
    const int xm = x0 + (x1 - x0) / 2;
    cv::line(canvas, {xm, y1}, {xm, y0}, {0, 0, 220}, 1);
    std::snprintf(text, sizeof text, "%s: +/-%g %s", s.parameter.c_str(), b, k < 3 ? "deg" : "m");
    cv::putText(canvas, text, {x0, origin.y + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1);
  }
  std::snprintf(text, sizeof text, "rho %.4f .. %.4f", lo, hi);
  cv::putText(canvas, text, {10, rows * panel_h - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1);
  if (!residuals.empty()) {
    const int k = static_cast<int>(slices.size());
    const cv::Point c((k % columns) * panel_w + panel_w / 2,
                      (k / columns) * panel_h + panel_h / 2 + 10);
    cv::putText(canvas, "board PnP residuals x20", {c.x - 110, c.y - panel_h / 2 + 8},
                cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1);
    for (const auto& r : residuals) {
      cv::line(canvas, c, c + cv::Point(static_cast<int>(20 * r.x()), static_cast<int>(20 * r.y())),
               {0, 120, 0}, 1);
    }
    cv::circle(canvas, c, 20, {180, 180, 180}, 1);  // 1 px
  }
  plot::WriteImageFile(path, canvas);
}

}  // namespace autoshovel::identification
