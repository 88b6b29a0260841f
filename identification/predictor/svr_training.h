// ε-SVR training for the penetration predictor (libsvm, RBF kernel), wheel-loader seed §7.4.1:
// features scaled to [−1, 1] on the training set, a grid search over C, γ and ε scored by k-fold
// cross-validation on the training set only (our own deterministic folds: libsvm's
// svm_cross_validation shuffles with rand()), the best setting refitted on the whole training
// set and saved as `<stem>.model` (libsvm) + `<stem>.scale` (penetration_predictor.h).
#pragma once

#include <string>
#include <vector>

#include "runtime/prediction/penetration_predictor.h"

namespace autoshovel::predictor {

struct SvrDataset {
  std::vector<std::vector<double>> x;  ///< unscaled feature vectors (PenetrationPredictor::Encode)
  std::vector<double> y;               ///< penetration [m]
};

struct SvrGrid {
  std::vector<double> c = {1, 4, 16, 64, 256};
  std::vector<double> gamma = {0.03, 0.1, 0.3, 1.0};
  std::vector<double> epsilon = {0.01, 0.03, 0.06};
  int folds = 5;
};

struct SvrTrainingResult {
  double c = 0, gamma = 0, epsilon = 0;
  double cv_mse = 0;  ///< of the chosen setting [m²]
  int support_vectors = 0;
  int settings_tried = 0;
};

/// Fits, selects and saves. `scaling` comes in with machine, materials and notes filled; its
/// names/min/max are set from `train`. Throws std::invalid_argument for an empty or ragged data
/// set and std::runtime_error when the files cannot be written.
SvrTrainingResult TrainPenetrationSvr(const SvrDataset& train, const SvrGrid& grid, int threads,
                                      prediction::FeatureScaling& scaling,
                                      const std::string& path_stem);

/// One more ε-SVR on the same features and scaling (`scaling` min/max as TrainPenetrationSvr
/// set them) with the given setting, saved to `model_path`; returns its support vectors. For
/// the travel curve's knots: their targets are the same machine's travel at other instants, so
/// the setting chosen for d is reused rather than searched again (one fit instead of 300).
int FitSvr(const SvrDataset& train, const prediction::FeatureScaling& scaling, double c,
           double gamma, double epsilon, const std::string& model_path);

}  // namespace autoshovel::predictor
