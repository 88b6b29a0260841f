// `autoshovel replay DIR`: the main job's perception and shovel point selection on a recorded run
// (docs/recording_format.md), no plant: every update's frames are fused into the semantic
// elevation map at their recorded timestamps and poses, selection runs where the recording
// machine ran it, from the localisation it had, and each scoop's volume prediction (V1, V2,
// seed §6.1) runs at its recorded decisions on the map the scoop started from. The run folder
// gets the map digests, the selections and the predictions as CSV (the recording's reference/
// has the same files from the machine), the map and candidate pictures of each cycle, and the
// log.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>

namespace autoshovel::app {

struct ReplayOptions {
  std::string recording;   ///< the recording folder
  std::string out;         ///< run folder; empty: runs/<UTC timestamp>
  std::string models_dir;  ///< for the machine's materials and the default segmenter
  /// The camera frames' recorded labels instead of the network (a simulated recording); unset:
  /// as the recording machine did (its manifest's `perception`), else the network.
  std::optional<bool> truth_labels;
  std::string segmenter;  ///< ONNX network; empty: models/segmentation/yard_segmenter.onnx
  /// perception::FusionOptions::segmentation_scale; unset: the recording machine's, else 1.
  std::optional<double> segmentation_scale;
  /// Penetration SVR (path without .model); empty: the main job's (prediction/shipped_models.h).
  std::string predictor;
  bool figures = true;
  /// Exit 1 when a map or a selection differs from the recording's reference.
  bool check = false;
};

/// Returns 0 on success, 1 when `check` found a difference, 2 on bad input.
int RunReplay(const ReplayOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
