// `autoshovel train segmentation`: fine-tunes the segmentation network on a new site (wheel-
// loader seed §7.6, "adapting to a new site"), from frames rendered in that site's yard.
//
// Steps, each a tool of the build run as its own process (their own options and output are
// documented in identification/segmentation/README.md):
//   1. segmentation_dataset renders `views` training views of the site (one in ten kept for
//      validation) and `heldout` views of another seed, never trained on;
//   2. segmentation_eval scores the base network on the held-out views (before);
//   3. identification/segmentation/train.py fine-tunes from the base network's ONNX file
//      (batch norm folded and frozen) for `steps` steps and exports a new ONNX file;
//   4. segmentation_eval scores the new network on the same held-out views (after).
// The new network goes to `out`; the shipped one (models/segmentation) is never written: an
// `out` inside that folder is refused. Training needs Debian's python3-torch and python3-onnx
// (scripts/setup installs them).
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct TrainSegmentationOptions {
  std::string scenario;            ///< the new site's yard (name under models/scenarios, or path)
  std::filesystem::path out;       ///< the new ONNX file
  std::filesystem::path base;      ///< empty: models/segmentation/yard_segmenter.onnx
  std::string models_dir;          ///< machines (and scenarios by name)
  int views = 400;                 ///< rendered training views of the site
  int heldout = 120;               ///< rendered held-out views (another seed)
  int steps = 600;                 ///< fine-tuning steps (batch 8)
  double learning_rate = 1e-3;     ///< peak of the one-cycle schedule
  std::uint64_t seed = 1;          ///< training views' seed; held-out: seed + 1000
  int jobs = 2;                    ///< rendering threads and training threads
  std::filesystem::path work_dir;  ///< rendered data and logs; empty: <out>.data
};

/// 0 on success; 2 for bad options or a missing tool (named on `err`); 1 when a step failed.
int RunTrainSegmentation(const TrainSegmentationOptions& options, std::ostream& out,
                         std::ostream& err);

}  // namespace autoshovel::app
