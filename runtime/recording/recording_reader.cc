#include "runtime/recording/recording_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <system_error>

#include "identification/camera_lidar/image_header.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/input_file.h"
#include "runtime/core/semantic_class.h"
#include "runtime/recording/csv_rows.h"
#include "runtime/recording/folder_checks.h"

namespace autoshovel::recording {

std::vector<std::string> Recording::overlay_paths() const {
  std::vector<std::string> paths;
  for (const std::string& overlay : manifest_.overlays) paths.push_back((dir_ / overlay).string());
  return paths;
}

Recording::Recording(const std::filesystem::path& dir) : dir_(dir) {
  std::error_code ec;
  const std::filesystem::path manifest = ManifestOf(dir_);
  manifest_ = ReadManifest(manifest);
  for (const std::string& overlay : manifest_.overlays) {
    if (!std::filesystem::is_regular_file(dir_ / overlay, ec)) {
      Refuse(manifest.string(), 0, 0, "overlays: " + (dir_ / overlay).string() + " is missing");
    }
  }
  const std::string updates_path = (dir_ / "updates.csv").string();
  updates_ = ParseUpdatesCsv(ReadTableFile(updates_path), updates_path);
  std::set<int> cycles;
  for (const CycleInfo& c : manifest_.cycles) cycles.insert(c.index);
  for (std::size_t i = 0; i < updates_.size(); ++i) {
    if (cycles.count(updates_[i].cycle) == 0) {
      Refuse(
          updates_path, updates_[i].line, 1,
          "cycle " + std::to_string(updates_[i].cycle) + " is not among recording.yaml's cycles");
    }
  }
  const std::string frames_path = (dir_ / "frames.csv").string();
  frames_ = ParseFramesCsv(ReadTableFile(frames_path), frames_path);
  frame_range_.assign(updates_.size(), {0, 0});
  std::size_t k = 0;
  for (std::size_t i = 0; i < updates_.size(); ++i) {
    frame_range_[i].first = k;
    int cameras = 0;
    while (k < frames_.size() && frames_[k].update == static_cast<long>(i)) {
      cameras += frames_[k].kind == FrameRow::Kind::kCamera;
      if (cameras > 1) {
        Refuse(frames_path, frames_[k].line, 1,
               "update " + std::to_string(i) + " has more than one camera frame");
      }
      ++k;
    }
    frame_range_[i].second = k;
  }
  if (k < frames_.size()) {
    Refuse(frames_path, frames_[k].line, 1,
           "update " + std::to_string(frames_[k].update) + " is not in updates.csv");
  }
  // The scoops (optional files: a recording whose cycles never scooped has none).
  std::error_code exists_ec;
  const std::filesystem::path scoop_path = dir_ / "scoop.csv";
  const std::filesystem::path tip_path = dir_ / "tip_path.csv";
  if (std::filesystem::exists(scoop_path, exists_ec)) {
    decisions_ = ParseScoopCsv(ReadTableFile(scoop_path), scoop_path.string());
    tip_path_ = ParseTipPathCsv(ReadTableFile(tip_path), tip_path.string());
  }
  std::map<int, long> points_of;
  for (const TipPoint& t : tip_path_) ++points_of[t.cycle];
  for (const DecisionRow& d : decisions_) {
    const CycleInfo* cycle = nullptr;
    for (const CycleInfo& c : manifest_.cycles) {
      if (c.index == d.cycle) cycle = &c;
    }
    if (cycle == nullptr || !cycle->scoop) {
      Refuse(scoop_path.string(), d.line, 1,
             "cycle " + std::to_string(d.cycle) +
                 " has no 'scoop' in recording.yaml (material, target volume)");
    }
    const long points = points_of[d.cycle];
    if (d.path_points > points) {
      Refuse(scoop_path.string(), d.line, 1,
             "path_points " + std::to_string(d.path_points) + " but tip_path.csv has " +
                 std::to_string(points) + " points of cycle " + std::to_string(d.cycle));
    }
  }
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    for (const std::string* file : {&frames_[i].file, &frames_[i].labels_file}) {
      if (file->empty()) continue;
      const std::string why = core::NotARegularFile(dir_ / *file);
      if (!why.empty()) {
        Refuse(frames_path, frames_[i].line, 1, *file + ": " + why);
      }
    }
  }
}

std::vector<Eigen::Vector3d> Recording::TipPathOf(int cycle) const {
  std::vector<Eigen::Vector3d> path;
  for (const TipPoint& t : tip_path_) {
    if (t.cycle == cycle) path.push_back(t.p);
  }
  return path;
}

std::vector<FrameRow> Recording::FramesOf(std::size_t i) const {
  return {frames_.begin() + static_cast<std::ptrdiff_t>(frame_range_.at(i).first),
          frames_.begin() + static_cast<std::ptrdiff_t>(frame_range_.at(i).second)};
}

sensors::PointCloud Recording::ReadLidar(const FrameRow& frame) const {
  sensors::PointCloud cloud = identification::ReadPointCloud((dir_ / frame.file).string());
  cloud.sensor = frame.sensor;
  cloud.stamp = frame.stamp;
  return cloud;
}

sensors::CameraFrame Recording::ReadCamera(const FrameRow& frame) const {
  const std::string path = (dir_ / frame.file).string();
  identification::ReadImageHeader(path);  // refuses a bitmap too large before decoding it
  cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty() || image.depth() != CV_8U) {
    Refuse(path, 0, 0, "OpenCV could not decode an 8-bit image");
  }
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  if (image.channels() != 3) Refuse(path, 0, 0, "expected a gray, BGR or BGRA image");
  sensors::CameraFrame out;
  out.stamp = frame.stamp;
  out.width = image.cols;
  out.height = image.rows;
  image = image.isContinuous() ? image : image.clone();
  out.bgr.assign(image.data, image.data + image.total() * 3);
  if (frame.labels_file.empty()) return out;
  const std::string labels_path = (dir_ / frame.labels_file).string();
  const identification::ImageHeader header = identification::ReadImageHeader(labels_path);
  if (header.width != out.width || header.height != out.height) {
    Refuse(labels_path, 0, 0,
           "labels are " + identification::ImageSizeText(header.width, header.height) +
               ", the image " + identification::ImageSizeText(out.width, out.height));
  }
  cv::Mat labels = cv::imread(labels_path, cv::IMREAD_UNCHANGED);
  if (labels.empty() || labels.type() != CV_8UC1) {
    Refuse(labels_path, 0, 0, "expected an 8-bit single-channel PNG of class ids");
  }
  labels = labels.isContinuous() ? labels : labels.clone();
  out.labels.assign(labels.data, labels.data + labels.total());
  for (const std::uint8_t c : out.labels) {
    if (c >= core::kNumSemanticClasses) {
      Refuse(labels_path, 0, 0,
             "class id " + std::to_string(c) + " is not a class (0.." +
                 std::to_string(core::kNumSemanticClasses - 1) + ")");
    }
  }
  return out;
}

}  // namespace autoshovel::recording
