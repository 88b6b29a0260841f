#include "identification/camera_lidar/calibrate_camera_lidar_command.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <ostream>
#include <sstream>

#include "identification/camera_lidar/auto_calibration.h"
#include "identification/camera_lidar/board_detection.h"
#include "identification/camera_lidar/board_simulation.h"
#include "identification/camera_lidar/image_header.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "identification/camera_lidar/projection_render.h"
#include "identification/camera_lidar/yard_simulation.h"
#include "identification/common/overlay_file.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/yaml_reader.h"
#include "runtime/model/description.h"
#include "runtime/plot/image_file.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::identification {

namespace fs = std::filesystem;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

[[noreturn]] void Fail(const std::string& file, int line, const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add({file, line, line > 0 ? 1 : 0}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

struct FramePaths {
  std::string name, image, cloud;
};

// Image + cloud files with the same stem in `dir`.
std::vector<FramePaths> ListFrames(const std::string& dir) {
  if (!fs::is_directory(dir)) Fail(dir, 0, "no such folder");
  std::map<std::string, FramePaths> by_stem;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string ext = entry.path().extension().string();
    const std::string stem = entry.path().stem().string();
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg")
      by_stem[stem].image = entry.path().string();
    if (ext == ".pcd" || ext == ".bin") by_stem[stem].cloud = entry.path().string();
  }
  std::vector<FramePaths> frames;
  for (auto& [stem, f] : by_stem) {
    if (f.image.empty() || f.cloud.empty()) continue;
    f.name = stem;
    frames.push_back(f);
  }
  if (frames.empty()) Fail(dir, 0, "no image + point cloud pairs (NAME.png|jpg + NAME.pcd|bin)");
  return frames;
}

cv::Mat ReadImage(const std::string& path, const CameraIntrinsics& intrinsics) {
  // The size from the header first: cv::imread allocates whatever the header announces (a
  // 1.1 MB PNG saying 20000 x 20000 px took 1.3 GB before this check could refuse it).
  const ImageHeader header = ReadImageHeader(path);
  if (header.width != intrinsics.width || header.height != intrinsics.height) {
    Fail(path, 0,
         "image is " + ImageSizeText(header.width, header.height) + " (" + header.format +
             " header), the intrinsics say " + ImageSizeText(intrinsics.width, intrinsics.height) +
             ": not decoded");
  }
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) Fail(path, 0, "cannot read the image");
  if (image.cols != intrinsics.width || image.rows != intrinsics.height) {
    Fail(path, 0,
         "image is " + ImageSizeText(image.cols, image.rows) + ", the intrinsics say " +
             ImageSizeText(intrinsics.width, intrinsics.height));
  }
  return image;
}

BoardGeometry ReadBoardYaml(const std::string& path) {
  BoardGeometry board;
  if (!fs::exists(path)) return board;  // the default board
  core::DiagnosticSink sink;
  try {
    const YAML::Node root = core::LoadYamlFile(path, sink);
    for (const auto& kv : root) {
      const std::string key = kv.first.as<std::string>();
      const YAML::Mark m = kv.second.Mark();
      double* target = key == "side"          ? &board.side
                       : key == "hole_side"   ? &board.hole_side
                       : key == "hole_offset" ? &board.hole_offset
                                              : nullptr;
      if (target == nullptr) {
        sink.Add({path, m.line + 1, m.column + 1}, key,
                 "unknown key (expected side, hole_side, hole_offset)");
        continue;
      }
      try {
        *target = kv.second.as<double>();
      } catch (const YAML::Exception&) {
        sink.Add({path, m.line + 1, m.column + 1}, key, "expected a number [m]");
      }
    }
  } catch (const YAML::Exception& e) {
    sink.Add({path, e.mark.line + 1, e.mark.column + 1}, "", e.msg);
  }
  sink.ThrowIfAny();
  if (const std::string problem = board.Check(); !problem.empty()) Fail(path, 0, problem);
  return board;
}

std::string PoseText(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d rpy = RollPitchYaw(T.linear()) / kDeg;
  char text[160];
  std::snprintf(text, sizeof text, "{xyz: [%.4f, %.4f, %.4f], rpy_deg: [%.3f, %.3f, %.3f]}",
                T.translation().x(), T.translation().y(), T.translation().z(), rpy.x(), rpy.y(),
                rpy.z());
  return text;
}

// Half width of the interval around the optimum where ρ stays within 0.5 % of its peak.
double BasinHalfWidth(const ScoreSlice& slice) {
  const double peak = *std::max_element(slice.rho.begin(), slice.rho.end());
  double width = 0;
  for (std::size_t i = 0; i < slice.rho.size(); ++i) {
    if (slice.rho[i] >= peak - 0.005 * std::abs(peak)) {
      width = std::max(width, std::abs(slice.offsets[i]));
    }
  }
  return width;
}

void Simulate(const model::MachineDescription& machine, const model::Lidar& lidar,
              const CalibrateCameraLidarOptions& options, std::ostream& out) {
  const std::string dir = options.simulate;
  core::CreateFolders(dir + "/board");
  core::CreateFolders(dir + "/frames");
  const Eigen::Isometry3d T_base_lidar = sensors::PoseToIsometry(lidar.pose);
  const Eigen::Isometry3d T_nominal =
      T_base_lidar.inverse() * sensors::PoseToIsometry(machine.sensors.camera.pose);
  const CameraIntrinsics intrinsics = IntrinsicsFromDescription(machine.sensors.camera);
  WriteCameraInfoYaml(dir + "/intrinsics.yaml", intrinsics);
  // Step 1 data: the board, seen with the mounting as built (the description's).
  const BoardGeometry board;
  {
    std::ostringstream f;
    f << "# calibration board (seed Fig. 4): square, four square holes at (+/-offset, "
         "+/-offset) [m]\nside: "
      << board.side << "\nhole_side: " << board.hole_side << "\nhole_offset: " << board.hole_offset
      << "\n";
    core::WriteFileAtomically(dir + "/board/board.yaml", f.str());
  }
  sensors::Rng rng(options.seed);
  int k = 0;
  for (const Eigen::Isometry3d& T_base_board : DefaultBoardPoses(machine.sensors.camera)) {
    const SimulatedBoardFrame f =
        SimulateBoardFrame(machine.sensors.camera, lidar, T_nominal, T_base_board, board, 1.0, rng);
    char name[64];
    std::snprintf(name, sizeof name, "%s/board/board_%03d", dir.c_str(), k++);
    plot::WriteImageFile(std::string(name) + ".png", f.image);
    WritePcd(std::string(name) + ".pcd", f.cloud, PcdEncoding::kBinary);
  }
  // Step 2 data: after "a period of operation" (seed Fig. 12) the camera has moved by 1.5° and
  // 3 cm against the LiDAR.
  const Eigen::Isometry3d T_drifted =
      Perturb(T_nominal, 1.5 * kDeg * Eigen::Vector3d(0.3, -0.8, 0.5).normalized(),
              Eigen::Vector3d(0.0, 0.02, -0.02));
  YardSimulationOptions yard;
  yard.seed = options.seed;
  const std::vector<YardFrame> frames =
      SimulateYardFrames(machine, lidar, T_drifted, options.models_dir, yard);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%03zu", i);
    plot::WriteImageFile(dir + "/frames/" + name + ".png", frames[i].image);
    const std::string cloud = dir + "/frames/" + name;
    if (i % 3 == 0) WritePcd(cloud + ".pcd", frames[i].cloud, PcdEncoding::kBinaryCompressed);
    if (i % 3 == 1) WritePcd(cloud + ".pcd", frames[i].cloud, PcdEncoding::kAscii);
    if (i % 3 == 2) WriteKittiBin(cloud + ".bin", frames[i].cloud);
    WriteMaskFolder(dir + "/masks/" + name, frames[i].masks);
  }
  core::WriteFileAtomically(dir + "/truth.yaml",
                            "# simulation truth: T_lidar_camera (camera body in the LiDAR frame)\n"
                            "board_session: " +
                                PoseText(T_nominal) + "\nframes: " + PoseText(T_drifted) + "\n");
  out << "simulated data set: " << dir << " (" << DefaultBoardPoses(machine.sensors.camera).size()
      << " board views, " << frames.size() << " yard frames with SAM-style masks)\n"
      << "try: autoshovel calibrate camera-lidar --machine " << machine.name << " --frames " << dir
      << "/frames --board " << dir << "/board\n";
}

Eigen::Isometry3d ReadTruth(const std::string& path) {
  core::DiagnosticSink sink;
  const YAML::Node root = core::LoadYamlFile(path, sink);
  sink.ThrowIfAny();
  const YAML::Node node = root["frames"];
  model::Pose3 pose;
  for (int i = 0; i < 3; ++i) {
    pose.xyz[i] = node["xyz"][i].as<double>();
    pose.rpy[i] = node["rpy_deg"][i].as<double>() * kDeg;
  }
  return sensors::PoseToIsometry(pose);
}

}  // namespace

int RunCalibrateCameraLidar(const CalibrateCameraLidarOptions& options, std::ostream& out,
                            std::ostream& err) {
  const char* const kCommand = "autoshovel calibrate camera-lidar";
  try {
    const model::MachineDescription machine = model::LoadMachineDescription(
        model::ResolveMachineDescription(options.machine, options.models_dir));
    const model::Lidar* lidar = nullptr;
    for (const auto& l : machine.sensors.lidars) {
      if (l.name == options.lidar) lidar = &l;
    }
    if (lidar == nullptr) {
      err << kCommand << ": " << machine.name << " has no LiDAR '" << options.lidar << "'\n";
      return 2;
    }
    if (!options.simulate.empty()) {
      Simulate(machine, *lidar, options, out);
      return 0;
    }
    Lock lock = Lock::kNone;
    if (options.lock == "rotation") {
      lock = Lock::kRotation;
    } else if (options.lock == "translation") {
      lock = Lock::kTranslation;
    } else if (!options.lock.empty()) {
      err << kCommand << ": --lock must be rotation or translation, got '" << options.lock << "'\n";
      return 2;
    }
    if (!options.initial.empty() && options.initial.size() != 6) {
      err << kCommand << ": --initial needs 6 values: x y z [m] roll pitch yaw [deg]\n";
      return 2;
    }
    // Where things are: the data root is the frames folder's parent.
    std::vector<FramePaths> frames;
    std::string root = ".";
    if (!options.frames.empty()) {
      frames = ListFrames(options.frames);
      root = fs::path(options.frames).lexically_normal().parent_path().string();
      if (root.empty()) root = ".";
    }
    for (const std::string& pair : options.pairs) {
      const auto comma = pair.find(',');
      if (comma == std::string::npos) {
        err << kCommand << ": --pair needs IMAGE,CLOUD, got '" << pair << "'\n";
        return 2;
      }
      const std::string image = pair.substr(0, comma);
      frames.push_back({fs::path(image).stem().string(), image, pair.substr(comma + 1)});
    }
    if (frames.empty()) {
      err << kCommand << ": give --frames DIR or --pair IMAGE,CLOUD (or --simulate DIR)\n";
      return 2;
    }
    std::string intrinsics_path = options.intrinsics;
    if (intrinsics_path.empty() && fs::exists(root + "/intrinsics.yaml")) {
      intrinsics_path = root + "/intrinsics.yaml";
    }
    const CameraIntrinsics intrinsics = intrinsics_path.empty()
                                            ? IntrinsicsFromDescription(machine.sensors.camera)
                                            : ReadCameraInfoYaml(intrinsics_path);
    std::string masks_root = options.masks;
    if (masks_root.empty() && fs::is_directory(root + "/masks")) masks_root = root + "/masks";
    if (masks_root == "none") masks_root.clear();

    const Eigen::Isometry3d T_base_lidar = sensors::PoseToIsometry(lidar->pose);
    const Eigen::Vector3d up_lidar = T_base_lidar.linear().transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Isometry3d T_nominal =
        T_base_lidar.inverse() * sensors::PoseToIsometry(machine.sensors.camera.pose);

    // Read and check every input before computing anything (and long before writing).
    struct Loaded {
      cv::Mat image;
      sensors::PointCloud cloud;
      MaskSet masks;
      std::string mask_source;
    };
    std::vector<Loaded> loaded;
    std::size_t points_read = 0, non_finite = 0, skipped = 0;
    for (const FramePaths& f : frames) {
      Loaded l;
      l.image = Undistort(ReadImage(f.image, intrinsics), intrinsics, false);
      PointCloudReadStats stats;
      l.cloud = ReadPointCloud(f.cloud, options.max_points, &stats);
      points_read += stats.points_in_file;
      non_finite += stats.non_finite;
      // An all-NaN cloud used to count as a frame and pull the score towards noise.
      if (stats.finite() < kMinFramePoints) {
        err << kCommand << ": warning: " << f.cloud << ": " << stats.finite() << " of "
            << stats.points_in_file << " points are finite (" << stats.non_finite
            << " NaN or infinite dropped), fewer than the " << kMinFramePoints
            << " a frame needs: frame '" << f.name << "' skipped\n";
        ++skipped;
        continue;
      }
      std::string mask_path;
      for (const std::string& candidate :
           {masks_root + "/" + f.name, masks_root + "/" + f.name + ".png",
            masks_root + "/" + f.name + ".json"}) {
        if (!masks_root.empty() && mask_path.empty() && fs::exists(candidate))
          mask_path = candidate;
      }
      if (!mask_path.empty()) {
        l.masks =
            UndistortMasks(ReadMasks(mask_path, intrinsics.width, intrinsics.height), intrinsics);
        l.mask_source = mask_path;
      } else {
        l.masks = BuiltInSegmentation(l.image);
        l.mask_source = "built-in segmenter";
      }
      loaded.push_back(std::move(l));
    }
    if (loaded.empty()) {
      Fail(options.frames.empty() ? frames.front().cloud : options.frames, 0,
           "no usable frame: all " + std::to_string(frames.size()) +
               " point clouds have fewer than " + std::to_string(kMinFramePoints) +
               " finite points");
    }
    // The masks are already undistorted: score with an undistorted camera.
    CameraIntrinsics pinhole = intrinsics;
    pinhole.D.clear();

    // Step 1: the board.
    Eigen::Isometry3d T0 = T_nominal;
    std::string start = "the description's nominal mounting";
    BoardCalibration board_result;
    if (!options.initial.empty()) {
      model::Pose3 pose;
      for (int i = 0; i < 3; ++i) {
        pose.xyz[i] = options.initial[i];
        pose.rpy[i] = options.initial[3 + i] * kDeg;
      }
      T0 = sensors::PoseToIsometry(pose);
      start = "--initial";
    } else if (!options.board.empty()) {
      const BoardGeometry board = ReadBoardYaml(options.board + "/board.yaml");
      std::vector<BoardObservation> observations;
      const Eigen::Vector3d boresight = T_nominal.linear().col(0);
      for (const FramePaths& f : ListFrames(options.board)) {
        const cv::Mat image = Undistort(ReadImage(f.image, intrinsics), intrinsics, false);
        const sensors::PointCloud cloud = ReadPointCloud(f.cloud, 0);
        std::vector<Eigen::Vector3f> points;
        for (const auto& p : cloud.points) points.push_back(p.p_sensor);
        const BoardCloudDetection c = DetectBoardInCloud(points, board, up_lidar, boresight);
        if (!c.ok) Fail(f.cloud, 0, c.failure);
        const BoardImageDetection i = DetectBoardInImage(image);
        if (!i.ok) Fail(f.image, 0, i.failure);
        observations.push_back({c.corners_lidar, i.corners_px});
      }
      board_result = SolveBoardPnP(observations, intrinsics.K);
      if (!board_result.ok) Fail(options.board, 0, board_result.failure);
      T0 = board_result.T_lidar_camera;
      char line[160];
      std::snprintf(line, sizeof line, "board PnP on %d views, reprojection RMS %.3f px",
                    board_result.boards, board_result.reprojection_rms);
      start = line;
    }

    // Step 2: Algorithm 1 lines 7–27.
    std::vector<ScoreFrame> score_frames;
    for (const Loaded& l : loaded) {
      score_frames.push_back(PrepareScoreFrame(l.cloud, l.masks, pinhole, up_lidar, 0));
    }
    AutoCalibrationOptions auto_options;
    auto_options.lock = lock;
    // The sky term (consistency_score.h): flagged once at T0 so that the optimisation and the
    // score surface below score the same ρ.
    if (auto_options.unsupported_density > 0) {
      MarkUnsupportedMasks(score_frames, T0, auto_options.unsupported_density);
    }
    const AutoCalibrationResult result = AutoCalibrate(score_frames, T0, auto_options);
    const std::vector<ScoreSlice> slices =
        ScoreSurface(score_frames, result.T_lidar_camera, auto_options.score);

    const Eigen::Isometry3d T_base_camera = T_base_lidar * result.T_lidar_camera;
    char line[256];
    out << "camera-lidar calibration of " << machine.name << " (" << lidar->name << "), "
        << loaded.size() << " frames";
    if (skipped > 0)
      out << " (" << skipped << " of " << frames.size() << " skipped: too few finite points)";
    out << ", masks: " << loaded.front().mask_source << (loaded.size() > 1 ? ", ..." : "") << "\n";
    if (non_finite > 0) {
      out << "  clouds: " << non_finite << " of " << points_read
          << " points dropped for a NaN or infinite coordinate\n";
    }
    out << "  start: " << start << "\n";
    {
      // The floor's noise decides how the ground class is made (cloud_features.h); a user with
      // a noisy or a very clean LiDAR sees it here.
      double noise_lo = INFINITY, noise_hi = 0;
      int k_lo = std::numeric_limits<int>::max(), k_hi = 0;
      for (const ScoreFrame& f : score_frames) {
        noise_lo = std::min(noise_lo, f.ground_noise);
        noise_hi = std::max(noise_hi, f.ground_noise);
        k_lo = std::min(k_lo, f.ground_smoothing_neighbours);
        k_hi = std::max(k_hi, f.ground_smoothing_neighbours);
      }
      std::snprintf(line, sizeof line,
                    "  floor noise sigma %.1f-%.1f mm: ground class on heights averaged over "
                    "%d-%d neighbours\n",
                    1e3 * noise_lo, 1e3 * noise_hi, k_lo, k_hi);
      out << line;
    }
    out << "  T_lidar_camera start " << PoseText(T0) << "\n";
    out << "  T_lidar_camera final " << PoseText(result.T_lidar_camera) << "\n";
    std::snprintf(line, sizeof line,
                  "  rho %.4f -> %.4f (F_R %.3f, F_N %.3f, F_S %.3f; %d masks, %ld points), %d "
                  "evaluations, %d Nelder-Mead runs, %.1f s\n",
                  result.initial.rho, result.final.rho, result.final.reflectivity,
                  result.final.normal, result.final.segmentation, result.final.masks_used,
                  result.final.points_in_masks, result.evaluations, result.runs, result.seconds);
    out << line;
    out << "  score surface (rho within 0.5 % of its peak):";
    for (const ScoreSlice& s : slices) {
      std::snprintf(line, sizeof line, " %s +/-%.3g%s", s.parameter.c_str(), BasinHalfWidth(s),
                    s.parameter.rfind("rot", 0) == 0 ? " deg" : " m");
      out << line;
    }
    out << "\n";
    if (fs::exists(root + "/truth.yaml")) {
      const PoseError e = ComparePoses(result.T_lidar_camera, ReadTruth(root + "/truth.yaml"));
      const PoseError e0 = ComparePoses(T0, ReadTruth(root + "/truth.yaml"));
      std::snprintf(line, sizeof line,
                    "  against the simulation truth: start %.3f deg %.1f mm, final %.3f deg "
                    "%.1f mm\n",
                    e0.rotation / kDeg, 1e3 * e0.translation, e.rotation / kDeg,
                    1e3 * e.translation);
      out << line;
    }

    const std::string overlay =
        options.overlay.empty() ? root + "/camera_lidar.overlay.yaml" : options.overlay;
    const std::string stem = fs::path(overlay).replace_extension("").string();
    const std::string png = options.png.empty() ? stem + ".projection.png" : options.png;
    const std::string residuals_png =
        options.residuals_png.empty() ? stem + ".surface.png" : options.residuals_png;
    std::string text =
        OverlayHeader(machine, std::string(kCommand) + " --frames " +
                                   (options.frames.empty() ? "(pairs)" : options.frames));
    text += "# camera pose = pose of LiDAR " + lidar->name + " (description) * T_lidar_camera " +
            PoseText(result.T_lidar_camera) + "\n";
    std::snprintf(line, sizeof line,
                  "# consistency score rho %.4f (start %.4f); rho stays within 0.5 %% of its peak "
                  "over",
                  result.final.rho, result.initial.rho);
    text += line;
    for (const ScoreSlice& s : slices) {
      std::snprintf(line, sizeof line, " %s +/-%.3g", s.parameter.c_str(), BasinHalfWidth(s));
      text += line;
    }
    text += " (deg, m)\nsensors:\n  camera:\n    pose: " + PoseText(T_base_camera) + "\n";
    WriteFileAtomically(overlay, text);
    WriteBeforeAfterPng(png, loaded.front().image, score_frames.front().points, pinhole.K, T0,
                        result.T_lidar_camera);
    WriteScoreSurfacePng(residuals_png, slices, board_result.residuals);
    out << "overlay: " << overlay << "\nprojection before/after: " << png
        << "\nscore surface and board residuals: " << residuals_png << "\n";
    return 0;
  } catch (const core::InputError& e) {
    // The located refusal alone: a refused input never writes anything, so saying so is noise.
    err << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::identification
