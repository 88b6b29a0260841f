// Penetration-depth predictor, wheel-loader seed §6.1 and §7.4.1: an ε-SVR (libsvm, RBF kernel)
// on the current speed v, the shoveled volume so far V1 (Eq. 19), the material M and six pile
// surface heights h1..h6 ahead of the bucket at Δl = 0.5 m.
//
// What it predicts (our reading; the seed calls it "travel distance" / "penetration depth"): the
// distance the machine still travels forward from the instant the scoop is triggered until it
// stops, while the scoop (hydraulic delay, bucket curl, boom lift) runs. That is the d that
// PredictFutureVolume (volume_estimation.h) turns into the future tip path and V2.
//
// Features as the model sees them: [v, V1, one-hot(M) over the model's materials, h1..h6], each
// scaled to [−1, 1] with the minimum and maximum of the training set (stored beside the model).
// h_k is the map height [m] (floor at 0) at k·Δl ahead of the bucket tip along the heading,
// averaged over five points across the bucket width (the seed samples the centre line only; the
// mean makes the feature robust to a bumpy face).
//
// Files: `<name>.model` is libsvm's own text format; `<name>.scale` is ours, one key per line:
//   format autoshovel-penetration-svr 1
//   machine <name>
//   delta_l <m>
//   materials <name> <name> …
//   feature <name> <min> <max>        (one per feature, in order)
//   travel_times <t1> <t2> …          (optional: the travel curve below) [s]
//   intake_factor <material> <κ>      (optional, one per material: see below) [-]
//   note <free text>                  (any number: the training command, figures)
//
// The optional travel curve: one more ε-SVR per time t_k on the same scaled features,
// `<name>.travel<k>.model` (k = 1, 2, …), predicting how far the machine has travelled t_k
// after the trigger (train_predictor --travel-curve). V2 then follows those knots instead of a
// constant deceleration over d (volume_estimation.h, ScoopPlan::travel_at).
//
// The optional intake factor κ_M per material (train_predictor --intake-factor): what the
// bucket takes in over what V1 + V2 counts. Eq. (19) counts the pile above the tip path; the
// pushing scoop's training runs that do not fill the bucket end with 1.06 (big gravel) to 1.23
// (river sand) times that (the cut faces relaxing to their angle of repose into the bucket's
// path is the likely reason, strongest in sand; not measured apart). κ_M is the least-squares
// gain through the origin of the payload on V1 + V2 over the training runs of M whose bucket did
// not fill; the trigger compares κ_M·(V1 + V2) with V_t. Absent, κ = 1 (the seed's
// V1 + V2 ≥ V_t as written).
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace autoshovel::prediction {

inline constexpr int kNumHeights = 6;
inline constexpr double kHeightSpacing = 0.5;  ///< Δl [m], seed §6.1

/// h1..h6: the surface k·Δl (k = 1…6) ahead of the bucket tip along the heading, each the mean
/// of five points across the bucket width (robust to a bumpy face). `height_at(x, y)` gives the
/// surface height there [m]. One definition for the training runs and the controller, so the
/// predictor sees the same features in both.
std::array<double, kNumHeights> SampleHeightsAhead(
    const std::function<double(double, double)>& height_at, const Eigen::Vector2d& tip_xy,
    double heading, double bucket_width);

struct PenetrationFeatures {
  double speed = 0;                           ///< v, forward [m/s]
  double shoveled_volume = 0;                 ///< V1, Eq. (19) [m³]
  std::string material;                       ///< M, a material name (models/materials)
  std::array<double, kNumHeights> heights{};  ///< h1..h6 [m]
};

/// Per-feature min/max scaling to [−1, 1] and the metadata of a model.
struct FeatureScaling {
  std::string machine;
  double delta_l = kHeightSpacing;
  std::vector<std::string> materials;  ///< one-hot order
  std::vector<std::string> names;      ///< feature names, in vector order
  std::vector<double> min, max;        ///< per feature
  std::vector<std::string> notes;
  /// Times after the trigger of the travel curve's models [s] (empty: no curve).
  std::vector<double> travel_times;
  /// κ_M per material (empty: none; a material not listed has κ = 1).
  std::map<std::string, double> intake_factor;

  /// The names of the features for `materials`: speed, shoveled_volume, material_<m>…, h1..h6.
  static std::vector<std::string> FeatureNames(const std::vector<std::string>& materials);
};

/// Outcome of a prediction: a run-time status, not an exception (a NaN from an unknown map cell
/// is something a controller must handle, not a bug).
struct PenetrationPrediction {
  bool ok = false;
  double penetration = 0;      ///< [m], ≥ 0
  std::vector<double> travel;  ///< [m] at FeatureScaling::travel_times (empty: no curve)
  std::string message;         ///< why not, when !ok
};

class PenetrationPredictor {
 public:
  /// The travel curve's model file for knot k (0-based): `<path_stem>.travel<k+1>.model`.
  static std::string TravelModelPath(const std::string& path_stem, std::size_t k);

  /// Loads `<path_stem>.model`, `<path_stem>.scale` and the travel curve's models if the scaling
  /// names travel times. Throws core::InputError naming the file,
  /// the line where known and what is wrong (missing file, not a libsvm ε-SVR RBF model, feature
  /// count mismatch, malformed scaling).
  static PenetrationPredictor Load(const std::string& path_stem);

  PenetrationPredictor(PenetrationPredictor&&) noexcept;
  PenetrationPredictor& operator=(PenetrationPredictor&&) noexcept;
  ~PenetrationPredictor();

  /// Refuses NaN or infinite features, a negative V1 and a material the model does not know.
  PenetrationPrediction Predict(const PenetrationFeatures& features) const;

  /// The feature vector, unscaled, in model order (also used for training); empty and `why` set
  /// when a feature is refused.
  static std::vector<double> Encode(const PenetrationFeatures& features,
                                    const std::vector<std::string>& materials, std::string* why);

  const FeatureScaling& scaling() const { return scaling_; }
  /// κ_M of `material`: the model's intake factor, 1 where it has none.
  double IntakeFactor(const std::string& material) const;

  /// Writes `<path_stem>.scale` (and nothing else: the .model is written by libsvm's
  /// svm_save_model). Throws std::runtime_error when the file cannot be written.
  static void SaveScaling(const std::string& path_stem, const FeatureScaling& scaling);
  /// Reads `<path_stem>.scale`. Throws core::InputError.
  static FeatureScaling LoadScaling(const std::string& path_stem);

 private:
  struct Model;
  PenetrationPredictor(std::unique_ptr<Model> model, FeatureScaling scaling);
  std::unique_ptr<Model> model_;
  FeatureScaling scaling_;
};

}  // namespace autoshovel::prediction
