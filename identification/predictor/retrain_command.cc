#include "identification/predictor/retrain_command.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <ostream>
#include <set>
#include <thread>

#include "identification/predictor/svr_training.h"
#include "runtime/core/file_output.h"
#include "runtime/model/description.h"
#include "runtime/prediction/model_provenance.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/prediction/shipped_models.h"
#include "runtime/results/results_db.h"

namespace autoshovel::predictor {
namespace {

constexpr const char* kCommand = "autoshovel train predictor";
constexpr int kMinTrainingSamples = 20;

// FNV-1a of run and cycle: a split that does not move when rows are added.
bool HeldOut(const std::string& run_id, int cycle) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const char c : run_id + "#" + std::to_string(cycle)) {
    h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  }
  return h % 5 == 4;
}

prediction::PenetrationFeatures FeaturesOf(const results::CrowdingSample& s) {
  prediction::PenetrationFeatures f;
  f.speed = s.speed;
  f.shoveled_volume = s.v1;
  f.material = s.material;
  for (int k = 0; k < prediction::kNumHeights; ++k) f.heights[k] = s.heights[k];
  return f;
}

struct Score {
  int samples = 0, refused = 0;
  double within_010 = 0, within_015 = 0, within_020 = 0, rmse = 0;
};

Score ScoreModel(const prediction::PenetrationPredictor& model,
                 const std::vector<results::CrowdingSample>& set) {
  Score s;
  s.samples = static_cast<int>(set.size());
  double sq = 0;
  int n = 0;
  for (const results::CrowdingSample& c : set) {
    const prediction::PenetrationPrediction p = model.Predict(FeaturesOf(c));
    if (!p.ok) {
      ++s.refused;  // counted as a miss in every bucket
      continue;
    }
    const double e = std::abs(p.penetration - c.penetration);
    s.within_010 += e <= 0.10, s.within_015 += e <= 0.15, s.within_020 += e <= 0.20;
    sq += e * e, ++n;
  }
  if (s.samples > 0) {
    s.within_010 /= s.samples, s.within_015 /= s.samples, s.within_020 /= s.samples;
  }
  s.rmse = n > 0 ? std::sqrt(sq / n) : NAN;
  return s;
}

// The travel the runs themselves predicted at the trigger (CrowdingSample::predicted_penetration),
// scored as ScoreModel scores a model: the predictor in the closed loop. Samples where either
// travel is not measured (NULL: a database from before the column, a failed prediction) are
// left out and counted in `skipped`; nothing is refused.
Score ScoreLogged(const std::vector<results::CrowdingSample>& set, int* skipped) {
  Score s;
  double sq = 0;
  *skipped = 0;
  for (const results::CrowdingSample& c : set) {
    if (!std::isfinite(c.predicted_penetration) || !std::isfinite(c.penetration)) {
      ++*skipped;
      continue;
    }
    const double e = std::abs(c.predicted_penetration - c.penetration);
    s.within_010 += e <= 0.10, s.within_015 += e <= 0.15, s.within_020 += e <= 0.20;
    sq += e * e, ++s.samples;
  }
  if (s.samples > 0) {
    s.within_010 /= s.samples, s.within_015 /= s.samples, s.within_020 /= s.samples;
  }
  s.rmse = s.samples > 0 ? std::sqrt(sq / s.samples) : NAN;
  return s;
}

void PrintScore(std::ostream& out, const char* name, const Score& s) {
  char line[200];
  std::snprintf(line, sizeof line, "| %s | %d | %.1f %% | %.1f %% | %.1f %% | %.3f | %d |\n", name,
                s.samples, 100 * s.within_010, 100 * s.within_015, 100 * s.within_020, s.rmse,
                s.refused);
  out << line;
}

int Threads(int requested) {
  return requested > 0 ? requested
                       : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// Without a database: crowding runs on the machine's simulated plant (plant_training.h).
int TrainOnThePlant(const RetrainOptions& o, std::ostream& out, std::ostream& err) {
  PlantTrainingOptions p = o.plant;
  p.machine = o.machine;
  p.models_dir = o.models_dir;
  p.out = o.out;
  p.threads = Threads(o.threads);
  p.command = kCommand;
  p.compare_with = o.base;  // scored on the same test runs when given
  return RunPlantTraining(p, out, err);
}

}  // namespace

PlantTrainingOptions RetrainOptions::MainJobPlantTraining() {
  PlantTrainingOptions p;
  p.runs = 2000;
  p.seed = 1;
  p.run_options.min_speed = p.run_options.max_speed = 1.5;
  p.scoop_deceleration = 0.6;
  p.dug_face_fraction = 0.4;
  p.travel_curve = true;
  p.intake_factor = true;
  return p;
}

int RunRetrainPredictor(const RetrainOptions& o, std::ostream& out, std::ostream& err) {
  try {
    if (o.out.empty()) {
      err << kCommand << ": give --out STEM for the new model (.model, .scale and .meta.yaml)\n";
      return 2;
    }
    for (const std::string& path :
         {o.out + ".model", o.out + ".scale", prediction::ProvenancePath(o.out),
          prediction::PenetrationPredictor::TravelModelPath(o.out, 0)}) {
      if (std::filesystem::exists(path)) {
        err << kCommand << ": " << path
            << " already exists; a model is never overwritten (choose another --out)\n";
        return 2;
      }
    }
    if (o.database.empty()) return TrainOnThePlant(o, out, err);
    const std::string base = o.base.empty() ? prediction::MainJobPredictor(o.models_dir) : o.base;
    if (std::filesystem::weakly_canonical(o.out + ".model") ==
        std::filesystem::weakly_canonical(base + ".model")) {
      err << kCommand << ": --out is the base model\n";
      return 2;
    }
    if (!std::filesystem::is_regular_file(o.database)) {
      err << kCommand << ": " << o.database << ": no such file\n";
      return 2;
    }
    const model::MachineDescription machine =
        model::LoadMachineDescription(model::ResolveMachineDescription(o.machine, o.models_dir));
    const prediction::PenetrationPredictor shipped = prediction::PenetrationPredictor::Load(base);

    std::vector<results::CrowdingSample> training, held_out;
    int skipped = 0, other_machines = 0;
    {
      // Read-only and checked with PRAGMA integrity_check; values through the typed reader.
      const results::ResultsDb db(o.database, results::ResultsDb::Access::kReadOnly);
      // Samples of another machine's runs would teach this machine's model another machine's
      // travel: only runs of --machine count.
      std::set<std::string> runs_of_machine;
      for (const results::RunInfo& run : db.Runs()) {
        if (run.machine == machine.name) runs_of_machine.insert(run.run_id);
      }
      for (const results::ResultsDb::StoredCrowdingSample& s : db.CrowdingSamples()) {
        if (!runs_of_machine.contains(s.run_id)) {
          ++other_machines;
          continue;
        }
        if (o.strategy != "all" && s.sample.strategy != o.strategy) {
          ++skipped;
          continue;
        }
        (HeldOut(s.run_id, s.cycle) ? held_out : training).push_back(s.sample);
      }
    }
    out << o.database << ": " << training.size() + held_out.size() << " crowding samples of "
        << machine.name << " (" << (o.strategy == "all" ? "every strategy" : o.strategy) << "; "
        << skipped << " of other strategies and " << other_machines
        << " of other machines' runs left out): " << training.size() << " to train, "
        << held_out.size() << " held out\n";
    if (static_cast<int>(training.size()) < kMinTrainingSamples || held_out.empty()) {
      err << kCommand << ": too few samples to train (" << training.size() << "; at least "
          << kMinTrainingSamples << " and one held out): run a longer campaign first\n";
      return 1;
    }

    std::vector<std::string> materials;
    for (const model::Material& m : machine.materials) materials.push_back(m.name);
    SvrDataset train;
    int not_measured = 0, not_encodable = 0;
    for (const results::CrowdingSample& s : training) {
      // NULL penetration: not measured (the reader refuses text and infinities outright).
      if (std::isnan(s.penetration)) {
        ++not_measured;
        continue;
      }
      std::string why;
      const std::vector<double> x =
          prediction::PenetrationPredictor::Encode(FeaturesOf(s), materials, &why);
      if (x.empty()) {  // refused, as the model would refuse it
        ++not_encodable;
        continue;
      }
      train.x.push_back(x);
      train.y.push_back(s.penetration);
    }
    if (not_measured > 0 || not_encodable > 0) {
      out << "left out of training: " << not_measured << " of " << training.size()
          << " samples with penetration_m not measured (NULL), " << not_encodable
          << " the model cannot encode (a NULL input or an unknown material)\n";
    }
    prediction::FeatureScaling scaling;
    scaling.machine = machine.name;
    scaling.materials = materials;
    scaling.notes.push_back("retrained by: autoshovel train predictor " + o.database + " --out " +
                            o.out + " (" + std::to_string(train.x.size()) + " samples of " +
                            o.strategy + ")");
    const std::filesystem::path parent = std::filesystem::path(o.out).parent_path();
    core::CreateFolders(parent);
    const int threads = Threads(o.threads);
    SvrGrid grid;
    grid.folds = std::min(grid.folds, static_cast<int>(train.x.size()));
    const SvrTrainingResult fit = TrainPenetrationSvr(train, grid, threads, scaling, o.out);
    const prediction::PenetrationPredictor retrained =
        prediction::PenetrationPredictor::Load(o.out);
    prediction::ModelProvenance provenance;
    provenance.machine = machine.name;
    provenance.description = std::filesystem::path(machine.source_file).filename().string();
    provenance.sha256 = machine.sha256;
    provenance.plant_samples = "crowding samples logged by runs of " + machine.name + " in " +
                               o.database + " (" + std::to_string(train.x.size()) + " trained on)";
    provenance.plant_code = "as the database's runs ran it (not recorded there)";
    provenance.trained_by = scaling.notes.back().substr(std::string("retrained by: ").size());
    prediction::SaveProvenance(o.out, provenance);

    char line[300];
    std::snprintf(line, sizeof line,
                  "SVR: C %g, gamma %g, epsilon %g, CV MSE %.4f m^2, %d support vectors, %d "
                  "settings tried\n\n",
                  fit.c, fit.gamma, fit.epsilon, fit.cv_mse, fit.support_vectors,
                  fit.settings_tried);
    out << line;
    out << "| held-out samples | n | |error| <= 0.10 m | <= 0.15 m | <= 0.20 m | RMSE m | refused "
           "|\n| --- | --- | --- | --- | --- | --- | --- |\n";
    PrintScore(out, ("shipped " + base).c_str(), ScoreModel(shipped, held_out));
    PrintScore(out, ("retrained " + o.out).c_str(), ScoreModel(retrained, held_out));
    int not_logged = 0;
    const Score logged = ScoreLogged(held_out, &not_logged);
    if (logged.samples > 0) PrintScore(out, "logged at the trigger (closed loop)", logged);
    if (not_logged > 0) {
      out << "logged at the trigger (closed loop): " << not_logged << " of " << held_out.size()
          << " held-out samples left out (predicted or actual travel not logged: NULL)\n";
    }
    out << "\nmodel: " << o.out << ".model, " << o.out << ".scale, "
        << prediction::ProvenancePath(o.out) << "\n";
    return 0;
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::predictor
