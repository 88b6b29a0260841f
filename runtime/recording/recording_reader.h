// Reads a recording folder (recording_format.h, docs/recording_format.md). Everything is checked
// before a replay starts: the manifest strictly (unknown keys, ranges), every CSV row (one
// problem refuses the file at `file:line:column`), that every update's cycle and every frame's
// update exist, that frame files are relative paths inside the folder that exist. Frame files
// are decoded when asked for (ReadLidar, ReadCamera), each refused with its path.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "runtime/recording/csv_rows.h"
#include "runtime/recording/recording_format.h"
#include "runtime/recording/recording_tables.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::recording {

class Recording {
 public:
  /// Reads and cross-checks the folder. Throws core::InputError.
  explicit Recording(const std::filesystem::path& dir);

  const std::filesystem::path& dir() const { return dir_; }
  const Manifest& manifest() const { return manifest_; }
  std::filesystem::path machine_path() const { return dir_ / manifest_.machine_file; }
  /// The overlays' paths, in the order they apply.
  std::vector<std::string> overlay_paths() const;
  const std::vector<UpdateRow>& updates() const { return updates_; }
  /// Frames of updates()[i], in the order they are fused.
  std::vector<FrameRow> FramesOf(std::size_t i) const;
  std::size_t frame_count() const { return frames_.size(); }

  /// The scoops' trigger decisions (scoop.csv; none when the file is absent), and the tip path
  /// of cycle `cycle` (tip_path.csv).
  const std::vector<DecisionRow>& decisions() const { return decisions_; }
  std::vector<Eigen::Vector3d> TipPathOf(int cycle) const;

  /// A LiDAR frame's points (sensor frame) stamped with the row's stamp and sensor. Throws
  /// core::InputError naming the file.
  sensors::PointCloud ReadLidar(const FrameRow& frame) const;
  /// A camera frame (BGR, and the labels when the row names them). Throws core::InputError.
  sensors::CameraFrame ReadCamera(const FrameRow& frame) const;

 private:
  std::filesystem::path dir_;
  Manifest manifest_;
  std::vector<UpdateRow> updates_;
  std::vector<FrameRow> frames_;
  std::vector<DecisionRow> decisions_;
  std::vector<TipPoint> tip_path_;
  std::vector<std::pair<std::size_t, std::size_t>> frame_range_;  ///< per update: [first, end)
};

}  // namespace autoshovel::recording
