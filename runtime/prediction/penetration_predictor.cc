#include "runtime/prediction/penetration_predictor.h"

#include <svm.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <utility>

#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/input_file.h"

namespace autoshovel::prediction {

namespace {

constexpr const char* kFormat = "autoshovel-penetration-svr";
constexpr int kFormatVersion = 1;

[[noreturn]] void Refuse(const std::string& file, int line, const std::string& message) {
  core::DiagnosticSink sink;
  sink.Add(core::SourceLocation{file, line, line > 0 ? 1 : 0}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
}

bool ParseFinite(const std::string& word, double& value) {
  char* end = nullptr;
  value = std::strtod(word.c_str(), &end);
  return !word.empty() && end == word.c_str() + word.size() && std::isfinite(value);
}

// libsvm's svm_load_model reports nothing but failure, takes "nan" for a number and, when the
// file ends before `total_sv` support vectors, repeats the last line read. So the text is checked
// here first, line by line: a header of known keys with finite numbers, "SV", then exactly
// total_sv lines `coefficient index:value ...` with increasing indices and finite numbers.
void CheckLibsvmModel(const std::string& path, int features) {
  if (const std::string why = core::NotARegularFile(path); !why.empty()) {
    Refuse(path, 0, "cannot open the libsvm model file (written by train_predictor): " + why);
  }
  std::ifstream file(path);
  if (!file) Refuse(path, 0, "cannot open the libsvm model file (written by train_predictor)");
  std::string text;
  int line = 0;
  long total_sv = -1, seen = 0;
  bool in_vectors = false;
  while (std::getline(file, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    std::istringstream in(text);
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    if (!in_vectors) {
      if (words.empty()) Refuse(path, line, "empty line in the header");
      const std::string& key = words[0];
      if (key == "SV" && words.size() == 1) {
        in_vectors = true;
        continue;
      }
      static const std::vector<std::string> kNumeric = {"degree",   "gamma", "coef0", "nr_class",
                                                        "total_sv", "rho",   "label", "probA",
                                                        "probB",    "nr_sv"};
      if (key == "svm_type" || key == "kernel_type") {
        const std::string expected = key == "svm_type" ? "epsilon_svr" : "rbf";
        if (words.size() != 2 || words[1] != expected) {
          Refuse(path, line,
                 key + ": expected " + expected +
                     " (the predictor is an epsilon-SVR with an RBF kernel), got '" +
                     text.substr(std::min(text.size(), key.size() + 1)) + "'");
        }
        continue;
      }
      if (std::find(kNumeric.begin(), kNumeric.end(), key) == kNumeric.end()) {
        Refuse(path, line,
               "'" + key +
                   "' is not a libsvm model header key (svm_type, kernel_type, "
                   "gamma, nr_class, total_sv, rho, ..., then SV)");
      }
      if (words.size() < 2) Refuse(path, line, key + ": no value");
      for (std::size_t i = 1; i < words.size(); ++i) {
        double v = 0;
        if (!ParseFinite(words[i], v)) {
          Refuse(
              path, line,
              key + ": value " + std::to_string(i) + " '" + words[i] + "' is not a finite number");
        }
        if (key == "total_sv") total_sv = v >= 0 && v == std::floor(v) ? static_cast<long>(v) : -1;
      }
      if (key == "total_sv" && total_sv < 0) Refuse(path, line, "total_sv: expected a count");
      continue;
    }
    if (words.empty()) continue;
    if (++seen > total_sv) {
      Refuse(path, line, "more support vectors than total_sv " + std::to_string(total_sv));
    }
    double v = 0;
    if (!ParseFinite(words[0], v)) {
      Refuse(path, line, "coefficient '" + words[0] + "' is not a finite number");
    }
    long last_index = 0;
    for (std::size_t i = 1; i < words.size(); ++i) {
      const std::size_t colon = words[i].find(':');
      char* end = nullptr;
      const long index = colon == std::string::npos ? 0 : std::strtol(words[i].c_str(), &end, 10);
      if (colon == std::string::npos || end != words[i].c_str() + colon || index <= last_index ||
          !ParseFinite(words[i].substr(colon + 1), v)) {
        Refuse(path, line,
               "'" + words[i] + "' is not index:value (increasing index >= 1, finite value)");
      }
      if (index > features) {
        Refuse(path, line,
               "support vector " + std::to_string(seen) + " uses feature index " +
                   std::to_string(index) + ", the scaling file has " + std::to_string(features) +
                   " features");
      }
      last_index = index;
    }
  }
  if (!in_vectors) Refuse(path, line, "no 'SV' line: not a libsvm model file");
  if (total_sv < 0) Refuse(path, line, "no total_sv in the header");
  if (seen < total_sv) {
    Refuse(path, line + 1,
           "truncated: total_sv " + std::to_string(total_sv) + ", " + std::to_string(seen) +
               " support vectors follow");
  }
}

}  // namespace

struct PenetrationPredictor::Model {
  svm_model* svm = nullptr;
  std::vector<svm_model*> travel;  ///< one per FeatureScaling::travel_times
  ~Model() {
    if (svm != nullptr) svm_free_and_destroy_model(&svm);
    for (svm_model*& m : travel) svm_free_and_destroy_model(&m);
  }
};

std::vector<std::string> FeatureScaling::FeatureNames(const std::vector<std::string>& materials) {
  std::vector<std::string> names = {"speed", "shoveled_volume"};
  for (const std::string& m : materials) names.push_back("material_" + m);
  for (int k = 1; k <= kNumHeights; ++k) names.push_back("h" + std::to_string(k));
  return names;
}

PenetrationPredictor::PenetrationPredictor(std::unique_ptr<Model> model, FeatureScaling scaling)
    : model_(std::move(model)), scaling_(std::move(scaling)) {}
PenetrationPredictor::PenetrationPredictor(PenetrationPredictor&&) noexcept = default;

double PenetrationPredictor::IntakeFactor(const std::string& material) const {
  const auto it = scaling_.intake_factor.find(material);
  return it == scaling_.intake_factor.end() ? 1.0 : it->second;
}

PenetrationPredictor& PenetrationPredictor::operator=(PenetrationPredictor&&) noexcept = default;
PenetrationPredictor::~PenetrationPredictor() = default;

std::vector<double> PenetrationPredictor::Encode(const PenetrationFeatures& features,
                                                 const std::vector<std::string>& materials,
                                                 std::string* why) {
  auto refuse = [&](const std::string& reason) {
    if (why) *why = reason;
    return std::vector<double>{};
  };
  if (!std::isfinite(features.speed)) return refuse("speed is not finite");
  if (!std::isfinite(features.shoveled_volume) || features.shoveled_volume < 0) {
    return refuse("shoveled volume V1 must be finite and >= 0 m^3, got " +
                  std::to_string(features.shoveled_volume));
  }
  for (int k = 0; k < kNumHeights; ++k) {
    if (!std::isfinite(features.heights[k])) {
      return refuse("pile height h" + std::to_string(k + 1) + " is not finite (unknown map cell?)");
    }
  }
  const auto found = std::find(materials.begin(), materials.end(), features.material);
  if (found == materials.end()) {
    std::string known;
    for (const std::string& m : materials) known += (known.empty() ? "" : ", ") + m;
    return refuse("material '" + features.material + "' is not one the model knows (" + known +
                  ")");
  }
  std::vector<double> x = {features.speed, features.shoveled_volume};
  for (const std::string& m : materials) x.push_back(m == features.material ? 1.0 : 0.0);
  for (double h : features.heights) x.push_back(h);
  return x;
}

PenetrationPrediction PenetrationPredictor::Predict(const PenetrationFeatures& features) const {
  PenetrationPrediction out;
  const std::vector<double> x = Encode(features, scaling_.materials, &out.message);
  if (x.empty()) return out;
  std::vector<svm_node> nodes(x.size() + 1);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double span = scaling_.max[i] - scaling_.min[i];
    nodes[i].index = static_cast<int>(i) + 1;
    nodes[i].value = span > 0 ? 2 * (x[i] - scaling_.min[i]) / span - 1 : 0.0;
  }
  nodes.back().index = -1;
  out.penetration = std::max(svm_predict(model_->svm, nodes.data()), 0.0);
  out.ok = std::isfinite(out.penetration);
  if (!out.ok) out.message = "the model returned a non-finite penetration";
  for (const svm_model* travel : model_->travel) {
    const double s = std::max(svm_predict(travel, nodes.data()), 0.0);
    if (!std::isfinite(s)) {
      out.ok = false;
      out.message = "the model returned a non-finite travel";
    }
    out.travel.push_back(s);
  }
  return out;
}

void PenetrationPredictor::SaveScaling(const std::string& path_stem, const FeatureScaling& s) {
  const std::string path = path_stem + ".scale";
  std::ostringstream file;  // then one checked atomic write (core/file_output.h)
  file << std::setprecision(17);
  file << "format " << kFormat << " " << kFormatVersion << "\n";
  file << "machine " << s.machine << "\n";
  file << "delta_l " << s.delta_l << "\n";
  file << "materials";
  for (const std::string& m : s.materials) file << " " << m;
  file << "\n";
  for (std::size_t i = 0; i < s.names.size(); ++i) {
    file << "feature " << s.names[i] << " " << s.min[i] << " " << s.max[i] << "\n";
  }
  if (!s.travel_times.empty()) {
    file << "travel_times";
    for (double t : s.travel_times) file << " " << t;
    file << "\n";
  }
  for (const auto& [material, factor] : s.intake_factor) {
    file << "intake_factor " << material << " " << factor << "\n";
  }
  for (const std::string& note : s.notes) file << "note " << note << "\n";
  core::WriteFileAtomically(path, file.str());
}

FeatureScaling PenetrationPredictor::LoadScaling(const std::string& path_stem) {
  const std::string path = path_stem + ".scale";
  if (const std::string why = core::NotARegularFile(path); !why.empty()) {
    Refuse(path, 0, "cannot open the feature scaling file (written by train_predictor): " + why);
  }
  std::ifstream file(path);
  if (!file) Refuse(path, 0, "cannot open the feature scaling file (written by train_predictor)");
  FeatureScaling s;
  core::DiagnosticSink sink;
  auto error = [&](int line, const std::string& message) {
    sink.Add(core::SourceLocation{path, line, 1}, "", message);
  };
  std::string text;
  int line = 0;
  bool have_format = false, have_materials = false;
  while (std::getline(file, text)) {
    ++line;
    if (text.empty() || text[0] == '#') continue;
    std::istringstream in(text);
    std::string key;
    in >> key;
    if (key == "format") {
      std::string name;
      int version = 0;
      if (!(in >> name >> version) || name != kFormat || version != kFormatVersion) {
        error(line, "expected 'format " + std::string(kFormat) + " " +
                        std::to_string(kFormatVersion) + "', got '" + text + "'");
      }
      have_format = true;
    } else if (key == "machine") {
      in >> s.machine;
    } else if (key == "delta_l") {
      if (!(in >> s.delta_l) || !(s.delta_l > 0)) error(line, "delta_l must be a number > 0 m");
    } else if (key == "materials") {
      std::string m;
      while (in >> m) s.materials.push_back(m);
      have_materials = true;
    } else if (key == "feature") {
      std::string name;
      double lo = 0, hi = 0;
      if (!(in >> name >> lo >> hi) || !std::isfinite(lo) || !std::isfinite(hi) || hi < lo) {
        error(line,
              "expected 'feature <name> <min> <max>' with finite min <= max, got '" + text + "'");
        continue;
      }
      s.names.push_back(name), s.min.push_back(lo), s.max.push_back(hi);
    } else if (key == "travel_times") {
      double t = 0;
      std::vector<double> times;
      while (in >> t) times.push_back(t);
      bool ok = in.eof() && !times.empty();
      for (std::size_t i = 0; ok && i < times.size(); ++i) {
        ok = std::isfinite(times[i]) && times[i] > (i == 0 ? 0.0 : times[i - 1]);
      }
      if (!ok) {
        error(line, "expected 'travel_times <t1> <t2> …' [s], finite, > 0 and increasing, got '" +
                        text + "'");
        continue;
      }
      s.travel_times = std::move(times);
    } else if (key == "intake_factor") {
      std::string material;
      double factor = 0;
      std::string extra;
      if (!(in >> material >> factor) || (in >> extra) || !std::isfinite(factor) || !(factor > 0)) {
        error(line, "expected 'intake_factor <material> <factor>' with a finite factor > 0, got '" +
                        text + "'");
        continue;
      }
      if (std::find(s.materials.begin(), s.materials.end(), material) == s.materials.end()) {
        error(line, "intake_factor for '" + material +
                        "', which is not in the 'materials' line (it must come after it)");
        continue;
      }
      if (!s.intake_factor.emplace(material, factor).second) {
        error(line, "a second intake_factor for '" + material + "'");
      }
    } else if (key == "note") {
      std::string rest;
      std::getline(in >> std::ws, rest);
      s.notes.push_back(rest);
    } else {
      error(line, "unknown key '" + key +
                      "' (expected format, machine, delta_l, materials, feature, travel_times, "
                      "intake_factor or note)");
    }
  }
  if (!have_format) error(0, "missing the 'format " + std::string(kFormat) + "' line");
  if (!have_materials || s.materials.empty()) error(0, "missing the 'materials' line");
  const std::vector<std::string> expected = FeatureScaling::FeatureNames(s.materials);
  if (have_materials && s.names != expected) {
    std::string list;
    for (const std::string& n : expected) list += " " + n;
    error(0, "expected " + std::to_string(expected.size()) + " features in the order" + list +
                 ", got " + std::to_string(s.names.size()));
  }
  if (std::abs(s.delta_l - kHeightSpacing) > 1e-9) {
    error(0, "delta_l " + std::to_string(s.delta_l) + " m: this build samples heights at " +
                 std::to_string(kHeightSpacing) + " m");
  }
  sink.ThrowIfAny();
  return s;
}

namespace {

// One ε-SVR RBF model file over `features` features, checked before and after libsvm reads it.
svm_model* LoadSvr(const std::string& path, int features) {
  if (!std::filesystem::is_regular_file(path)) {
    Refuse(path, 0, "cannot open the libsvm model file (written by train_predictor)");
  }
  CheckLibsvmModel(path, features);
  svm_model* svm = svm_load_model(path.c_str());
  if (svm == nullptr)
    Refuse(path, 0, "not a libsvm model file (svm_load_model could not parse it)");
  auto refuse = [&](const std::string& why) {
    svm_free_and_destroy_model(&svm);
    Refuse(path, 0, why);
  };
  if (svm_get_svm_type(svm) != EPSILON_SVR) {
    refuse("expected an epsilon_svr model, got svm_type " + std::to_string(svm_get_svm_type(svm)));
  }
  if (svm->param.kernel_type != RBF) {
    refuse("expected an rbf kernel, got kernel_type " + std::to_string(svm->param.kernel_type));
  }
  if (svm->l <= 0) refuse("the model has no support vectors");
  for (int i = 0; i < svm->l; ++i) {
    for (const svm_node* node = svm->SV[i]; node->index != -1; ++node) {
      if (node->index < 1 || node->index > features) {
        refuse("support vector " + std::to_string(i + 1) + " uses feature index " +
               std::to_string(node->index) + ", the scaling file has " + std::to_string(features) +
               " features");
      }
    }
  }
  return svm;
}

}  // namespace

std::string PenetrationPredictor::TravelModelPath(const std::string& path_stem, std::size_t k) {
  return path_stem + ".travel" + std::to_string(k + 1) + ".model";
}

PenetrationPredictor PenetrationPredictor::Load(const std::string& path_stem) {
  FeatureScaling scaling = LoadScaling(path_stem);
  const int features = static_cast<int>(scaling.names.size());
  auto model = std::make_unique<Model>();
  model->svm = LoadSvr(path_stem + ".model", features);
  for (std::size_t k = 0; k < scaling.travel_times.size(); ++k) {
    model->travel.push_back(LoadSvr(TravelModelPath(path_stem, k), features));
  }
  return PenetrationPredictor(std::move(model), std::move(scaling));
}

std::array<double, kNumHeights> SampleHeightsAhead(
    const std::function<double(double, double)>& height_at, const Eigen::Vector2d& tip_xy,
    double heading, double bucket_width) {
  const Eigen::Vector2d forward(std::cos(heading), std::sin(heading));
  const Eigen::Vector2d left(-forward.y(), forward.x());
  std::array<double, kNumHeights> h{};
  for (int k = 0; k < kNumHeights; ++k) {
    double sum = 0;
    for (int j = -2; j <= 2; ++j) {
      const Eigen::Vector2d p =
          tip_xy + (k + 1) * kHeightSpacing * forward + j * 0.2 * bucket_width * left;
      sum += height_at(p.x(), p.y());
    }
    h[k] = sum / 5;
  }
  return h;
}

}  // namespace autoshovel::prediction
