#include "identification/camera_lidar/correspondence_pnp.h"

#include <opencv2/calib3d.hpp>

namespace autoshovel::identification {

CorrespondencePnP SolveCorrespondencePnP(const std::vector<Correspondence>& pairs,
                                         const CameraIntrinsics& intrinsics,
                                         const CorrespondencePnPOptions& options) {
  CorrespondencePnP out;
  out.total = static_cast<int>(pairs.size());
  BoardCalibration& result = out.calibration;
  if (pairs.size() < 4) {
    result.failure = "PnP needs at least 4 correspondences, got " + std::to_string(pairs.size());
    return out;
  }
  cv::Mat K(3, 3, CV_64F);
  for (int i = 0; i < 9; ++i) K.at<double>(i / 3, i % 3) = intrinsics.K(i / 3, i % 3);
  std::vector<cv::Point2d> raw, pixels;
  std::vector<cv::Point3d> object;
  for (const Correspondence& c : pairs) {
    raw.emplace_back(c.uv.x(), c.uv.y());
    object.emplace_back(c.p_lidar.x(), c.p_lidar.y(), c.p_lidar.z());
  }
  if (intrinsics.D.empty()) {
    pixels = raw;
  } else {
    cv::undistortPoints(raw, pixels, K, cv::Mat(intrinsics.D), cv::noArray(), K);
  }
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  bool ok = false;
  if (pairs.size() >= 6) {
    ok = cv::solvePnPRansac(
        object, pixels, K, cv::noArray(), rvec, tvec, false, options.ransac_iterations,
        static_cast<float>(options.ransac_threshold_px), 0.999, inliers, cv::SOLVEPNP_EPNP);
  } else {
    ok = cv::solvePnP(object, pixels, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_ITERATIVE);
    for (int i = 0; i < static_cast<int>(pairs.size()); ++i) inliers.push_back(i);
  }
  if (!ok || inliers.size() < 4) {
    result.failure = "PnP found no pose consistent with 4 or more of the " +
                     std::to_string(pairs.size()) + " correspondences";
    return out;
  }
  std::vector<cv::Point3d> object_in;
  std::vector<cv::Point2d> pixels_in;
  for (const int i : inliers) {
    object_in.push_back(object[static_cast<std::size_t>(i)]);
    pixels_in.push_back(pixels[static_cast<std::size_t>(i)]);
  }
  cv::solvePnPRefineLM(object_in, pixels_in, K, cv::noArray(), rvec, tvec);
  const Eigen::Isometry3d T_optical_lidar = PoseFromPnP(rvec, tvec);
  result.reprojection_rms =
      ReprojectionResiduals(object_in, pixels_in, intrinsics.K, T_optical_lidar, result.residuals);
  result.T_lidar_camera = CameraInLidarFromOptical(T_optical_lidar);
  result.ok = true;
  out.inliers = static_cast<int>(inliers.size());
  return out;
}

}  // namespace autoshovel::identification
