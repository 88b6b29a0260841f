#include "runtime/plant/top_view.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "runtime/plot/image_file.h"

namespace autoshovel::plant {
namespace {

// BGR colours.
const cv::Vec3f kFloor(150, 150, 150);
const cv::Vec3f kMaterialColours[] = {{185, 135, 80},  {95, 175, 220}, {120, 165, 125},
                                      {170, 105, 175}, {80, 115, 200}, {175, 175, 90}};

cv::Scalar ClassColour(core::SemanticClass c) {
  switch (c) {
    case core::SemanticClass::kOtherLoader:
      return {0, 200, 255};
    case core::SemanticClass::kPerson:
      return {0, 0, 255};
    case core::SemanticClass::kWall:
      return {40, 40, 40};
    case core::SemanticClass::kOwnLoader:
      return {255, 255, 0};
    default:
      return {200, 0, 200};
  }
}

}  // namespace

void WriteTopView(const World& world, const std::string& png_path, const TopViewOptions& options) {
  const Terrain& terrain = world.terrain;
  const double mpp = options.metres_per_pixel;
  if (!(mpp > 0) || terrain.nx() <= 0 || terrain.ny() <= 0) {
    throw std::invalid_argument("WriteTopView: empty terrain or metres_per_pixel <= 0");
  }
  const int nx = terrain.nx(), ny = terrain.ny();
  const int width = static_cast<int>(std::ceil(nx * terrain.resolution() / mpp - 1e-9));
  const int height = static_cast<int>(std::ceil(ny * terrain.resolution() / mpp - 1e-9));

  // Terrain as images, north up: image row 0 is the largest y.
  cv::Mat heights(ny, nx, CV_32F), materials(ny, nx, CV_16S);
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      heights.at<float>(ny - 1 - iy, ix) = static_cast<float>(terrain.height(ix, iy));
      materials.at<std::int16_t>(ny - 1 - iy, ix) = terrain.material(ix, iy);
    }
  }
  cv::Mat h, m;
  cv::resize(heights, h, {width, height}, 0, 0, cv::INTER_AREA);
  cv::resize(materials, m, {width, height}, 0, 0, cv::INTER_NEAREST);

  // Hillshade, light from the north-west 45° up; a flat cell keeps its colour.
  cv::Mat gx, gy;
  cv::Sobel(h, gx, CV_32F, 1, 0, 3, 1.0 / (8 * mpp), 0, cv::BORDER_REPLICATE);
  cv::Sobel(h, gy, CV_32F, 0, 1, 3, -1.0 / (8 * mpp), 0, cv::BORDER_REPLICATE);  // +y is north
  const cv::Vec3f light(-0.5f, 0.5f, static_cast<float>(std::sqrt(0.5)));
  const int palette = static_cast<int>(std::size(kMaterialColours));
  cv::Mat image(height, width, CV_8UC3);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const cv::Vec3f normal(-gx.at<float>(row, col), -gy.at<float>(row, col), 1.0f);
      const float shade = std::clamp(
          normal.dot(light) / static_cast<float>(cv::norm(normal)) / light[2], 0.25f, 1.3f);
      const int material = m.at<std::int16_t>(row, col);
      const cv::Vec3f base = material < 0 ? kFloor : kMaterialColours[material % palette];
      const cv::Vec3f c = base * shade;
      image.at<cv::Vec3b>(row, col) =
          cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                    cv::saturate_cast<uchar>(c[2]));
    }
  }

  const Eigen::Vector2d origin = terrain.geometry().origin;
  const auto pixel = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround((x - origin.x()) / mpp)),
                     static_cast<int>(std::lround(height - (y - origin.y()) / mpp)));
  };
  for (const OrientedBox& box : world.obstacles) {
    const double c = std::cos(box.yaw), s = std::sin(box.yaw);
    std::vector<cv::Point> corners;
    for (const auto& [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      const double lx = u * box.half_extents.x(), ly = v * box.half_extents.y();
      corners.push_back(pixel(box.center.x() + c * lx - s * ly, box.center.y() + s * lx + c * ly));
    }
    cv::polylines(image, corners, true, ClassColour(box.semantic_class), 2, cv::LINE_AA);
  }

  if (options.start) {
    const StartPose& p = *options.start;
    const cv::Point from = pixel(p.x, p.y);
    const cv::Point to = pixel(p.x + 5 * std::cos(p.heading), p.y + 5 * std::sin(p.heading));
    cv::circle(image, from, 4, {255, 0, 255}, cv::FILLED, cv::LINE_AA);
    cv::arrowedLine(image, from, to, {255, 0, 255}, 2, cv::LINE_AA, 0, 0.3);
  }

  // Scale bar (about a fifth of the width, a round length) at the bottom left.
  const double span = width * mpp / 5;
  double bar = 1;
  for (const double candidate : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0}) {
    if (candidate <= span) bar = candidate;
  }
  const int bar_px = static_cast<int>(std::lround(bar / mpp));
  const cv::Point bar_at(10, height - 12);
  cv::rectangle(image, bar_at, bar_at + cv::Point(bar_px, 6), {255, 255, 255}, cv::FILLED);
  cv::rectangle(image, bar_at, bar_at + cv::Point(bar_px, 6), {0, 0, 0}, 1);
  cv::putText(image, std::to_string(static_cast<int>(bar)) + " m", bar_at + cv::Point(0, -5),
              cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1, cv::LINE_AA);

  // Material legend at the top left.
  for (std::size_t i = 0; i < world.materials.size(); ++i) {
    const cv::Point at(10, 10 + 18 * static_cast<int>(i));
    const cv::Vec3f c = kMaterialColours[i % palette];
    cv::rectangle(image, at, at + cv::Point(12, 12), cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
    cv::putText(image, world.materials[i].name, at + cv::Point(18, 11), cv::FONT_HERSHEY_SIMPLEX,
                0.45, {0, 0, 0}, 1, cv::LINE_AA);
  }

  plot::WriteImageFile(png_path, image);
}

}  // namespace autoshovel::plant
