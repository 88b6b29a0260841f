#include "runtime/perception/pile_extraction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace autoshovel::perception {

std::vector<ExtractedPile> ExtractPiles(GridMap& map, const Eigen::Vector3d& plane,
                                        const PileExtractionConfig& config) {
  const int nx = map.size().x(), ny = map.size().y();
  const Eigen::MatrixXf& cls = map["class"];
  const Eigen::MatrixXf& elevation = map["elevation"];
  if (!map.Exists("pile_elevation")) map.Add("pile_elevation");
  Eigen::MatrixXf& pile_elevation = map["pile_elevation"];
  pile_elevation.setConstant(std::numeric_limits<float>::quiet_NaN());

  // Connected components and ordered outlines by OpenCV (rows = iy, columns = ix).
  cv::Mat mask(ny, nx, CV_8U, cv::Scalar(0));
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      if (cls(ix, iy) == static_cast<float>(CellClass::kPile)) {
        mask.at<std::uint8_t>(iy, ix) = 255;
        pile_elevation(ix, iy) = elevation(ix, iy);
      }
    }
  }
  cv::Mat labels;
  const int count = cv::connectedComponents(mask, labels, 4, CV_32S);
  std::vector<ExtractedPile> piles(std::max(count - 1, 0));
  const double area = map.resolution() * map.resolution();
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const int label = labels.at<int>(iy, ix);
      if (label == 0) continue;
      ExtractedPile& pile = piles[label - 1];
      const Eigen::Vector2d xy = map.PositionOf(Index(ix, iy));
      const double above =
          elevation(ix, iy) - (plane.x() * xy.x() + plane.y() * xy.y() + plane.z());
      pile.cells.emplace_back(ix, iy);
      pile.volume += std::max(above, 0.0) * area;
      pile.peak_height = std::max(pile.peak_height, above);
      pile.centroid += xy;
    }
  }
  for (int label = 1; label < count; ++label) {
    ExtractedPile& pile = piles[label - 1];
    if (pile.cells.empty()) continue;
    pile.centroid /= static_cast<double>(pile.cells.size());
    cv::Mat component = labels == label;
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(component, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    if (contours.empty()) continue;
    const auto& outline =
        *std::max_element(contours.begin(), contours.end(),
                          [](const auto& a, const auto& b) { return a.size() < b.size(); });
    for (const cv::Point& c : outline) {
      BoundaryPoint point;
      point.xy = map.PositionOf(Index(c.x, c.y));
      point.height = elevation(c.x, c.y);
      // The front: a 4-neighbour outside the pile that is known ground.
      const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int x = c.x + dx[k], y = c.y + dy[k];
        if (x < 0 || y < 0 || x >= nx || y >= ny) continue;
        point.front |= cls(x, y) == static_cast<float>(CellClass::kGround);
      }
      pile.boundary.push_back(point);
    }
  }
  piles.erase(std::remove_if(piles.begin(), piles.end(),
                             [&](const ExtractedPile& p) {
                               return static_cast<int>(p.cells.size()) < config.min_cells ||
                                      p.peak_height < config.min_peak_height;
                             }),
              piles.end());
  std::sort(piles.begin(), piles.end(),
            [](const ExtractedPile& a, const ExtractedPile& b) { return a.volume > b.volume; });
  return piles;
}

}  // namespace autoshovel::perception
