#include "runtime/app/truck_loading/bed_picture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "runtime/planning/dump/fill_summary.h"
#include "runtime/plot/image_file.h"

namespace autoshovel::app {

void WriteBedHeightPng(const planning::BedHeightMap& map, double rim,
                       const std::filesystem::path& path) {
  // Top view of the bed, 24 px per 15 cm cell, the cab end at the top: colour from the floor
  // (blue) to the rim (red), grey where the map has no data.
  const int px = 24;
  cv::Mat gray(map.cells_x() * px, map.cells_y() * px, CV_8UC1, cv::Scalar(0));
  cv::Mat known(gray.size(), CV_8UC1, cv::Scalar(0));
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (!map.known(ix, iy)) continue;
      const double f = std::clamp(map.height(ix, iy) / rim, 0.0, 1.0);
      // Row 0 at the cab (largest bed x), column 0 on the bed's right (smallest y).
      const cv::Rect cell(iy * px, (map.cells_x() - 1 - ix) * px, px, px);
      gray(cell).setTo(cv::Scalar(static_cast<int>(std::lround(255 * f))));
      known(cell).setTo(cv::Scalar(255));
    }
  }
  cv::Mat color;
  cv::applyColorMap(gray, color, cv::COLORMAP_JET);
  color.setTo(cv::Scalar(128, 128, 128), known == 0);
  for (int ix = 0; ix <= map.cells_x(); ++ix) {
    cv::line(color, {0, ix * px}, {color.cols, ix * px}, cv::Scalar(40, 40, 40), 1);
  }
  for (int iy = 0; iy <= map.cells_y(); ++iy) {
    cv::line(color, {iy * px, 0}, {iy * px, color.rows}, cv::Scalar(40, 40, 40), 1);
  }
  cv::Mat framed;
  cv::copyMakeBorder(color, framed, 40, 10, 10, 10, cv::BORDER_CONSTANT, cv::Scalar(255, 255, 255));
  const planning::FillSummary fill = planning::SummarizeFill(map, rim);
  char title[160];
  std::snprintf(title, sizeof title, "cab ^  mean %.2f m, std %.2f m (rim %.2f m)",
                fill.mean_height_m, fill.std_height_m, rim);
  cv::putText(framed, title, {10, 26}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  plot::WriteImageFile(path, framed);
}

}  // namespace autoshovel::app
