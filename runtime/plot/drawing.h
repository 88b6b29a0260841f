// Drawing primitives shared by the plot writers of this folder (internal: only runtime/plot/*.cc
// include it, so OpenCV stays out of every other header).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "runtime/plot/line_plot.h"

namespace autoshovel::plot::internal {

inline constexpr int kFont = 0;  // cv::FONT_HERSHEY_SIMPLEX

cv::Scalar ToScalar(Color c);
void PutText(cv::Mat& image, const std::string& text, cv::Point origin, double scale,
             const cv::Scalar& color = cv::Scalar(0, 0, 0), int thickness = 1);
cv::Size TextSize(const std::string& text, double scale, int thickness = 1);
/// A line from a to b, solid or in dashes of 9 px with gaps of 6 px (a dashed line of no length
/// draws nothing).
void DrawSegment(cv::Mat& image, cv::Point2d a, cv::Point2d b, const cv::Scalar& color,
                 int thickness, bool dashed);
/// The x axis at `p`: a grid line up to `top`, a 5 px tick below the axis and `label` centred
/// under it.
void DrawXGridTick(cv::Mat& image, const cv::Point2d& p, double top, const std::string& label);
/// The y axis at `p`: a grid line across to x = `right`, a 5 px tick left of the axis and `label`
/// right-aligned 8 px left of it.
void DrawYGridTick(cv::Mat& image, const cv::Point2d& p, double right, const std::string& label);
/// Text rotated 90° counter-clockwise, centred vertically at `center_y`, left edge at `x`.
void PutVerticalText(cv::Mat& image, const std::string& text, int x, int center_y, double scale);

}  // namespace autoshovel::plot::internal
