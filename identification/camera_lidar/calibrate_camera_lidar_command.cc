#include "identification/camera_lidar/calibrate_camera_lidar_command.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <ostream>
#include <sstream>

#include "identification/camera_lidar/auto_calibration.h"
#include "identification/camera_lidar/board_detection.h"
#include "identification/camera_lidar/board_simulation.h"
#include "identification/camera_lidar/correspondence_pnp.h"
#include "identification/camera_lidar/image_header.h"
#include "identification/camera_lidar/perturbation_protocol.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "identification/camera_lidar/projection_render.h"
#include "identification/camera_lidar/rig_files.h"
#include "identification/camera_lidar/street_simulation.h"
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

// Without a machine: one synthetic street scene (street_simulation.h) in the CalibAnything
// layout, its calib.txt holding the truth; start from it with --perturb to try the search.
void SimulateStreetScene(const CalibrateCameraLidarOptions& options, std::ostream& out) {
  const std::string dir = options.simulate;
  core::CreateFolders(dir + "/masks");
  const Eigen::Isometry3d T_truth = StreetSceneMount();
  StreetSceneOptions scene;
  scene.seed = options.seed;
  const StreetFrame frame = SimulateStreetFrame(T_truth, scene);
  plot::WriteImageFile(dir + "/scene.png", frame.image);
  WritePcd(dir + "/scene.pcd", frame.cloud, PcdEncoding::kBinaryCompressed);
  WriteMaskFolder(dir + "/masks", frame.masks);
  const Eigen::Matrix3d& K = frame.intrinsics.K;
  const Eigen::Matrix4d T = OpticalFromLidar(T_truth).matrix();
  std::ostringstream calib;
  calib.precision(9);
  calib << "K: " << K(0, 0) << " 0 " << K(0, 2) << " 0 " << K(1, 1) << " " << K(1, 2)
        << " 0 0 1\nD: 0 0 0 0\nT:";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) calib << " " << T(r, c);
  }
  calib << "\n";
  WriteFileAtomically(dir + "/calib.txt", calib.str());
  out << "simulated street scene: " << dir << " (" << frame.cloud.points.size() << " points, "
      << frame.masks.masks.size() << " masks; calib.txt holds the truth)\n"
      << "try: autoshovel calibrate camera-lidar --scene " << dir
      << " --perturb 3,3,3,0.1,0.1,0.1\n";
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

namespace {

// Where a run's inputs come from, resolved before anything is read.
struct Inputs {
  std::vector<FramePaths> frames;
  std::vector<std::string> mask_paths;  ///< per frame; empty entry: look under masks_root
  std::string root = ".";               ///< the data root (intrinsics.yaml, masks/, truth.yaml)
  std::string output_root = ".";  ///< outputs go here by default (scene folders may be read-only)
  std::string calib;              ///< calib.txt, if any
  std::string frames_folder;      ///< --frames, named when no frame is usable
};

// The one image + cloud of a CalibAnything-style scene folder, its masks/ and calib.txt.
void AddScene(const std::string& dir, Inputs& inputs) {
  const std::vector<FramePaths> pairs = ListFrames(dir);
  if (pairs.size() != 1) {
    Fail(dir, 0,
         "a scene folder holds one image + point cloud pair, found " +
             std::to_string(pairs.size()) + " (use --frames for a folder of several)");
  }
  FramePaths frame = pairs.front();
  frame.name = fs::path(dir).lexically_normal().filename().string() + "/" + frame.name;
  inputs.frames.push_back(frame);
  inputs.mask_paths.push_back(fs::is_directory(dir + "/masks") ? dir + "/masks" : "");
  if (inputs.calib.empty() && fs::exists(dir + "/calib.txt")) inputs.calib = dir + "/calib.txt";
}

Inputs ResolveInputs(const CalibrateCameraLidarOptions& options) {
  Inputs inputs;
  if (!options.frames.empty()) {
    inputs.frames = ListFrames(options.frames);
    inputs.mask_paths.assign(inputs.frames.size(), "");
    inputs.root = fs::path(options.frames).lexically_normal().parent_path().string();
    if (inputs.root.empty()) inputs.root = ".";
    inputs.output_root = inputs.root;
    inputs.frames_folder = options.frames;
  }
  for (const std::string& pair : options.pairs) {
    const auto comma = pair.find(',');
    if (comma == std::string::npos) Fail(pair, 0, "--pair needs IMAGE,CLOUD");
    const std::string image = pair.substr(0, comma);
    inputs.frames.push_back({fs::path(image).stem().string(), image, pair.substr(comma + 1)});
    inputs.mask_paths.emplace_back();
  }
  for (const std::string& scene : options.scenes) AddScene(scene, inputs);
  if (!options.calib.empty()) inputs.calib = options.calib;
  return inputs;
}

// K and D: --intrinsics YAML, else calib.txt, else <root>/intrinsics.yaml, else the description.
CameraIntrinsics ResolveIntrinsics(const CalibrateCameraLidarOptions& options, const Inputs& inputs,
                                   const RigCalibrationFile* calib,
                                   const model::MachineDescription* machine) {
  if (!options.intrinsics.empty()) return ReadCameraInfoYaml(options.intrinsics);
  if (calib != nullptr && calib->K) {
    CameraIntrinsics intrinsics;
    const ImageHeader header = ReadImageHeader(inputs.frames.front().image);
    intrinsics.width = header.width;
    intrinsics.height = header.height;
    intrinsics.K = *calib->K;
    intrinsics.D = calib->D;
    return intrinsics;
  }
  if (fs::exists(inputs.root + "/intrinsics.yaml")) {
    return ReadCameraInfoYaml(inputs.root + "/intrinsics.yaml");
  }
  if (machine != nullptr) return IntrinsicsFromDescription(machine->sensors.camera);
  Fail(inputs.frames.front().image, 0,
       "no intrinsics: give --intrinsics camera_info.yaml or --calib calib.txt (K:, D:) for a "
       "standalone rig");
}

struct Loaded {
  cv::Mat image;
  sensors::PointCloud cloud;
  MaskSet masks;
  std::string mask_source;
};

// Every frame read and checked before anything is computed (and long before anything is
// written); frames with too few finite points are skipped with a warning.
std::vector<Loaded> LoadFrames(const Inputs& inputs, const std::string& masks_option,
                               const CameraIntrinsics& intrinsics, std::size_t max_points,
                               std::ostream& err, std::size_t& points_read, std::size_t& non_finite,
                               std::size_t& skipped) {
  std::string masks_root = masks_option;
  if (masks_root.empty() && fs::is_directory(inputs.root + "/masks")) {
    masks_root = inputs.root + "/masks";
  }
  const bool builtin = masks_root == "none";
  if (builtin) masks_root.clear();
  std::vector<Loaded> loaded;
  for (std::size_t k = 0; k < inputs.frames.size(); ++k) {
    const FramePaths& f = inputs.frames[k];
    Loaded l;
    l.image = Undistort(ReadImage(f.image, intrinsics), intrinsics, false);
    PointCloudReadStats stats;
    l.cloud = ReadPointCloud(f.cloud, max_points, &stats);
    points_read += stats.points_in_file;
    non_finite += stats.non_finite;
    // An all-NaN cloud used to count as a frame and pull the score towards noise.
    if (stats.finite() < kMinFramePoints) {
      err << "autoshovel calibrate camera-lidar: warning: " << f.cloud << ": " << stats.finite()
          << " of " << stats.points_in_file << " points are finite (" << stats.non_finite
          << " NaN or infinite dropped), fewer than the " << kMinFramePoints
          << " a frame needs: frame '" << f.name << "' skipped\n";
      ++skipped;
      continue;
    }
    std::string mask_path = builtin ? "" : inputs.mask_paths[k];
    for (const std::string& candidate :
         {masks_root + "/" + f.name, masks_root + "/" + f.name + ".png",
          masks_root + "/" + f.name + ".json"}) {
      if (!masks_root.empty() && mask_path.empty() && fs::exists(candidate)) mask_path = candidate;
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
    Fail(inputs.frames_folder.empty() ? inputs.frames.front().cloud : inputs.frames_folder, 0,
         "no usable frame: all " + std::to_string(inputs.frames.size()) +
             " point clouds have fewer than " + std::to_string(kMinFramePoints) + " finite points");
  }
  return loaded;
}

// The points that can matter: those projecting into the image enlarged by `margin_px` at T0 (a
// spinning LiDAR's cloud is 360°, the camera sees a sixth of it). Scoring, normals, planes and
// depth edges then work on the camera's view only: 4–6 times less work per evaluation. The
// margin covers the search range (4° at f = 2000 px is 140 px).
sensors::PointCloud CropToView(const sensors::PointCloud& cloud, const CameraIntrinsics& pinhole,
                               const Eigen::Isometry3d& T_lidar_camera, double margin_px) {
  sensors::PointCloud out = cloud;
  out.points.clear();
  const Eigen::Isometry3d T = OpticalFromLidar(T_lidar_camera);
  for (const auto& point : cloud.points) {
    const Eigen::Vector3d p = T * point.p_sensor.cast<double>();
    if (p.z() < 0.1) continue;
    const double u = pinhole.K(0, 0) * p.x() / p.z() + pinhole.K(0, 2);
    const double v = pinhole.K(1, 1) * p.y() / p.z() + pinhole.K(1, 2);
    if (u < -margin_px || v < -margin_px || u > pinhole.width + margin_px ||
        v > pinhole.height + margin_px) {
      continue;
    }
    out.points.push_back(point);
  }
  return out;
}

std::string ExtrinsicErrorText(const Eigen::Isometry3d& T_ref_optical_lidar,
                               const Eigen::Isometry3d& T_optical_lidar) {
  const ProtocolError e = CompareExtrinsics(T_ref_optical_lidar, T_optical_lidar);
  const Eigen::Isometry3d E = T_ref_optical_lidar * T_optical_lidar.inverse();
  const Eigen::Vector3d rpy = RollPitchYaw(E.linear()) / kDeg;
  char text[200];
  std::snprintf(text, sizeof text,
                "%.3f deg %.1f mm (optical frame: rpy %+.2f %+.2f %+.2f deg, xyz %+.0f %+.0f "
                "%+.0f mm)",
                e.rotation / kDeg, 1e3 * e.translation, rpy.x(), rpy.y(), rpy.z(),
                1e3 * E.translation().x(), 1e3 * E.translation().y(), 1e3 * E.translation().z());
  return text;
}

void PrintSliceTable(const std::vector<ScoreSlice>& slices, std::ostream& out) {
  out << "  score slices around the start (rho and its terms; argmax per axis):\n"
      << "  | axis | argmax rho | argmax F_R | argmax F_N | argmax F_S | argmax f | rho(0) | "
         "max rho |\n  | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  auto argmax = [](const ScoreSlice& s, const std::vector<double>& v) {
    return s.offsets[static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin())];
  };
  char line[256];
  for (const ScoreSlice& s : slices) {
    const std::size_t middle = s.rho.size() / 2;
    const char* unit = s.parameter.rfind("rot", 0) == 0 ? "deg" : "m";
    std::snprintf(line, sizeof line,
                  "  | %s [%s] | %+.3g | %+.3g | %+.3g | %+.3g | %+.3g | %.5f | %.5f |\n",
                  s.parameter.c_str(), unit, argmax(s, s.rho), argmax(s, s.reflectivity),
                  argmax(s, s.normal), argmax(s, s.segmentation), argmax(s, s.size), s.rho[middle],
                  *std::max_element(s.rho.begin(), s.rho.end()));
    out << line;
  }
}

void PrintFeatureSummary(const std::vector<ScoreFrame>& frames, std::ostream& out) {
  // The floor's noise decides how the ground class is made (cloud_features.h); a user with a
  // noisy or a very clean LiDAR sees it here.
  double noise_lo = INFINITY, noise_hi = 0;
  int k_lo = std::numeric_limits<int>::max(), k_hi = 0, segments = 0;
  for (const ScoreFrame& f : frames) {
    noise_lo = std::min(noise_lo, f.ground_noise);
    noise_hi = std::max(noise_hi, f.ground_noise);
    k_lo = std::min(k_lo, f.ground_smoothing_neighbours);
    k_hi = std::max(k_hi, f.ground_smoothing_neighbours);
    segments += f.num_segments;
  }
  char line[200];
  std::snprintf(line, sizeof line,
                "  cloud segments %d; floor noise sigma %.1f-%.1f mm: ground class on heights "
                "averaged over %d-%d neighbours\n",
                segments, 1e3 * noise_lo, 1e3 * noise_hi, k_lo, k_hi);
  out << line;
}

void WriteResults(const CalibrateCameraLidarOptions& options, const Inputs& inputs,
                  const model::MachineDescription* machine, const model::Lidar* lidar,
                  const Eigen::Isometry3d& T_base_lidar, const std::vector<Loaded>& loaded,
                  const std::vector<ScoreFrame>& score_frames, const CameraIntrinsics& pinhole,
                  const Eigen::Isometry3d& T0, const AutoCalibrationResult& result,
                  const std::vector<ScoreSlice>& slices, const BoardCalibration& board_result,
                  std::ostream& out) {
  const std::string overlay =
      options.overlay.empty() ? inputs.output_root + "/camera_lidar.overlay.yaml" : options.overlay;
  const std::string stem = fs::path(overlay).replace_extension("").string();
  const std::string png = options.png.empty() ? stem + ".projection.png" : options.png;
  const std::string residuals_png =
      options.residuals_png.empty() ? stem + ".surface.png" : options.residuals_png;
  const std::string extrinsic =
      options.extrinsic_out.empty() ? stem + ".extrinsic.txt" : options.extrinsic_out;
  for (const std::string& path : {overlay, png, residuals_png, extrinsic, options.slices_png}) {
    const fs::path folder = fs::path(path).parent_path();
    if (!path.empty() && !folder.empty()) core::CreateFolders(folder);
  }
  const Eigen::Isometry3d T_optical_lidar = OpticalFromLidar(result.T_lidar_camera);
  char line[256];
  std::snprintf(line, sizeof line,
                "LiDAR -> camera (OpenCV optical frame: x right, y down, z forward), "
                "p_camera = T p_lidar\nconsistency score rho %.4f (start %.4f)",
                result.final.rho, result.initial.rho);
  WriteFileAtomically(extrinsic, ExtrinsicText(T_optical_lidar, std::string("autoshovel calibrate "
                                                                            "camera-lidar\n") +
                                                                    line));
  if (machine != nullptr) {
    const Eigen::Isometry3d T_base_camera = T_base_lidar * result.T_lidar_camera;
    std::string text = OverlayHeader(
        *machine, "autoshovel calibrate camera-lidar --frames " +
                      (options.frames.empty() ? std::string("(pairs)") : options.frames));
    text += "# camera pose = pose of LiDAR " + lidar->name + " (description) * T_lidar_camera " +
            PoseText(result.T_lidar_camera) + "\n";
    std::snprintf(line, sizeof line,
                  "# consistency score rho %.4f (start %.4f); rho stays within 0.5 %% of its "
                  "peak over",
                  result.final.rho, result.initial.rho);
    text += line;
    for (const ScoreSlice& s : slices) {
      std::snprintf(line, sizeof line, " %s +/-%.3g", s.parameter.c_str(), BasinHalfWidth(s));
      text += line;
    }
    text += " (deg, m)\nsensors:\n  camera:\n    pose: " + PoseText(T_base_camera) + "\n";
    WriteFileAtomically(overlay, text);
    out << "overlay: " << overlay << "\n";
  }
  WriteBeforeAfterPng(png, loaded.front().image, score_frames.front().points, pinhole.K, T0,
                      result.T_lidar_camera);
  const std::string edges_png = stem + ".edges.png";
  plot::WriteImageFile(
      edges_png, RenderEdges(loaded.front().image, score_frames.front(), result.T_lidar_camera));
  const std::string slices_png = options.slices_png.empty() ? residuals_png : options.slices_png;
  WriteScoreSurfacePng(slices_png, slices, board_result.residuals);
  {
    std::ostringstream csv;
    csv << "axis,offset,rho,F_R,F_N,F_S,size\n";
    for (const ScoreSlice& sl : slices) {
      for (std::size_t i = 0; i < sl.offsets.size(); ++i) {
        std::snprintf(line, sizeof line, "%s,%.6g,%.6f,%.6f,%.6f,%.6f,%.6f\n", sl.parameter.c_str(),
                      sl.offsets[i], sl.rho[i], sl.reflectivity[i], sl.normal[i],
                      sl.segmentation[i], sl.size[i]);
        csv << line;
      }
    }
    WriteFileAtomically(fs::path(slices_png).replace_extension(".csv"), csv.str());
  }
  out << "extrinsic (4x4 LiDAR -> camera optical): " << extrinsic
      << "\nprojection before/after: " << png << "\nscore surface and board residuals: "
      << (options.slices_png.empty() ? residuals_png : options.slices_png) << "\n";
}

// Per mask: its points and terms at T, and for each axis the offset where its own contribution
// |P_i| ε_i peaks (a mask pulling away from T shows here).
void PrintMaskTable(const std::vector<ScoreFrame>& frames, const Eigen::Isometry3d& T,
                    const ScoreOptions& options, std::ostream& out) {
  const ScoreBreakdown at = ConsistencyScore(frames, T, options);
  std::map<std::pair<int, int>, std::array<double, 6>> peak_offset, peak_value;
  const char* names[6] = {"rot_x", "rot_y", "rot_z", "x", "y", "z"};
  for (int k = 0; k < 6; ++k) {
    const double half = k < 3 ? 1.0 : 0.05;
    for (int i = 0; i <= 20; ++i) {
      const double offset = -half + half * i / 10.0;
      Eigen::Vector3d w = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
      if (k < 3) {
        w[k] = offset * kDeg;
      } else {
        t[k - 3] = offset;
      }
      const ScoreBreakdown b = ConsistencyScore(frames, Perturb(T, w, t), options);
      for (const MaskScore& m : b.masks) {
        const double value = static_cast<double>(m.n) * m.epsilon;
        auto& best = peak_value[{m.frame, m.mask}];
        if (i == 0 || value > best[k]) {
          best[k] = value;
          peak_offset[{m.frame, m.mask}][k] = offset;
        }
      }
    }
  }
  std::vector<MaskScore> masks = at.masks;
  std::sort(masks.begin(), masks.end(),
            [](const MaskScore& a, const MaskScore& b) { return a.n > b.n; });
  out << "  masks at the start (largest first) and where each one's n*eps peaks (+/-1 deg, "
         "+/-5 cm):\n  | frame/mask | n | F_R | F_N | F_S |";
  for (const char* n : names) out << " " << n << " |";
  out << "\n";
  char line[160];
  for (const MaskScore& m : masks) {
    std::snprintf(line, sizeof line, "  | %d/%d | %ld | %.3f | %.3f | %.3f |", m.frame, m.mask, m.n,
                  m.f_r, m.f_n, m.f_s);
    out << line;
    for (int k = 0; k < 6; ++k) {
      std::snprintf(line, sizeof line, " %+.3g |", peak_offset[{m.frame, m.mask}][k]);
      out << line;
    }
    out << "\n";
  }
}

}  // namespace

int RunCalibrateCameraLidar(const CalibrateCameraLidarOptions& options, std::ostream& out,
                            std::ostream& err) {
  const char* const kCommand = "autoshovel calibrate camera-lidar";
  try {
    std::optional<model::MachineDescription> machine;
    const model::Lidar* lidar = nullptr;
    if (!options.machine.empty()) {
      machine = model::LoadMachineDescription(
          model::ResolveMachineDescription(options.machine, options.models_dir));
      for (const auto& l : machine->sensors.lidars) {
        if (l.name == options.lidar) lidar = &l;
      }
      if (lidar == nullptr) {
        err << kCommand << ": " << machine->name << " has no LiDAR '" << options.lidar << "'\n";
        return 2;
      }
    }
    if (!options.simulate.empty()) {
      if (machine) {
        Simulate(*machine, *lidar, options, out);
      } else {
        SimulateStreetScene(options, out);
      }
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
    if (!options.perturb.empty() && options.perturb.size() != 6) {
      err << kCommand << ": --perturb needs 6 values: roll pitch yaw [deg] x y z [m]\n";
      return 2;
    }
    const Inputs inputs = ResolveInputs(options);
    if (inputs.frames.empty()) {
      err << kCommand
          << ": give --frames DIR, --pair IMAGE,CLOUD or --scene DIR (or --simulate DIR)\n";
      return 2;
    }
    std::optional<RigCalibrationFile> calib;
    if (!inputs.calib.empty()) calib = ReadCalibTxt(inputs.calib);
    const CameraIntrinsics intrinsics = ResolveIntrinsics(
        options, inputs, calib ? &*calib : nullptr, machine ? &*machine : nullptr);

    // The LiDAR's mounting and gravity's up axis are known from a description only; a
    // standalone rig's cloud is segmented without them (cloud_features.h).
    const Eigen::Isometry3d T_base_lidar =
        lidar != nullptr ? sensors::PoseToIsometry(lidar->pose) : Eigen::Isometry3d::Identity();
    std::optional<Eigen::Vector3d> up_lidar;
    if (lidar != nullptr) up_lidar = T_base_lidar.linear().transpose() * Eigen::Vector3d::UnitZ();

    std::size_t points_read = 0, non_finite = 0, skipped = 0;
    const std::vector<Loaded> loaded =
        LoadFrames(inputs, options.masks, intrinsics, options.max_points, err, points_read,
                   non_finite, skipped);
    // The masks are already undistorted: score with an undistorted camera.
    CameraIntrinsics pinhole = intrinsics;
    pinhole.D.clear();

    // Step 1: the start. --initial, --initial-matrix, the board, calib.txt's T, the description.
    Eigen::Isometry3d T0 = Eigen::Isometry3d::Identity();
    std::string start;
    BoardCalibration board_result;
    if (!options.initial.empty()) {
      model::Pose3 pose;
      for (int i = 0; i < 3; ++i) {
        pose.xyz[i] = options.initial[i];
        pose.rpy[i] = options.initial[3 + i] * kDeg;
      }
      T0 = sensors::PoseToIsometry(pose);
      start = "--initial";
    } else if (!options.initial_matrix.empty()) {
      T0 = CameraInLidarFromOptical(ReadExtrinsic(options.initial_matrix));
      start = options.initial_matrix;
    } else if (!options.correspondences.empty()) {
      const std::vector<Correspondence> pairs = ReadCorrespondences(options.correspondences);
      const CorrespondencePnP pnp = SolveCorrespondencePnP(pairs, intrinsics);
      if (!pnp.calibration.ok) Fail(options.correspondences, 0, pnp.calibration.failure);
      board_result = pnp.calibration;
      T0 = pnp.calibration.T_lidar_camera;
      char line[200];
      std::snprintf(line, sizeof line,
                    "PnP on %d of %d correspondences (RANSAC inliers), reprojection RMS %.3f px",
                    pnp.inliers, pnp.total, pnp.calibration.reprojection_rms);
      start = line;
    } else if (!options.board.empty()) {
      if (!up_lidar) {
        err << kCommand << ": --board needs --machine (the LiDAR's up axis and boresight)\n";
        return 2;
      }
      const Eigen::Isometry3d T_nominal =
          T_base_lidar.inverse() * sensors::PoseToIsometry(machine->sensors.camera.pose);
      const BoardGeometry board = ReadBoardYaml(options.board + "/board.yaml");
      std::vector<BoardObservation> observations;
      const Eigen::Vector3d boresight = T_nominal.linear().col(0);
      for (const FramePaths& f : ListFrames(options.board)) {
        const cv::Mat image = Undistort(ReadImage(f.image, intrinsics), intrinsics, false);
        const sensors::PointCloud cloud = ReadPointCloud(f.cloud, 0);
        std::vector<Eigen::Vector3f> points;
        for (const auto& p : cloud.points) points.push_back(p.p_sensor);
        const BoardCloudDetection c = DetectBoardInCloud(points, board, *up_lidar, boresight);
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
    } else if (calib && calib->T_optical_lidar) {
      T0 = CameraInLidarFromOptical(*calib->T_optical_lidar);
      start = inputs.calib + " (T:)";
    } else if (machine) {
      T0 = T_base_lidar.inverse() * sensors::PoseToIsometry(machine->sensors.camera.pose);
      start = "the description's nominal mounting";
    } else {
      err << kCommand
          << ": no start: give --initial-matrix FILE, --calib calib.txt with a T: line, "
             "--initial x y z roll pitch yaw or --machine\n";
      return 2;
    }
    // The reference errors are reported against: --reference, else the unperturbed start.
    std::optional<Eigen::Isometry3d> T_ref_optical_lidar;
    if (!options.reference.empty()) {
      T_ref_optical_lidar = ReadExtrinsic(options.reference);
    } else if (!options.perturb.empty()) {
      T_ref_optical_lidar = OpticalFromLidar(T0);
    }
    if (!options.perturb.empty()) {
      const Eigen::Isometry3d delta = ProtocolDelta(
          Eigen::Vector3d(options.perturb[0], options.perturb[1], options.perturb[2]) * kDeg,
          Eigen::Vector3d(options.perturb[3], options.perturb[4], options.perturb[5]));
      T0 = CameraInLidarFromOptical(OpticalFromLidar(T0) * delta);
      start += " perturbed by --perturb";
    }

    // Step 2: Algorithm 1 lines 7–27.
    AutoCalibrationOptions auto_options;
    CloudFeatureOptions feature_options;
    MaskPreparationOptions mask_options;
    std::vector<ScoreFrame> score_frames;
    for (const Loaded& l : loaded) {
      const double margin = 0.15 * std::max(pinhole.width, pinhole.height);
      score_frames.push_back(PrepareScoreFrame(CropToView(l.cloud, pinhole, T0, margin), l.masks,
                                               pinhole, up_lidar, 0, feature_options,
                                               mask_options));
    }
    auto_options.lock = lock;
    if (options.protocol) {
      // Around the reference: --reference, else the start (before any --perturb).
      const Eigen::Isometry3d T_ref =
          T_ref_optical_lidar ? CameraInLidarFromOptical(*T_ref_optical_lidar) : T0;
      out << "camera-lidar perturbation protocol, " << loaded.size() << " frames, +/-"
          << options.protocol_rotation << " deg and +/-" << options.protocol_translation
          << " m per axis around " << (options.reference.empty() ? start : options.reference)
          << "\n";
      PrintProtocol(
          RunPerturbationProtocol(score_frames, T_ref, auto_options, options.protocol_rotation,
                                  options.protocol_translation),
          out);
      return 0;
    }
    // The sky term (consistency_score.h): flagged once at T0 so that the optimisation and the
    // score surface below score the same ρ.
    if (auto_options.unsupported_density > 0) {
      MarkUnsupportedMasks(score_frames, T0, auto_options.unsupported_density);
    }
    AutoCalibrationResult result;
    if (options.evaluate_only) {
      result.T_lidar_camera = T0;
      result.initial = result.final = ConsistencyScore(score_frames, T0, auto_options.score);
    } else {
      result = AutoCalibrate(score_frames, T0, auto_options);
    }
    const std::vector<ScoreSlice> slices =
        ScoreSurface(score_frames, result.T_lidar_camera, auto_options.score, 2.0, 0.1, 41);

    char line[256];
    out << "camera-lidar calibration of "
        << (machine ? machine->name + " (" + lidar->name + ")" : std::string("a standalone rig"))
        << ", " << loaded.size() << " frames";
    if (skipped > 0) {
      out << " (" << skipped << " of " << inputs.frames.size()
          << " skipped: too few finite points)";
    }
    out << ", masks: " << loaded.front().mask_source << (loaded.size() > 1 ? ", ..." : "") << "\n";
    if (non_finite > 0) {
      out << "  clouds: " << non_finite << " of " << points_read
          << " points dropped for a NaN or infinite coordinate\n";
    }
    out << "  start: " << start << "\n";
    PrintFeatureSummary(score_frames, out);
    out << "  T_lidar_camera start " << PoseText(T0) << "\n";
    out << "  T_lidar_camera final " << PoseText(result.T_lidar_camera) << "\n";
    std::snprintf(line, sizeof line,
                  "  rho %.4f -> %.4f (F_R %.3f, F_N %.3f, F_S %.3f; %d masks, %ld points), %d "
                  "evaluations, %d Nelder-Mead runs, %.1f s\n",
                  result.initial.rho, result.final.rho, result.final.reflectivity,
                  result.final.normal, result.final.segmentation, result.final.masks_used,
                  result.final.points_in_masks, result.evaluations, result.runs, result.seconds);
    out << line;
    if (auto_options.staged && !options.evaluate_only) {
      std::snprintf(
          line, sizeof line,
          "  translation stage: gain %.5f, %.1f standard errors over %d masks: %s\n",
          result.translation_gain.gain,
          result.translation_gain.gain / std::max(1e-12, result.translation_gain.standard_error),
          result.translation_gain.masks,
          result.translation_kept ? "kept" : "not carried by the scene: a local refinement");
      out << line;
    }
    out << "  score surface (rho within 0.5 % of its peak):";
    for (const ScoreSlice& s : slices) {
      std::snprintf(line, sizeof line, " %s +/-%.3g%s", s.parameter.c_str(), BasinHalfWidth(s),
                    s.parameter.rfind("rot", 0) == 0 ? " deg" : " m");
      out << line;
    }
    out << "\n";
    if (fs::exists(inputs.root + "/truth.yaml")) {
      const PoseError e =
          ComparePoses(result.T_lidar_camera, ReadTruth(inputs.root + "/truth.yaml"));
      const PoseError e0 = ComparePoses(T0, ReadTruth(inputs.root + "/truth.yaml"));
      std::snprintf(line, sizeof line,
                    "  against the simulation truth: start %.3f deg %.1f mm, final %.3f deg "
                    "%.1f mm\n",
                    e0.rotation / kDeg, 1e3 * e0.translation, e.rotation / kDeg,
                    1e3 * e.translation);
      out << line;
    }
    if (T_ref_optical_lidar) {
      out << "  against the reference (T_ref * T_est^-1): start "
          << ExtrinsicErrorText(*T_ref_optical_lidar, OpticalFromLidar(T0)) << ", final "
          << ExtrinsicErrorText(*T_ref_optical_lidar, OpticalFromLidar(result.T_lidar_camera))
          << "\n";
    }
    if (options.evaluate_only || !options.slices_png.empty()) PrintSliceTable(slices, out);
    if (options.evaluate_only) {
      PrintMaskTable(score_frames, result.T_lidar_camera, auto_options.score, out);
    }
    WriteResults(options, inputs, machine ? &*machine : nullptr, lidar, T_base_lidar, loaded,
                 score_frames, pinhole, T0, result, slices, board_result, out);
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
