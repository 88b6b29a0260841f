#include "identification/camera_lidar/board_detection.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "identification/camera_lidar/camera_model.h"

namespace autoshovel::identification {

BoardImageDetection DetectBoardInImage(const cv::Mat& image) {
  BoardImageDetection out;
  cv::Mat grey, binary;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  cv::threshold(grey, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  cv::findContours(binary, contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
  for (std::size_t i = 0; i < contours.size() && !out.ok; ++i) {
    if (hierarchy[i][3] >= 0) continue;  // outer contours only
    std::vector<std::vector<cv::Point2f>> holes;
    std::vector<double> areas;
    for (int c = hierarchy[i][2]; c >= 0; c = hierarchy[c][0]) {
      const double area = cv::contourArea(contours[c]);
      if (area < 12) continue;
      std::vector<cv::Point> quad;
      cv::approxPolyDP(contours[c], quad, 0.06 * cv::arcLength(contours[c], true), true);
      if (quad.size() != 4 || !cv::isContourConvex(quad)) continue;
      holes.emplace_back(quad.begin(), quad.end());
      areas.push_back(area);
    }
    if (holes.size() != 4) continue;
    const auto [lo, hi] = std::minmax_element(areas.begin(), areas.end());
    if (*hi > 2.5 * *lo) continue;
    cv::Point2f board_centre(0, 0);
    std::vector<cv::Point2f> centres;
    for (const auto& h : holes) {
      cv::Point2f c(0, 0);
      for (const auto& p : h) c += 0.25f * p;
      centres.push_back(c);
      board_centre += 0.25f * c;
    }
    // Quadrant order TL, TR, BR, BL (image v grows downwards: "up" is −v).
    auto quadrant = [](const cv::Point2f& d) {
      if (d.y < 0) return d.x < 0 ? 0 : 1;
      return d.x > 0 ? 2 : 3;
    };
    std::vector<Eigen::Vector2d> corners(16);
    std::vector<int> seen(16, 0);
    bool unique = true;
    for (std::size_t h = 0; h < 4; ++h) {
      const int hq = quadrant(centres[h] - board_centre);
      std::vector<cv::Point2f> refined = holes[h];
      cv::cornerSubPix(grey, refined, cv::Size(3, 3), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
      for (int k = 0; k < 4; ++k) {
        const int index = 4 * hq + quadrant(holes[h][k] - centres[h]);
        unique = unique && seen[index]++ == 0;
        corners[index] = Eigen::Vector2d(refined[k].x, refined[k].y);
      }
    }
    if (!unique) continue;
    out.corners_px = corners;
    out.ok = true;
  }
  if (!out.ok) out.failure = "no board with four square holes found in the image";
  return out;
}

Eigen::Isometry3d PoseFromPnP(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Isometry3d T_optical_lidar = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T_optical_lidar.linear()(r, c) = R.at<double>(r, c);
    T_optical_lidar.translation()(r) = tvec.at<double>(r);
  }
  return T_optical_lidar;
}

double ReprojectionResiduals(const std::vector<cv::Point3d>& object,
                             const std::vector<cv::Point2d>& pixels, const Eigen::Matrix3d& K,
                             const Eigen::Isometry3d& T_optical_lidar,
                             std::vector<Eigen::Vector2d>& residuals) {
  double sum = 0;
  for (std::size_t i = 0; i < object.size(); ++i) {
    const Eigen::Vector3d p =
        T_optical_lidar * Eigen::Vector3d(object[i].x, object[i].y, object[i].z);
    const Eigen::Vector2d uv(K(0, 0) * p.x() / p.z() + K(0, 2), K(1, 1) * p.y() / p.z() + K(1, 2));
    residuals.push_back(Eigen::Vector2d(pixels[i].x, pixels[i].y) - uv);
    sum += residuals.back().squaredNorm();
  }
  return object.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(object.size()));
}

BoardCalibration SolveBoardPnP(const std::vector<BoardObservation>& observations,
                               const Eigen::Matrix3d& K) {
  BoardCalibration out;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> pixels;
  for (const auto& o : observations) {
    if (o.corners_lidar.size() != o.corners_px.size()) continue;
    for (std::size_t i = 0; i < o.corners_px.size(); ++i) {
      object.emplace_back(o.corners_lidar[i].x(), o.corners_lidar[i].y(), o.corners_lidar[i].z());
      pixels.emplace_back(o.corners_px[i].x(), o.corners_px[i].y());
    }
    ++out.boards;
  }
  if (object.size() < 6) {
    out.failure = "too few corners for PnP (" + std::to_string(object.size()) + ")";
    return out;
  }
  cv::Mat camera(3, 3, CV_64F);
  for (int i = 0; i < 9; ++i) camera.at<double>(i / 3, i % 3) = K(i / 3, i % 3);
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(object, pixels, camera, cv::noArray(), rvec, tvec, false,
                    cv::SOLVEPNP_ITERATIVE)) {
    out.failure = "cv::solvePnP failed";
    return out;
  }
  cv::solvePnPRefineLM(object, pixels, camera, cv::noArray(), rvec, tvec);
  const Eigen::Isometry3d T_optical_lidar = PoseFromPnP(rvec, tvec);
  out.T_lidar_camera = CameraInLidarFromOptical(T_optical_lidar);
  out.reprojection_rms = ReprojectionResiduals(object, pixels, K, T_optical_lidar, out.residuals);
  out.ok = true;
  return out;
}

}  // namespace autoshovel::identification
