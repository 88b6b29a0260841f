#include "runtime/plot/drawing.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace autoshovel::plot::internal {

static_assert(kFont == cv::FONT_HERSHEY_SIMPLEX);

cv::Scalar ToScalar(Color c) { return cv::Scalar(c.b, c.g, c.r); }

void PutText(cv::Mat& image, const std::string& text, cv::Point origin, double scale,
             const cv::Scalar& color, int thickness) {
  cv::putText(image, text, origin, kFont, scale, color, thickness, cv::LINE_AA);
}

cv::Size TextSize(const std::string& text, double scale, int thickness) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, thickness, &baseline);
}

void DrawSegment(cv::Mat& image, cv::Point2d a, cv::Point2d b, const cv::Scalar& color,
                 int thickness, bool dashed) {
  if (!dashed) {
    cv::line(image, a, b, color, thickness, cv::LINE_AA);
    return;
  }
  const double length = cv::norm(b - a);
  constexpr double kDash = 9.0, kGap = 6.0;
  for (double s = 0.0; s < length; s += kDash + kGap) {
    const double e = std::min(s + kDash, length);
    cv::line(image, a + (b - a) * (s / length), a + (b - a) * (e / length), color, thickness,
             cv::LINE_AA);
  }
}

void PutVerticalText(cv::Mat& image, const std::string& text, int x, int center_y, double scale) {
  if (text.empty()) return;
  const cv::Size size = TextSize(text, scale);
  cv::Mat horizontal(size.height + 8, size.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
  PutText(horizontal, text, cv::Point(2, size.height + 2), scale);
  cv::Mat vertical;
  cv::rotate(horizontal, vertical, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int top =
      std::clamp(center_y - vertical.rows / 2, 0, std::max(0, image.rows - vertical.rows));
  const cv::Rect roi(x, top, std::min(vertical.cols, image.cols - x),
                     std::min(vertical.rows, image.rows - top));
  if (roi.width > 0 && roi.height > 0)
    vertical(cv::Rect(0, 0, roi.width, roi.height)).copyTo(image(roi));
}

void DrawXGridTick(cv::Mat& image, const cv::Point2d& p, double top, const std::string& label) {
  const cv::Scalar grid(225, 225, 225), black(0, 0, 0);
  cv::line(image, cv::Point2d(p.x, top), p, grid, 1);
  cv::line(image, p, p + cv::Point2d(0, 5), black, 1);
  const cv::Size size = TextSize(label, 0.45);
  PutText(
      image, label,
      cv::Point(static_cast<int>(p.x) - size.width / 2, static_cast<int>(p.y) + 8 + size.height),
      0.45);
}

void DrawYGridTick(cv::Mat& image, const cv::Point2d& p, double right, const std::string& label) {
  const cv::Scalar grid(225, 225, 225), black(0, 0, 0);
  cv::line(image, p, cv::Point2d(right, p.y), grid, 1);
  cv::line(image, p, p - cv::Point2d(5, 0), black, 1);
  const cv::Size size = TextSize(label, 0.45);
  PutText(
      image, label,
      cv::Point(static_cast<int>(p.x) - 8 - size.width, static_cast<int>(p.y) + size.height / 2),
      0.45);
}

}  // namespace autoshovel::plot::internal
