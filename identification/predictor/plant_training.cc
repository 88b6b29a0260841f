// Training the penetration predictor on a machine's simulated plant (plant_training.h).
#include "identification/predictor/plant_training.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <sstream>

#include "identification/predictor/evaluation.h"
#include "runtime/core/file_output.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"
#include "runtime/prediction/model_provenance.h"
#include "runtime/prediction/penetration_predictor.h"

namespace autoshovel::predictor {

namespace {

// printf to a stream (the tool printed with printf; the figures keep their format).
void Print(std::ostream& out, const char* format, ...) {
  char line[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  out << line;
}

std::string Joined(const std::vector<double>& values) {
  std::string text;
  char number[32];
  for (double v : values) {
    std::snprintf(number, sizeof number, "%g", v);
    text += (text.empty() ? "" : ",") + std::string(number);
  }
  return text;
}

}  // namespace

int RunPlantTraining(const PlantTrainingOptions& o, std::ostream& out, std::ostream& err) {
  const std::string& command = o.command;
  if (o.out.empty()) {
    err << command << ": give --out STEM for the new model (.model, .scale, .meta.yaml)\n";
    return 2;
  }
  if (!(o.run_options.min_speed <= o.run_options.max_speed)) {
    err << command << ": --min-speed must not exceed --max-speed\n";
    return 2;
  }
  if (o.runs < 5) {
    err << command << ": --runs must be at least 5 (every fifth run is a test run), got " << o.runs
        << "\n";
    return 2;
  }
  model::MachineDescription machine;
  machines::MachineCode code;
  try {
    machine =
        model::LoadMachineDescription(model::ResolveMachineDescription(o.machine, o.models_dir));
    // Compiled in, the machine library `autoshovel gen` built, or the interpreted model: the
    // plant the runs are made on, recorded in the provenance.
    machines::ResolveOptions resolve;
    resolve.notes = &err;
    code = machines::ResolveMachineCode(machine, resolve);
  } catch (const std::exception& e) {
    err << command << ": " << e.what() << "\n";
    return 2;
  }
  const generated::MachineFunctions* functions = code.functions;
  const std::string plant_code =
      std::string(machines::ToString(code.source)) + " (" + code.where + ")";
  try {
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    CrowdingRunOptions options = o.run_options;
    options.scoop_deceleration = o.scoop_deceleration;
    options.dug_face_fraction = o.dug_face_fraction;
    const int runs = o.runs;
    Print(out, "%s: %d crowding runs of %s on %d threads, seed %llu\n", command.c_str(), runs,
          machine.name.c_str(), o.threads, static_cast<unsigned long long>(o.seed));
    out.flush();
    const std::vector<CrowdingRun> all = RunCrowdingBatch(
        machine, *functions, options, o.seed, 0, runs, o.threads,
        [&](const CrowdingRun& run, int done) {
          if (!run.ok) Print(out, "  run %d failed: %s\n", run.spec.index, run.failure.c_str());
          if (done % 50 == 0) {
            Print(out, "  %d/%d runs, %.0f s\n", done, runs, elapsed());
            out.flush();
          }
        });
    const double generation_time = elapsed();

    std::vector<std::string> materials;
    for (const model::Material& m : machine.materials) materials.push_back(m.name);
    // 80/20 split by run index: runs 5k+4 are the test set (the specs are i.i.d. draws).
    SvrDataset train;
    std::vector<const CrowdingRun*> test_runs, train_runs;
    int failed = 0;
    for (const CrowdingRun& run : all) {
      if (!run.ok) {
        ++failed;
        continue;
      }
      if (run.spec.index % 5 == 4) {
        test_runs.push_back(&run);
        continue;
      }
      std::string why;
      const std::vector<double> x =
          prediction::PenetrationPredictor::Encode(run.features, materials, &why);
      if (x.empty()) throw std::runtime_error("run " + std::to_string(run.spec.index) + ": " + why);
      train.x.push_back(x);
      train.y.push_back(run.penetration);
      train_runs.push_back(&run);
    }
    if (train.x.size() < 5 || test_runs.empty()) {
      err << command << ": only " << train.x.size() << " training and " << test_runs.size()
          << " test runs completed (" << failed << " failed): too few to train\n";
      return 1;
    }
    prediction::FeatureScaling scaling;
    scaling.machine = machine.name;
    scaling.materials = materials;
    std::string note = "trained by: " + command + " --machine " + machine.name + " --runs " +
                       std::to_string(runs) + " --seed " + std::to_string(o.seed) + " --c " +
                       Joined(o.grid.c) + " --gamma " + Joined(o.grid.gamma) + " --epsilon " +
                       Joined(o.grid.epsilon) + " --out " + o.out;
    {
      char speeds[96];
      std::snprintf(speeds, sizeof speeds, " --min-speed %g --max-speed %g", options.min_speed,
                    options.max_speed);
      note += speeds;
    }
    if (o.dug_face_fraction > 0) {
      char dug[64];
      std::snprintf(dug, sizeof dug, " --dug-face-fraction %g", o.dug_face_fraction);
      note += dug;
    }
    if (o.scoop_deceleration > 0) {
      char deceleration[64];
      std::snprintf(deceleration, sizeof deceleration, " --scoop-deceleration %g",
                    o.scoop_deceleration);
      note += deceleration;
    }
    if (o.travel_curve) {
      note += " --travel-curve --travel-times " + Joined(o.travel_times);
      scaling.travel_times = o.travel_times;
    }
    if (o.intake_factor) note += " --intake-factor";
    scaling.notes.push_back(note);
    const std::filesystem::path parent = std::filesystem::path(o.out).parent_path();
    core::CreateFolders(parent.empty() ? std::filesystem::path(".") : parent);
    const SvrTrainingResult fit = TrainPenetrationSvr(train, o.grid, o.threads, scaling, o.out);
    if (o.travel_curve) {
      for (std::size_t k = 0; k < o.travel_times.size(); ++k) {
        SvrDataset knot;
        knot.x = train.x;
        for (const CrowdingRun* run : train_runs) {
          knot.y.push_back(TravelAt(*run, o.travel_times[k]));
        }
        const std::string path = prediction::PenetrationPredictor::TravelModelPath(o.out, k);
        const int vectors = FitSvr(knot, scaling, fit.c, fit.gamma, fit.epsilon, path);
        Print(out, "travel at %.2f s: %d support vectors, %s\n", o.travel_times[k], vectors,
              path.c_str());
      }
    }
    const double training_time = elapsed() - generation_time;

    double capacity = 0;  // what the bucket holds full and racked back (evaluation.h)
    for (const CrowdingRun* run : train_runs) capacity = std::max(capacity, run->payload);
    if (o.intake_factor) {
      // Fitted with the final d and travel models on the training runs, then stored beside them.
      const prediction::PenetrationPredictor fitted = prediction::PenetrationPredictor::Load(o.out);
      prediction::FeatureScaling with_intake = fitted.scaling();
      with_intake.intake_factor = FitIntakeFactors(fitted, machine, train_runs, capacity);
      for (const auto& [material, factor] : with_intake.intake_factor) {
        Print(out, "intake factor %s: %.3f\n", material.c_str(), factor);
      }
      prediction::PenetrationPredictor::SaveScaling(o.out, with_intake);
    }
    const prediction::PenetrationPredictor model = prediction::PenetrationPredictor::Load(o.out);
    // The model is complete: say which machine and plant it was trained on.
    prediction::SaveProvenance(
        o.out, prediction::ModelProvenance::OfSimulatedPlant(
                   machine, plant_code, note.substr(std::string("trained by: ").size())));
    if (!o.samples_csv.empty()) {
      // Every completed run with the final model's prediction beside its target, so the error
      // tail can be read by cause (test set: runs i mod 5 = 4).
      std::ostringstream csv;  // then one checked atomic write (core/file_output.h)
      csv << "run,set,shape,material,height,v0,trigger_volume,trigger_cause,speed,V1,h1,h2,h3,h4,"
             "h5,h6,penetration,predicted_penetration,payload,dug_depth\n";
      for (const CrowdingRun& run : all) {
        if (!run.ok) continue;
        csv << run.spec.index << "," << (run.spec.index % 5 == 4 ? "test" : "train") << ","
            << run.spec.shape << "," << run.spec.material << "," << run.spec.height << ","
            << run.spec.approach_speed << "," << run.spec.trigger_volume << "," << run.trigger_cause
            << "," << run.features.speed << "," << run.features.shoveled_volume;
        for (double h : run.features.heights) csv << "," << h;
        const prediction::PenetrationPrediction predicted = model.Predict(run.features);
        csv << "," << run.penetration << ","
            << (predicted.ok ? predicted.penetration : std::nan("")) << "," << run.payload << ","
            << run.spec.dug_depth << "\n";
      }
      core::WriteFileAtomically(o.samples_csv, csv.str());
    }
    Print(out, "bucket capacity racked back (largest training payload): %.3f m^3\n", capacity);
    const PredictorEvaluation on_test = EvaluatePredictor(model, machine, test_runs, capacity);
    const PredictorEvaluation on_train = EvaluatePredictor(model, machine, train_runs, capacity);
    Print(out, "runs: %d (%d failed), train %zu, test %zu; generation %.0f s, training %.0f s\n",
          runs, failed, train.y.size(), test_runs.size(), generation_time, training_time);
    Print(out,
          "SVR: C %g, gamma %g, epsilon %g, %d-fold CV MSE %.4f m^2 (%d settings), %d "
          "support vectors\n",
          fit.c, fit.gamma, fit.epsilon, o.grid.folds, fit.cv_mse, fit.settings_tried,
          fit.support_vectors);
    Print(out, "test:  %s\n", FormatEvaluation(on_test).c_str());
    Print(out, "train: %s\n", FormatEvaluation(on_train).c_str());
    // The test runs split two ways: by approach speed (the closed loop attacks at 1 m/s, the runs
    // are drawn up to 2 m/s, and a fast machine glides through a low pile past the 3 m the six
    // heights see) and, when the runs hold both, into fresh piles and dug faces.
    std::vector<const CrowdingRun*> slow_runs, fast_runs, fresh_runs, dug_runs;
    for (const CrowdingRun* run : test_runs) {
      (run->spec.approach_speed <= o.envelope_speed ? slow_runs : fast_runs).push_back(run);
      (run->spec.dug_depth > 0 ? dug_runs : fresh_runs).push_back(run);
    }
    char slow_label[64], fast_label[64];
    std::snprintf(slow_label, sizeof slow_label, "v0 <= %.2f m/s", o.envelope_speed);
    std::snprintf(fast_label, sizeof fast_label, "v0 > %.2f m/s", o.envelope_speed);
    std::vector<std::pair<std::string, const std::vector<const CrowdingRun*>*>> subsets = {
        {slow_label, &slow_runs}, {fast_label, &fast_runs}};
    if (!dug_runs.empty()) {
      subsets.push_back({"fresh piles", &fresh_runs});
      subsets.push_back({"dug faces", &dug_runs});
    }
    auto score_subsets = [&](const prediction::PenetrationPredictor& scored,
                             const std::string& prefix) {
      for (const auto& [label, subset] : subsets) {
        if (subset->empty()) continue;
        Print(out, "%stest, %s: %s\n", prefix.c_str(), label.c_str(),
              FormatEvaluation(EvaluatePredictor(scored, machine, *subset, capacity)).c_str());
      }
    };
    score_subsets(model, "");
    if (!o.compare_with.empty()) {
      const prediction::PenetrationPredictor other =
          prediction::PenetrationPredictor::Load(o.compare_with);
      Print(out, "%s, test: %s\n", o.compare_with.c_str(),
            FormatEvaluation(EvaluatePredictor(other, machine, test_runs, capacity)).c_str());
      score_subsets(other, o.compare_with + ", ");
    }
    Print(out, "wrote %s.model, %s.scale and %s\n", o.out.c_str(), o.out.c_str(),
          prediction::ProvenancePath(o.out).c_str());
    return 0;
  } catch (const std::exception& e) {
    err << command << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace autoshovel::predictor
