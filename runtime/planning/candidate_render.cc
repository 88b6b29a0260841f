#include "runtime/planning/candidate_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "runtime/perception/semantic_map.h"
#include "runtime/plot/image_file.h"

namespace autoshovel::planning {

namespace {

using perception::CellClass;
using perception::GridMap;
using perception::Index;

struct Arrow {
  Eigen::Vector2d xy;
  double heading = 0;
  double score = 0;
};

// World ↔ pixel for the cropped panel (north up).
struct View {
  Eigen::Vector2d lo, hi;  // world window [m]
  double pixels_per_metre = 1;
  cv::Point Pixel(const Eigen::Vector2d& xy) const {
    return {static_cast<int>(std::lround((xy.x() - lo.x()) * pixels_per_metre)),
            static_cast<int>(std::lround((hi.y() - xy.y()) * pixels_per_metre))};
  }
  cv::Size size() const {
    return {static_cast<int>(std::lround((hi.x() - lo.x()) * pixels_per_metre)),
            static_cast<int>(std::lround((hi.y() - lo.y()) * pixels_per_metre))};
  }
};

cv::Mat Background(const GridMap& map, const View& view) {
  const cv::Size size = view.size();
  cv::Mat image(size, CV_8UC3, cv::Scalar(40, 40, 40));
  const Eigen::MatrixXf& elevation = map["elevation"];
  const Eigen::MatrixXf& cls = map["class"];
  float top = 0.5f;
  for (perception::GridMapIterator it(map); !it.done(); ++it) {
    if (cls((*it).x(), (*it).y()) == static_cast<float>(CellClass::kPile)) {
      top = std::max(top, elevation((*it).x(), (*it).y()));
    }
  }
  cv::Mat lut(1, 256, CV_8U);
  for (int i = 0; i < 256; ++i) lut.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
  cv::Mat colours;
  cv::applyColorMap(lut, colours, cv::COLORMAP_VIRIDIS);
  const double m = 1.0 / view.pixels_per_metre;
  for (int row = 0; row < size.height; ++row) {
    for (int col = 0; col < size.width; ++col) {
      const Eigen::Vector2d xy(view.lo.x() + (col + 0.5) * m, view.hi.y() - (row + 0.5) * m);
      Index i;
      if (!map.IndexOf(xy, i)) continue;
      const float c = cls(i.x(), i.y()), z = elevation(i.x(), i.y());
      if (std::isnan(c) || std::isnan(z)) continue;
      cv::Vec3b& px = image.at<cv::Vec3b>(row, col);
      if (c == static_cast<float>(CellClass::kObstacle)) {
        px = cv::Vec3b(30, 30, 150);
      } else if (c == static_cast<float>(CellClass::kPile)) {
        const int k = std::clamp(static_cast<int>(std::lround(255 * z / top)), 0, 255);
        px = colours.at<cv::Vec3b>(0, k);
      } else {
        px = cv::Vec3b(125, 125, 125);
      }
    }
  }
  return image;
}

void DrawLoader(cv::Mat& image, const View& view, const Pose2& T_world_hinge,
                const LoaderGeometry& loader) {
  const Eigen::Vector2d u(std::cos(T_world_hinge.heading), std::sin(T_world_hinge.heading));
  const Eigen::Vector2d v(-u.y(), u.x());
  const double hw = loader.HalfWidth() - loader.body_margin;
  const double back = loader.hinge_to_rear_axle + loader.rear_overhang;
  std::vector<cv::Point> outline;
  for (const auto& [a, l] : {std::pair{loader.tip_reach, hw}, std::pair{loader.tip_reach, -hw},
                             std::pair{-back, -hw}, std::pair{-back, hw}}) {
    outline.push_back(view.Pixel(T_world_hinge.xy + a * u + l * v));
  }
  cv::polylines(image, outline, true, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  cv::arrowedLine(image, view.Pixel(T_world_hinge.xy),
                  view.Pixel(T_world_hinge.xy + loader.tip_reach * u), cv::Scalar(255, 255, 255), 2,
                  cv::LINE_AA, 0, 0.3);
}

void DrawArrows(cv::Mat& image, const View& view, const std::vector<Arrow>& arrows, double length) {
  if (arrows.empty()) return;
  double lo = arrows.back().score, hi = arrows.front().score;
  for (const Arrow& a : arrows) lo = std::min(lo, a.score), hi = std::max(hi, a.score);
  cv::Mat lut(1, 256, CV_8U);
  for (int i = 0; i < 256; ++i) lut.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
  cv::Mat colours;
  cv::applyColorMap(lut, colours, cv::COLORMAP_COOL);
  // Worst first, so that the better arrows lie on top; the best last, in red.
  for (int k = static_cast<int>(arrows.size()) - 1; k >= 0; --k) {
    const Arrow& a = arrows[k];
    const Eigen::Vector2d u(std::cos(a.heading), std::sin(a.heading));
    const cv::Point tail = view.Pixel(a.xy - length * u), head = view.Pixel(a.xy);
    const bool best = k == 0;
    const int t =
        hi - lo > 1e-12 ? static_cast<int>(std::lround(255 * (a.score - lo) / (hi - lo))) : 255;
    const cv::Vec3b c = colours.at<cv::Vec3b>(0, std::clamp(t, 0, 255));
    const cv::Scalar colour = best ? cv::Scalar(0, 0, 255) : cv::Scalar(c[0], c[1], c[2]);
    cv::arrowedLine(image, tail, head, cv::Scalar(0, 0, 0), best ? 6 : 4, cv::LINE_AA, 0, 0.35);
    cv::arrowedLine(image, tail, head, colour, best ? 3 : 2, cv::LINE_AA, 0, 0.35);
  }
}

void Title(cv::Mat& panel, const std::string& text) {
  cv::rectangle(panel, cv::Rect(0, 0, panel.cols, 22), cv::Scalar(255, 255, 255), cv::FILLED);
  cv::putText(panel, text, cv::Point(6, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
}

}  // namespace

void WriteCandidatePng(const GridMap& map, const ShovelPointResult& result,
                       const std::vector<Chen2024Candidate>* baseline, const Pose2& T_world_hinge,
                       const LoaderGeometry& loader, const std::string& png_path,
                       const CandidateRenderOptions& options) {
  // The window: known cells, the loader and the candidates, plus the margin.
  Eigen::Vector2d lo = T_world_hinge.xy, hi = T_world_hinge.xy;
  for (perception::GridMapIterator it(map); !it.done(); ++it) {
    if (std::isnan(map.at("elevation", *it))) continue;
    const Eigen::Vector2d p = map.PositionOf(*it);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d map_lo = map.position() - map.length() / 2;
  const Eigen::Vector2d map_hi = map.position() + map.length() / 2;
  View view;
  view.lo = (lo - Eigen::Vector2d::Constant(options.margin)).cwiseMax(map_lo);
  view.hi = (hi + Eigen::Vector2d::Constant(options.margin)).cwiseMin(map_hi);
  view.pixels_per_metre = options.pixels_per_cell / map.resolution();
  const cv::Mat background = Background(map, view);

  std::vector<Arrow> ours;
  for (const ShovelCandidate& c : result.ranked) {
    if (!c.feasible || static_cast<int>(ours.size()) >= options.top) break;
    ours.push_back({c.pose.xy, c.pose.entry_heading, c.score});
  }
  cv::Mat left = background.clone();
  if (const ShovelCandidate* best = result.best()) {
    std::vector<cv::Point> line;
    for (const PathSample& s : SamplePath(best->path, 0.2)) line.push_back(view.Pixel(s.xy));
    cv::polylines(left, line, false, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  }
  DrawLoader(left, view, T_world_hinge, loader);
  DrawArrows(left, view, ours, options.arrow_length);
  char text[160];
  if (const ShovelCandidate* best = result.best()) {
    std::snprintf(text, sizeof text, "Eq. (18): top %zu of %d feasible, best F = %.3f", ours.size(),
                  result.feasible, best->score);
  } else {
    std::snprintf(text, sizeof text, "Eq. (18): %s", ToString(result.status));
  }
  Title(left, text);
  cv::Mat all = left;
  if (baseline != nullptr) {
    std::vector<Arrow> theirs;
    for (const Chen2024Candidate& c : *baseline) {
      if (static_cast<int>(theirs.size()) >= options.top) break;
      theirs.push_back({c.pose.xy, c.pose.entry_heading, c.score});
    }
    cv::Mat right = background.clone();
    DrawLoader(right, view, T_world_hinge, loader);
    DrawArrows(right, view, theirs, options.arrow_length);
    std::snprintf(text, sizeof text, "Chen et al. 2024: top %zu, best score %.3f", theirs.size(),
                  theirs.empty() ? 0.0 : theirs.front().score);
    Title(right, text);
    cv::Mat gap(left.rows, 6, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::hconcat(std::vector<cv::Mat>{left, gap, right}, all);
  }
  plot::WriteImageFile(png_path, all);
}

}  // namespace autoshovel::planning
