#include "identification/camera_lidar/perturbation_protocol.h"

#include <algorithm>
#include <cstdio>
#include <numbers>
#include <ostream>

namespace autoshovel::identification {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

ProtocolRun RunOne(const std::vector<ScoreFrame>& frames, const Eigen::Isometry3d& T_ref,
                   const AutoCalibrationOptions& options, const Eigen::Vector3d& rpy_deg,
                   const Eigen::Vector3d& xyz) {
  ProtocolRun run;
  run.rpy_deg = rpy_deg;
  run.xyz = xyz;
  const Eigen::Isometry3d T_ref_optical = OpticalFromLidar(T_ref);
  const Eigen::Isometry3d T_start_optical = T_ref_optical * ProtocolDelta(rpy_deg * kDeg, xyz);
  const AutoCalibrationResult result =
      AutoCalibrate(frames, CameraInLidarFromOptical(T_start_optical), options);
  const Eigen::Isometry3d T_final_optical = OpticalFromLidar(result.T_lidar_camera);
  run.start = CompareExtrinsics(T_ref_optical, T_start_optical);
  run.final = CompareExtrinsics(T_ref_optical, T_final_optical);
  run.final_xyz_optical = (T_ref_optical * T_final_optical.inverse()).translation();
  run.translation_kept = result.translation_kept;
  run.seconds = result.seconds;
  return run;
}

}  // namespace

ProtocolSummary RunPerturbationProtocol(const std::vector<ScoreFrame>& frames,
                                        const Eigen::Isometry3d& T_ref_lidar_camera,
                                        const AutoCalibrationOptions& options, double rotation_deg,
                                        double translation_m) {
  ProtocolSummary summary;
  for (const double t : {0.0, translation_m}) {
    for (int pattern = 0; pattern < 8; ++pattern) {
      const Eigen::Vector3d sign((pattern & 4) ? -1 : 1, (pattern & 2) ? -1 : 1,
                                 (pattern & 1) ? -1 : 1);
      summary.runs.push_back(
          RunOne(frames, T_ref_lidar_camera, options, rotation_deg * sign, t * sign));
    }
  }
  summary.at_reference =
      RunOne(frames, T_ref_lidar_camera, options, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  std::vector<double> rotation, translation;
  for (const ProtocolRun& r : summary.runs) {
    rotation.push_back(r.final.rotation);
    translation.push_back(r.final.translation);
    if (r.final.rotation < r.start.rotation && r.final.translation < r.start.translation) {
      ++summary.improved;
    }
  }
  summary.median_rotation = Median(rotation);
  summary.median_translation = Median(translation);
  summary.worst_rotation = *std::max_element(rotation.begin(), rotation.end());
  summary.worst_translation = *std::max_element(translation.begin(), translation.end());
  return summary;
}

void PrintProtocol(const ProtocolSummary& summary, std::ostream& out) {
  out << "  perturbation protocol (start = reference * dT; error of T_ref * T_est^-1):\n"
      << "  | roll pitch yaw [deg] | x y z [m] | start deg / mm | final deg / mm | final xyz "
         "(optical) mm | translation | s |\n  | --- | --- | --- | --- | --- | --- | --- |\n";
  char line[256];
  auto row = [&](const ProtocolRun& r) {
    std::snprintf(line, sizeof line,
                  "  | %+.0f %+.0f %+.0f | %+.2f %+.2f %+.2f | %.2f / %.0f | %.2f / %.0f | %+.0f "
                  "%+.0f %+.0f | %s | %.1f |\n",
                  r.rpy_deg.x(), r.rpy_deg.y(), r.rpy_deg.z(), r.xyz.x() + 0.0, r.xyz.y() + 0.0,
                  r.xyz.z() + 0.0, r.start.rotation / kDeg, 1e3 * r.start.translation,
                  r.final.rotation / kDeg, 1e3 * r.final.translation, 1e3 * r.final_xyz_optical.x(),
                  1e3 * r.final_xyz_optical.y(), 1e3 * r.final_xyz_optical.z(),
                  r.translation_kept ? "searched" : "local", r.seconds);
    out << line;
  };
  for (const ProtocolRun& r : summary.runs) row(r);
  row(summary.at_reference);
  std::snprintf(line, sizeof line,
                "  closer in both: %d of %zu; median %.2f deg %.0f mm, worst %.2f deg %.0f mm; "
                "from the reference: moved %.2f deg %.0f mm\n",
                summary.improved, summary.runs.size(), summary.median_rotation / kDeg,
                1e3 * summary.median_translation, summary.worst_rotation / kDeg,
                1e3 * summary.worst_translation, summary.at_reference.final.rotation / kDeg,
                1e3 * summary.at_reference.final.translation);
  out << line;
}

}  // namespace autoshovel::identification
