#include "runtime/perception/map_render.h"

#include <cmath>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "runtime/plot/image_file.h"

namespace autoshovel::perception {

namespace {

const cv::Vec3b kUnknown(40, 40, 40);

// One layer as an image: colormap over [lo, hi] (NaN dark grey), north up.
cv::Mat Panel(const Eigen::MatrixXf& layer, float lo, float hi, int colormap, int scale) {
  const int nx = static_cast<int>(layer.rows()), ny = static_cast<int>(layer.cols());
  cv::Mat gray(ny, nx, CV_8U), valid(ny, nx, CV_8U);
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const float v = layer(ix, iy);
      const int row = ny - 1 - iy;  // north up
      valid.at<std::uint8_t>(row, ix) = std::isnan(v) ? 0 : 1;
      const float t = std::isnan(v) ? 0.0f : std::clamp((v - lo) / (hi - lo), 0.0f, 1.0f);
      gray.at<std::uint8_t>(row, ix) = static_cast<std::uint8_t>(std::lround(255 * t));
    }
  }
  cv::Mat color;
  cv::applyColorMap(gray, color, colormap);
  color.setTo(kUnknown, valid == 0);
  cv::Mat big;
  cv::resize(color, big, cv::Size(), scale, scale, cv::INTER_NEAREST);
  return big;
}

cv::Mat ClassPanel(const Eigen::MatrixXf& cls, int scale) {
  const int nx = static_cast<int>(cls.rows()), ny = static_cast<int>(cls.cols());
  cv::Mat image(ny, nx, CV_8UC3, kUnknown);
  const cv::Vec3b colours[3] = {cv::Vec3b(120, 120, 120), cv::Vec3b(60, 170, 230),
                                cv::Vec3b(40, 40, 220)};  // ground, pile, obstacle (BGR)
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const float c = cls(ix, iy);
      if (!std::isnan(c)) image.at<cv::Vec3b>(ny - 1 - iy, ix) = colours[static_cast<int>(c)];
    }
  }
  cv::Mat big;
  cv::resize(image, big, cv::Size(), scale, scale, cv::INTER_NEAREST);
  return big;
}

void Title(cv::Mat& panel, const std::string& text) {
  cv::rectangle(panel, cv::Rect(0, 0, panel.cols, 22), cv::Scalar(255, 255, 255), cv::FILLED);
  cv::putText(panel, text, cv::Point(6, 16), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
}

}  // namespace

void WriteSemanticMapPng(const GridMap& map, const std::vector<ExtractedPile>& piles,
                         const std::string& png_path, int scale) {
  const Eigen::MatrixXf& elevation = map["elevation"];
  float top = 0.5f;
  for (int i = 0; i < elevation.size(); ++i) {
    if (!std::isnan(elevation.data()[i])) top = std::max(top, elevation.data()[i]);
  }
  std::vector<cv::Mat> panels;
  panels.push_back(Panel(elevation, 0.0f, top, cv::COLORMAP_VIRIDIS, scale));
  Title(panels.back(), "elevation 0.." + std::to_string(top).substr(0, 4) + " m");
  // Standard deviation on a log scale: 1 cm to 10 m (σp² = α_d d² spans that range).
  Eigen::MatrixXf log_sigma = (0.5f * map["variance"].array().log10());
  for (int i = 0; i < log_sigma.size(); ++i) {
    if (std::isnan(elevation.data()[i]))
      log_sigma.data()[i] = std::numeric_limits<float>::quiet_NaN();
  }
  panels.push_back(Panel(log_sigma, -2.0f, 1.0f, cv::COLORMAP_MAGMA, scale));
  Title(panels.back(), "std dev, log 0.01..10 m");
  const char* names[3] = {"ground_confidence", "pile_confidence", "obstacle_confidence"};
  for (const char* name : names) {
    panels.push_back(map.Exists(name) ? Panel(map[name], 0.0f, 1.0f, cv::COLORMAP_INFERNO, scale)
                                      : cv::Mat(panels.front().size(), CV_8UC3, kUnknown));
    Title(panels.back(), name);
  }
  panels.push_back(map.Exists("class") ? ClassPanel(map["class"], scale)
                                       : cv::Mat(panels.front().size(), CV_8UC3, kUnknown));
  const int ny = map.size().y();
  for (const ExtractedPile& pile : piles) {
    for (const BoundaryPoint& b : pile.boundary) {
      Index i;
      if (!map.IndexOf(b.xy, i)) continue;
      const cv::Point p(i.x() * scale + scale / 2, (ny - 1 - i.y()) * scale + scale / 2);
      cv::circle(panels.back(), p, std::max(1, scale / 2),
                 b.front ? cv::Scalar(0, 255, 255) : cv::Scalar(255, 0, 255), cv::FILLED);
    }
  }
  Title(panels.back(), "class: ground / pile / obstacle; front yellow");
  cv::Mat top_row, bottom_row, all;
  cv::hconcat(std::vector<cv::Mat>{panels[0], panels[1], panels[5]}, top_row);
  cv::hconcat(std::vector<cv::Mat>{panels[2], panels[3], panels[4]}, bottom_row);
  cv::vconcat(top_row, bottom_row, all);
  plot::WriteImageFile(png_path, all);
}

}  // namespace autoshovel::perception
