// Writes a recording folder (recording_format.h, docs/recording_format.md) as a run goes: each
// frame's file when its update is added, the CSVs and the manifest at Close(). A folder without
// recording.yaml is an unfinished recording and is refused by the reader.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/perception/sensor_fusion.h"
#include "runtime/recording/recording_format.h"

namespace autoshovel::recording {

class RecordingWriter {
 public:
  /// Creates `dir` (it must not exist, or be an empty folder) and copies the machine
  /// description at `description_path` byte for byte. `manifest` gives the map grid, the
  /// selection and the source; its cycles are added by BeginCycle. Throws core::OutputError
  /// (or std::invalid_argument for a folder that holds files).
  RecordingWriter(std::filesystem::path dir, const std::string& description_path,
                  Manifest manifest);

  /// The selection as the machine runs it (the manifest keeps the last one given).
  void SetSelection(const planning::ShovelPointConfig& config, double min_planned_clearance,
                    bool chen2024);

  /// An identification overlay the machine ran with (model::LoadOptions::overlays), copied byte
  /// for byte into the folder as `overlay_<n>_<file name>`; overlays apply in the order added.
  /// Throws core::OutputError.
  void AddOverlay(const std::string& overlay_path);

  /// How the camera frames are labelled (manifest `perception`).
  void SetPerception(bool truth_labels, double segmentation_scale);

  /// Updates from here on belong to `cycle`.
  void BeginCycle(const CycleInfo& cycle);

  /// One map update: the frames the machine fused (in order) and its row (`row.update` and
  /// `row.cycle` are set here). Returns the update's number.
  long AddUpdate(UpdateRow row, const perception::SensorFrames& frames,
                 const std::string& camera_name);

  /// The scoop of the running cycle: what its volume prediction assumed.
  void SetScoop(const ScoopInfo& scoop);

  /// A scoop's trigger decisions (scoop.csv), the machine's V1 and V2 at each
  /// (reference/predictions.csv; `v2` NaN where none was predicted), and its tip path
  /// (tip_path.csv), for the running cycle.
  void AddScoop(const std::vector<DecisionRow>& decisions, const std::vector<double>& v1,
                const std::vector<double>& v2, const std::vector<Eigen::Vector3d>& tip_path);

  /// What the recording machine computed at the update just added, for checking a replay:
  /// reference/map_digests.csv and reference/selections.csv rows (replay_check.h).
  void AddReference(const std::string& map_digest_row, const std::string& selection_row);

  /// Writes updates.csv, frames.csv, the reference files and, last, recording.yaml.
  void Close();

  const std::filesystem::path& dir() const { return dir_; }
  long updates() const { return next_update_; }

 private:
  std::filesystem::path dir_;
  Manifest manifest_;
  long next_update_ = 0;
  std::string updates_csv_, frames_csv_, digests_csv_, selections_csv_;
  std::string scoop_csv_, tip_path_csv_, predictions_csv_;
  bool closed_ = false;
};

/// The LiDAR frame as a binary PCD: FIELDS x y z intensity ring time_offset (float32, except
/// ring uint16), points in the sensor frame. Returns the file's bytes.
std::string LidarPcdBytes(const sensors::PointCloud& cloud);

}  // namespace autoshovel::recording
