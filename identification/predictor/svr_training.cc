#include "identification/predictor/svr_training.h"

#include <svm.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "runtime/core/file_output.h"

namespace autoshovel::predictor {

namespace {

void Quiet(const char*) {}

// A libsvm problem over scaled rows; owns its nodes (a model trained on it points into them).
struct Problem {
  std::vector<std::vector<svm_node>> rows;
  std::vector<svm_node*> pointers;
  std::vector<double> y;
  svm_problem problem{};

  Problem(const std::vector<std::vector<double>>& x, const std::vector<double>& targets,
          const std::vector<int>& indices) {
    for (int i : indices) {
      std::vector<svm_node> row(x[i].size() + 1);
      for (std::size_t j = 0; j < x[i].size(); ++j) {
        row[j].index = static_cast<int>(j) + 1;
        row[j].value = x[i][j];
      }
      row.back().index = -1;
      rows.push_back(std::move(row));
      y.push_back(targets[i]);
    }
    for (auto& row : rows) pointers.push_back(row.data());
    problem.l = static_cast<int>(rows.size());
    problem.y = y.data();
    problem.x = pointers.data();
  }
};

svm_parameter Parameters(double c, double gamma, double epsilon) {
  svm_parameter p{};
  p.svm_type = EPSILON_SVR;
  p.kernel_type = RBF;
  p.gamma = gamma;
  p.C = c;
  p.p = epsilon;
  p.eps = 1e-3;
  p.cache_size = 100;
  p.shrinking = 1;
  p.probability = 0;
  return p;
}

double Predict(const svm_model* model, const std::vector<double>& x) {
  std::vector<svm_node> row(x.size() + 1);
  for (std::size_t j = 0; j < x.size(); ++j) row[j] = {static_cast<int>(j) + 1, x[j]};
  row.back().index = -1;
  return std::max(svm_predict(model, row.data()), 0.0);
}

// The rows scaled to [−1, 1] with the scaling's per-feature min and max (as Predict does).
std::vector<std::vector<double>> ScaleRows(const std::vector<std::vector<double>>& x,
                                           const prediction::FeatureScaling& scaling) {
  std::vector<std::vector<double>> scaled = x;
  for (auto& row : scaled) {
    if (row.size() != scaling.min.size())
      throw std::invalid_argument("SVR training: ragged samples");
    for (std::size_t j = 0; j < row.size(); ++j) {
      const double span = scaling.max[j] - scaling.min[j];
      row[j] = span > 0 ? 2 * (row[j] - scaling.min[j]) / span - 1 : 0.0;
    }
  }
  return scaled;
}

// Fits one ε-SVR on every scaled row and saves it to `model_path`; returns its support vectors.
int FitAndSave(const std::vector<std::vector<double>>& scaled, const std::vector<double>& y,
               double c, double gamma, double epsilon, const std::string& model_path) {
  std::vector<int> all(scaled.size());
  for (std::size_t i = 0; i < scaled.size(); ++i) all[i] = static_cast<int>(i);
  Problem problem(scaled, y, all);
  const svm_parameter p = Parameters(c, gamma, epsilon);
  svm_model* model = svm_train(&problem.problem, &p);
  const int support_vectors = model->l;
  // libsvm writes to a path in place; it writes a scratch file, whose bytes then go through the
  // project's checked atomic write (core/file_output.h), so a failed save never leaves half a
  // model under the final name.
  const std::string scratch = model_path + ".svm.tmp";
  const int saved = svm_save_model(scratch.c_str(), model);
  svm_free_and_destroy_model(&model);
  std::ostringstream bytes;
  {
    std::ifstream in(scratch, std::ios::binary);
    bytes << in.rdbuf();
  }
  std::error_code ignored;
  std::filesystem::remove(scratch, ignored);
  if (saved != 0 || bytes.str().empty()) {
    throw core::OutputError(model_path, "libsvm could not write the model");
  }
  core::WriteFileAtomically(model_path, bytes.str());
  return support_vectors;
}

}  // namespace

SvrTrainingResult TrainPenetrationSvr(const SvrDataset& train, const SvrGrid& grid, int threads,
                                      prediction::FeatureScaling& scaling,
                                      const std::string& path_stem) {
  const std::size_t n = train.x.size();
  if (n < static_cast<std::size_t>(std::max(grid.folds, 2)) || train.y.size() != n) {
    throw std::invalid_argument("TrainPenetrationSvr: need at least " +
                                std::to_string(std::max(grid.folds, 2)) +
                                " samples with targets, got " + std::to_string(n) + " and " +
                                std::to_string(train.y.size()));
  }
  const std::size_t dim = train.x.front().size();
  scaling.names = prediction::FeatureScaling::FeatureNames(scaling.materials);
  if (scaling.names.size() != dim) {
    throw std::invalid_argument("TrainPenetrationSvr: " + std::to_string(dim) +
                                " features per sample, the materials give " +
                                std::to_string(scaling.names.size()));
  }
  scaling.min.assign(dim, std::numeric_limits<double>::infinity());
  scaling.max.assign(dim, -std::numeric_limits<double>::infinity());
  for (const auto& row : train.x) {
    if (row.size() != dim) throw std::invalid_argument("TrainPenetrationSvr: ragged samples");
    for (std::size_t j = 0; j < dim; ++j) {
      scaling.min[j] = std::min(scaling.min[j], row[j]);
      scaling.max[j] = std::max(scaling.max[j], row[j]);
    }
  }
  const std::vector<std::vector<double>> scaled = ScaleRows(train.x, scaling);
  svm_set_print_string_function(&Quiet);

  struct Setting {
    double c, gamma, epsilon, mse = 0;
  };
  std::vector<Setting> settings;
  for (double c : grid.c)
    for (double g : grid.gamma)
      for (double e : grid.epsilon) settings.push_back({c, g, e});
  // Fold of sample i: i mod k (the samples come in run order, already random).
  const int k = grid.folds;
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int s = next++; s < static_cast<int>(settings.size()); s = next++) {
      double sse = 0;
      for (int fold = 0; fold < k; ++fold) {
        std::vector<int> fit, held;
        for (std::size_t i = 0; i < n; ++i) {
          (static_cast<int>(i % k) == fold ? held : fit).push_back(static_cast<int>(i));
        }
        Problem problem(scaled, train.y, fit);
        const svm_parameter p = Parameters(settings[s].c, settings[s].gamma, settings[s].epsilon);
        svm_model* model = svm_train(&problem.problem, &p);
        for (int i : held) {
          const double e = Predict(model, scaled[i]) - train.y[i];
          sse += e * e;
        }
        svm_free_and_destroy_model(&model);
      }
      settings[s].mse = sse / static_cast<double>(n);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::max(threads, 1); ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();

  const Setting best =
      *std::min_element(settings.begin(), settings.end(),
                        [](const Setting& a, const Setting& b) { return a.mse < b.mse; });
  SvrTrainingResult result;
  result.c = best.c, result.gamma = best.gamma, result.epsilon = best.epsilon;
  result.cv_mse = best.mse;
  result.settings_tried = static_cast<int>(settings.size());
  result.support_vectors =
      FitAndSave(scaled, train.y, best.c, best.gamma, best.epsilon, path_stem + ".model");
  prediction::PenetrationPredictor::SaveScaling(path_stem, scaling);
  return result;
}

int FitSvr(const SvrDataset& train, const prediction::FeatureScaling& scaling, double c,
           double gamma, double epsilon, const std::string& model_path) {
  if (train.x.empty() || train.y.size() != train.x.size()) {
    throw std::invalid_argument("FitSvr: need samples with targets, got " +
                                std::to_string(train.x.size()) + " and " +
                                std::to_string(train.y.size()));
  }
  svm_set_print_string_function(&Quiet);
  return FitAndSave(ScaleRows(train.x, scaling), train.y, c, gamma, epsilon, model_path);
}

}  // namespace autoshovel::predictor
