// Random camera views of the simulated yards, with their ground-truth labels: the data the
// segmentation network is trained and evaluated on (wheel-loader seed §4.2).
//
// One view (YardViewSampler::Render) is drawn from a generator seeded by (set seed, view index)
// alone, so a view does not depend on which other views were rendered, in which order or on how
// many threads: the same seed gives byte-identical data sets, and a held-out set is simply
// another seed. Each view:
//  - takes a scenario of models/scenarios (uniformly) and copies its world;
//  - with probability 1/2 adds one or two random piles (cone or lobed heap of a random
//    material, flanks at 70–100 % of the angle of repose) on free floor, so that held-out views
//    show piles that no training view showed;
//  - puts a loader (the scenario's machine, or another loader description with generated code)
//    in the open yard facing a pile (from the bin's open front for a bin pile), 2–20 m off its
//    foot, heading at it ±12°; one view in five stands anywhere in the yard facing anywhere;
//  - draws the arm joints uniformly within their limits (the bucket and boom then appear
//    anywhere from below the image to across it), an articulation angle in three views of ten,
//    a chassis pitch of ±1.7°;
//  - adds persons, a parked loader, debris and fences on free floor 7–28 m ahead in the camera's
//    field of view (the scenarios hold few of these classes, and the network must see them);
//  - lights the yard normal, bright or dim (view index mod 3, or as asked), with the sun at a
//    random azimuth and 25–70° elevation;
//  - renders sensors::SimulateCameraFrame with the machine's own body from
//    plant::Plant::OwnBodies() as extra boxes of the scene (class own_loader).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/semantic_class.h"
#include "runtime/plant/world.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::identification {

/// One rendered view and how it was made.
struct YardView {
  std::string scenario;
  std::string machine;
  plant::Lighting lighting = plant::Lighting::kNormal;
  double x = 0, y = 0, heading = 0;  ///< base origin and heading, world [m, rad]
  double articulation = 0;           ///< [rad]
  std::vector<double> joints;        ///< arm joints [rad]
  int extra_piles = 0;               ///< random piles added
  int extra_obstacles = 0;           ///< persons, loaders, debris, fences added
  sensors::CameraFrame frame;        ///< bgr and labels
};

class YardViewSampler {
 public:
  /// Loads the scenarios (names or paths; empty: every scenario under `<models_dir>/scenarios`
  /// whose machine is one of these loaders) and every wheel-loader description under
  /// `models_dir` that has generated code. Throws std::runtime_error when a scenario or machine
  /// cannot be loaded, a named scenario is not a loader's, or none is left.
  explicit YardViewSampler(const std::string& models_dir,
                           const std::vector<std::string>& scenarios = {});
  ~YardViewSampler();
  YardViewSampler(const YardViewSampler&) = delete;
  YardViewSampler& operator=(const YardViewSampler&) = delete;

  /// View number `index` of the set seeded by `seed`. `lighting`: forced, or by default
  /// `index mod 3` (normal, bright, dim), so any run of consecutive views is balanced. Const
  /// and free of shared mutable state: several threads may render at once.
  YardView Render(std::uint64_t seed, std::uint64_t index,
                  std::optional<plant::Lighting> lighting = std::nullopt) const;

  /// Names of the scenarios views are drawn from, in the order used.
  std::vector<std::string> scenario_names() const;

 private:
  struct Data;
  std::unique_ptr<Data> data_;
};

/// Confusion counts of predicted against true labels and the IoU derived from them.
class ConfusionMatrix {
 public:
  /// Adds a frame. Throws std::invalid_argument when the sizes differ or a label is out of
  /// range.
  void Add(const std::vector<std::uint8_t>& truth, const std::vector<std::uint8_t>& predicted);
  /// Intersection over union of class c: TP / (TP + FP + FN); nullopt when the class occurs
  /// neither in the truth nor in the prediction.
  std::optional<double> Iou(int c) const;
  /// Mean of the defined per-class IoUs (classes absent from truth and prediction left out).
  double MeanIou() const;
  /// Pixels of class c in the truth.
  std::uint64_t TruthPixels(int c) const;
  double PixelAccuracy() const;
  std::uint64_t count(int truth, int predicted) const {
    return counts_[truth * core::kNumSemanticClasses + predicted];
  }

 private:
  std::array<std::uint64_t, core::kNumSemanticClasses * core::kNumSemanticClasses> counts_{};
};

/// The generator of view `index` of the set `seed` (SplitMix64 of both): neighbouring indices and
/// seeds give unrelated streams.
std::uint64_t ViewSeed(std::uint64_t seed, std::uint64_t index);

}  // namespace autoshovel::identification
