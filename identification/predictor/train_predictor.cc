// train_predictor: generates plant crowding runs, trains the ε-SVR penetration predictor on 80 %
// of them and scores it on the other 20 % (wheel-loader seed §6.1, §7.4.1). See README.md.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include "generated/registry.h"
#include "identification/predictor/crowding_runs.h"
#include "identification/predictor/evaluation.h"
#include "identification/predictor/svr_training.h"

using namespace autoshovel;

int main(int argc, char** argv) {
  CLI::App app{"Train the penetration-depth predictor (epsilon-SVR) on plant crowding runs"};
  std::string machine_name = "xcmg_968ev";
  std::string models_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  std::string out = "models/prediction/penetration_svr";
  std::string samples_csv;
  int runs = 1000;
  std::uint64_t seed = 1;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  app.add_option("--machine", machine_name, "machine description name")->capture_default_str();
  app.add_option("--models-dir", models_dir, "models directory")->capture_default_str();
  app.add_option("--out", out, "model path stem: writes <stem>.model and <stem>.scale")
      ->capture_default_str();
  app.add_option("--runs", runs, "crowding runs (>= 1000 for the shipped model)")
      ->capture_default_str();
  app.add_option("--seed", seed, "seed of the randomised runs")->capture_default_str();
  app.add_option("--threads", threads, "worker threads")->capture_default_str();
  app.add_option("--samples-csv", samples_csv, "also write every sample to this CSV file");
  double scoop_deceleration = 0;
  app.add_option("--scoop-deceleration", scoop_deceleration,
                 "after the bucket moves, follow a speed reference falling at this rate [m/s^2] "
                 "instead of releasing the drive (0: release, the shipped model's regime)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  try {
    const model::MachineDescription machine =
        model::LoadMachineDescription(model::ResolveMachineDescription(machine_name, models_dir));
    const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
    if (functions == nullptr) throw std::runtime_error("no generated code for " + machine.name);

    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    predictor::CrowdingRunOptions options;
    options.scoop_deceleration = scoop_deceleration;
    std::printf("train_predictor: %d crowding runs of %s on %d threads, seed %llu\n", runs,
                machine.name.c_str(), threads, static_cast<unsigned long long>(seed));
    std::fflush(stdout);
    const std::vector<predictor::CrowdingRun> all = predictor::RunCrowdingBatch(
        machine, *functions, options, seed, 0, runs, threads,
        [&](const predictor::CrowdingRun& run, int done) {
          if (!run.ok) std::printf("  run %d failed: %s\n", run.spec.index, run.failure.c_str());
          if (done % 50 == 0) {
            std::printf("  %d/%d runs, %.0f s\n", done, runs, elapsed());
            std::fflush(stdout);
          }
        });
    const double generation_time = elapsed();

    std::vector<std::string> materials;
    for (const model::Material& m : machine.materials) materials.push_back(m.name);
    // 80/20 split by run index: runs 5k+4 are the test set (the specs are i.i.d. draws).
    predictor::SvrDataset train;
    std::vector<const predictor::CrowdingRun*> test_runs, train_runs;
    int failed = 0;
    for (const predictor::CrowdingRun& run : all) {
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
    prediction::FeatureScaling scaling;
    scaling.machine = machine.name;
    scaling.materials = materials;
    char note[512];
    std::snprintf(note, sizeof note,
                  "trained by: train_predictor --machine %s --runs %d --seed %llu --out %s",
                  machine.name.c_str(), runs, static_cast<unsigned long long>(seed), out.c_str());
    scaling.notes.push_back(note);
    std::filesystem::create_directories(std::filesystem::path(out).parent_path().empty()
                                            ? std::filesystem::path(".")
                                            : std::filesystem::path(out).parent_path());
    const predictor::SvrGrid grid;
    const predictor::SvrTrainingResult fit =
        predictor::TrainPenetrationSvr(train, grid, threads, scaling, out);
    const double training_time = elapsed() - generation_time;

    const prediction::PenetrationPredictor model = prediction::PenetrationPredictor::Load(out);
    if (!samples_csv.empty()) {
      // Every completed run with the final model's prediction beside its target, so the error
      // tail can be read by cause (test set: runs i mod 5 = 4).
      std::ofstream csv(samples_csv);
      csv << "run,set,shape,material,height,v0,trigger_volume,trigger_cause,speed,V1,h1,h2,h3,h4,"
             "h5,h6,penetration,predicted_penetration,payload\n";
      for (const predictor::CrowdingRun& run : all) {
        if (!run.ok) continue;
        csv << run.spec.index << "," << (run.spec.index % 5 == 4 ? "test" : "train") << ","
            << run.spec.shape << "," << run.spec.material << "," << run.spec.height << ","
            << run.spec.approach_speed << "," << run.spec.trigger_volume << "," << run.trigger_cause
            << "," << run.features.speed << "," << run.features.shoveled_volume;
        for (double h : run.features.heights) csv << "," << h;
        const prediction::PenetrationPrediction predicted = model.Predict(run.features);
        csv << "," << run.penetration << ","
            << (predicted.ok ? predicted.penetration : std::nan("")) << "," << run.payload << "\n";
      }
      if (!csv) throw std::runtime_error("cannot write " + samples_csv);
    }
    double capacity = 0;  // what the bucket holds full and racked back (evaluation.h)
    for (const predictor::CrowdingRun* run : train_runs)
      capacity = std::max(capacity, run->payload);
    std::printf("bucket capacity racked back (largest training payload): %.3f m^3\n", capacity);
    const predictor::PredictorEvaluation on_test =
        predictor::EvaluatePredictor(model, machine, test_runs, capacity);
    const predictor::PredictorEvaluation on_train =
        predictor::EvaluatePredictor(model, machine, train_runs, capacity);
    std::printf("runs: %d (%d failed), train %zu, test %zu; generation %.0f s, training %.0f s\n",
                runs, failed, train.y.size(), test_runs.size(), generation_time, training_time);
    std::printf(
        "SVR: C %g, gamma %g, epsilon %g, %d-fold CV MSE %.4f m^2 (%d settings), %d "
        "support vectors\n",
        fit.c, fit.gamma, fit.epsilon, grid.folds, fit.cv_mse, fit.settings_tried,
        fit.support_vectors);
    std::printf("test:  %s\n", predictor::FormatEvaluation(on_test).c_str());
    std::printf("train: %s\n", predictor::FormatEvaluation(on_train).c_str());
    std::printf("wrote %s.model and %s.scale\n", out.c_str(), out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "train_predictor: %s\n", e.what());
    return 1;
  }
}
