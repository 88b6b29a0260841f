#include "runtime/recording/recording_writer.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <system_error>

#include "runtime/core/file_output.h"
#include "runtime/core/sha256.h"
#include "runtime/core/strings.h"
#include "runtime/recording/replay_check.h"

namespace autoshovel::recording {

namespace {

std::string Num(double v) { return core::FormatNumber(v); }

std::string PaddedUpdate(long update) {
  char name[32];
  std::snprintf(name, sizeof name, "%06ld", update);
  return name;
}

std::string PngBytes(const cv::Mat& image, const std::filesystem::path& path) {
  std::vector<std::uint8_t> buffer;
  if (!cv::imencode(".png", image, buffer)) {
    throw core::OutputError(path, "OpenCV could not encode the PNG");
  }
  return {buffer.begin(), buffer.end()};
}

std::string FrameRowText(const FrameRow& f) {
  const Eigen::Vector3d t = f.T_world_sensor.translation();
  const Eigen::Matrix3d R = f.T_world_sensor.linear();
  std::string row = std::to_string(f.update) + "," +
                    (f.kind == FrameRow::Kind::kLidar ? "lidar" : "camera") + "," + f.sensor + "," +
                    Num(f.stamp) + "," + f.file + "," + f.labels_file + "," +
                    (f.health_check ? "1" : "0");
  for (int i = 0; i < 3; ++i) row += "," + Num(t[i]);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) row += "," + Num(R(r, c));
  }
  return row + "\n";
}

std::string UpdateRowText(const UpdateRow& u) {
  std::string row = std::to_string(u.update) + "," + std::to_string(u.cycle) + "," + Num(u.stamp) +
                    "," + Num(u.hinge_xy.x()) + "," + Num(u.hinge_xy.y()) + "," + Num(u.heading) +
                    "," + Num(u.articulation) + "," + Num(u.tip_reach) + "," +
                    (u.select ? "1" : "0");
  if (u.select) {
    row += "," + Num(u.select_xy.x()) + "," + Num(u.select_xy.y()) + "," + Num(u.select_heading);
  } else {
    row += ",,,";
  }
  return row + "\n";
}

std::string Pair(const Eigen::Vector2d& v) { return "[" + Num(v.x()) + ", " + Num(v.y()) + "]"; }

// Names go into YAML double-quoted: escape what would end or break the scalar.
std::string Quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out.push_back(c);
  }
  return out + "\"";
}

std::string ManifestText(const Manifest& m) {
  const planning::ShovelPointConfig& s = m.selection;
  std::string y;
  y += "# A recorded run (docs/recording_format.md): replay it with `autoshovel replay DIR`.\n";
  y += std::string("format: ") + kFormatName + "\n";
  y += "version: " + std::to_string(kFormatVersion) + "\n";
  y += "machine: " + Quoted(m.machine_file) + "\n";
  if (!m.overlays.empty()) {
    y += "overlays: [";
    for (std::size_t i = 0; i < m.overlays.size(); ++i) {
      y += (i > 0 ? ", " : "") + Quoted(m.overlays[i]);
    }
    y += "]\n";
  }
  y += "source: " + Quoted(m.source) + "\n";
  y += "map:\n";
  y += "  resolution: " + Num(m.map_resolution) + "\n";
  y += "  length: " + Pair(m.map_length) + "\n";
  y += "  center: " + Pair(m.map_center) + "\n";
  if (m.truth_labels) {
    y += "perception: {semantics: " + std::string(*m.truth_labels ? "labels" : "network") +
         ", segmentation_scale: " + Num(m.segmentation_scale) + "}\n";
  }
  y += "selection:\n";
  y += "  method: " + std::string(m.chen2024 ? "chen2024" : "ours") + "\n";
  y += "  min_planned_clearance: " + Num(m.min_planned_clearance) + "\n";
  auto field = [&y](const char* name, double v) {
    y += std::string("  ") + name + ": " + Num(v) + "\n";
  };
  field("k_t", s.k_t);
  field("k_s", s.k_s);
  field("k_c", s.k_c);
  field("k_e", s.k_e);
  field("k_a", s.k_a);
  field("torque_threshold", s.torque_threshold);
  field("safety_distance", s.safety_distance);
  field("max_curvature", s.max_curvature);
  field("candidate_spacing", s.candidate_spacing);
  y += "  entry_angle_offsets: [";
  for (std::size_t i = 0; i < s.entry_angle_offsets.size(); ++i) {
    y += (i > 0 ? ", " : "") + Num(s.entry_angle_offsets[i]);
  }
  y += "]\n";
  field("normal_radius", s.normal_radius);
  field("penetration_length", s.penetration_length);
  field("scoop_advance", s.scoop_advance);
  field("crowd_stop_distance", s.crowd_stop_distance);
  field("concavity_tolerance", s.concavity_tolerance);
  field("entry_window", s.entry_window);
  field("path_spacing", s.path_spacing);
  field("max_drive_over_height", s.max_drive_over_height);
  y += "cycles:\n";
  for (const CycleInfo& c : m.cycles) {
    y += "  - index: " + std::to_string(c.index) + "\n";
    y += "    site: " + Quoted(c.site) + "\n";
    if (c.scoop) {
      y += "    scoop: {material: " + Quoted(c.scoop->material) +
           ", target_volume: " + Num(c.scoop->target_volume) +
           ", bucket_max: " + Num(c.scoop->bucket_max) + ", boom_lift: " + Num(c.scoop->boom_lift) +
           "}\n";
    }
    if (c.area.kind == WorkArea::Kind::kRectangle) {
      y += "    rectangle: {front_center: " + Pair(c.area.front_center) +
           ", yaw: " + Num(c.area.yaw) + ", width: " + Num(c.area.width) +
           ", depth: " + Num(c.area.depth) + "}\n";
    } else {
      y += "    discs:\n";
      for (const Eigen::Vector3d& d : c.area.discs) {
        y += "      - [" + Num(d.x()) + ", " + Num(d.y()) + ", " + Num(d.z()) + "]\n";
      }
    }
  }
  return y;
}

}  // namespace

std::string LidarPcdBytes(const sensors::PointCloud& cloud) {
  // Written here rather than by pcl::io: the header is ten lines, and the bytes go through
  // core::WriteFileAtomically like every file the project writes.
  const std::size_t n = cloud.points.size();
  std::string out =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
      "FIELDS x y z intensity ring time_offset\nSIZE 4 4 4 4 2 4\n"
      "TYPE F F F F U F\nCOUNT 1 1 1 1 1 1\nWIDTH " +
      std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) +
      "\nDATA binary\n";
  constexpr std::size_t kPointBytes = 22;
  const std::size_t start = out.size();
  out.resize(start + n * kPointBytes);
  char* p = out.data() + start;
  for (const sensors::LidarPoint& q : cloud.points) {
    const float xyzi[4] = {q.p_sensor.x(), q.p_sensor.y(), q.p_sensor.z(), q.intensity};
    std::memcpy(p, xyzi, 16);
    std::memcpy(p + 16, &q.ring, 2);
    std::memcpy(p + 18, &q.time_offset, 4);
    p += kPointBytes;
  }
  return out;
}

RecordingWriter::RecordingWriter(std::filesystem::path dir, const std::string& description_path,
                                 Manifest manifest)
    : dir_(std::move(dir)), manifest_(std::move(manifest)) {
  std::error_code ec;
  if (std::filesystem::exists(dir_, ec) && !std::filesystem::is_empty(dir_, ec)) {
    throw std::invalid_argument(dir_.string() +
                                ": the recording folder must be new or empty (it holds files)");
  }
  core::CreateFolders(dir_);
  manifest_.machine_file = "machine.yaml";
  core::WriteFileAtomically(dir_ / manifest_.machine_file, core::ReadFileBytes(description_path));
  updates_csv_ = std::string(kUpdatesHeader) + "\n";
  frames_csv_ = std::string(kFramesHeader) + "\n";
  digests_csv_ = std::string(kMapDigestsHeader) + "\n";
  selections_csv_ = std::string(kSelectionsHeader) + "\n";
  scoop_csv_ = std::string(kScoopHeader) + "\n";
  tip_path_csv_ = std::string(kTipPathHeader) + "\n";
  predictions_csv_ = std::string(kPredictionsHeader) + "\n";
}

void RecordingWriter::AddOverlay(const std::string& overlay_path) {
  const std::string name = "overlay_" + std::to_string(manifest_.overlays.size()) + "_" +
                           std::filesystem::path(overlay_path).filename().string();
  core::WriteFileAtomically(dir_ / name, core::ReadFileBytes(overlay_path));
  manifest_.overlays.push_back(name);
}

void RecordingWriter::SetScoop(const ScoopInfo& scoop) {
  if (manifest_.cycles.empty()) throw std::logic_error("RecordingWriter: no cycle begun");
  manifest_.cycles.back().scoop = scoop;
}

void RecordingWriter::AddScoop(const std::vector<DecisionRow>& decisions,
                               const std::vector<double>& v1, const std::vector<double>& v2,
                               const std::vector<Eigen::Vector3d>& tip_path) {
  if (manifest_.cycles.empty()) throw std::logic_error("RecordingWriter: no cycle begun");
  if (v1.size() != decisions.size() || v2.size() != decisions.size()) {
    throw std::invalid_argument("RecordingWriter::AddScoop: one V1 and V2 per decision");
  }
  const int cycle = manifest_.cycles.back().index;
  const std::string c = std::to_string(cycle);
  for (std::size_t i = 0; i < decisions.size(); ++i) {
    const DecisionRow& d = decisions[i];
    scoop_csv_ += c + "," + Num(d.time) + "," + Num(d.hinge_xy.x()) + "," + Num(d.hinge_xy.y()) +
                  "," + Num(d.heading) + "," + Num(d.speed) + "," + Num(d.q_boom) + "," +
                  Num(d.q_bucket) + "," + std::to_string(d.path_points) + "," +
                  (d.predict ? "1" : "0") + "\n";
    predictions_csv_ += PredictionRow(cycle, d.time, v1[i], v2[i]) + "\n";
  }
  for (const Eigen::Vector3d& p : tip_path) {
    tip_path_csv_ += c + "," + Num(p.x()) + "," + Num(p.y()) + "," + Num(p.z()) + "\n";
  }
}

void RecordingWriter::SetPerception(bool truth_labels, double segmentation_scale) {
  manifest_.truth_labels = truth_labels;
  manifest_.segmentation_scale = segmentation_scale;
}

void RecordingWriter::SetSelection(const planning::ShovelPointConfig& config,
                                   double min_planned_clearance, bool chen2024) {
  manifest_.selection = config;
  manifest_.min_planned_clearance = min_planned_clearance;
  manifest_.chen2024 = chen2024;
}

void RecordingWriter::BeginCycle(const CycleInfo& cycle) { manifest_.cycles.push_back(cycle); }

long RecordingWriter::AddUpdate(UpdateRow row, const perception::SensorFrames& frames,
                                const std::string& camera_name) {
  if (manifest_.cycles.empty()) throw std::logic_error("RecordingWriter: no cycle begun");
  row.update = next_update_++;
  row.cycle = manifest_.cycles.back().index;
  const std::string stem = PaddedUpdate(row.update);
  int k = 0;
  for (const perception::LidarFrame& lidar : frames.lidar) {
    FrameRow f;
    f.update = row.update;
    f.kind = FrameRow::Kind::kLidar;
    f.sensor = lidar.lidar;
    f.stamp = lidar.stamp;
    f.file = "lidar/" + lidar.lidar + "/" + stem + "_" + std::to_string(k++) + ".pcd";
    f.health_check = !lidar.health_check_rays.empty();
    f.T_world_sensor = lidar.T_world_lidar;
    core::CreateFolders((dir_ / f.file).parent_path());
    core::WriteFileAtomically(dir_ / f.file, LidarPcdBytes(lidar.cloud));
    frames_csv_ += FrameRowText(f);
  }
  if (frames.camera) {
    const sensors::CameraFrame& image = *frames.camera;
    FrameRow f;
    f.update = row.update;
    f.kind = FrameRow::Kind::kCamera;
    f.sensor = camera_name;
    f.stamp = image.stamp;
    f.file = "camera/" + stem + ".png";
    f.T_world_sensor = frames.T_world_camera;
    core::CreateFolders(dir_ / "camera");
    const cv::Mat bgr(image.height, image.width, CV_8UC3,
                      const_cast<std::uint8_t*>(image.bgr.data()));
    core::WriteFileAtomically(dir_ / f.file, PngBytes(bgr, dir_ / f.file));
    if (!image.labels.empty()) {
      f.labels_file = "camera/" + stem + "_labels.png";
      const cv::Mat labels(image.height, image.width, CV_8UC1,
                           const_cast<std::uint8_t*>(image.labels.data()));
      core::WriteFileAtomically(dir_ / f.labels_file, PngBytes(labels, dir_ / f.labels_file));
    }
    frames_csv_ += FrameRowText(f);
  }
  updates_csv_ += UpdateRowText(row);
  return row.update;
}

void RecordingWriter::AddReference(const std::string& map_digest_row,
                                   const std::string& selection_row) {
  digests_csv_ += map_digest_row + "\n";
  if (!selection_row.empty()) selections_csv_ += selection_row + "\n";
}

void RecordingWriter::Close() {
  if (closed_) return;
  core::WriteFileAtomically(dir_ / "updates.csv", updates_csv_);
  core::WriteFileAtomically(dir_ / "frames.csv", frames_csv_);
  core::CreateFolders(dir_ / "reference");
  core::WriteFileAtomically(dir_ / "reference" / "map_digests.csv", digests_csv_);
  core::WriteFileAtomically(dir_ / "reference" / "selections.csv", selections_csv_);
  core::WriteFileAtomically(dir_ / "reference" / "predictions.csv", predictions_csv_);
  core::WriteFileAtomically(dir_ / "scoop.csv", scoop_csv_);
  core::WriteFileAtomically(dir_ / "tip_path.csv", tip_path_csv_);
  core::WriteFileAtomically(dir_ / "recording.yaml", ManifestText(manifest_));
  closed_ = true;
}

}  // namespace autoshovel::recording
