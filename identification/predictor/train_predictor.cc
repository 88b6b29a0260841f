// train_predictor: generates plant crowding runs, trains the ε-SVR penetration predictor on 80 %
// of them and scores it on the other 20 % (wheel-loader seed §6.1, §7.4.1). See README.md. The
// work is plant_training.h's, which `autoshovel train predictor --machine M` runs too; this tool
// keeps the options of the commands that made the shipped models.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <thread>

#include "identification/predictor/plant_training.h"

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
  double dug_face_fraction = 0;
  app.add_option("--dug-face-fraction", dug_face_fraction,
                 "share of runs on a pile a previous scoop has dug into (a revisit's face; 0: "
                 "fresh piles only, the shipped model's regime)")
      ->check(CLI::Range(0.0, 1.0));
  predictor::CrowdingRunOptions run_options;
  app.add_option("--min-speed", run_options.min_speed,
                 "slowest approach speed v0 of the runs [m/s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-speed", run_options.max_speed,
                 "fastest approach speed v0 of the runs [m/s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  bool travel_curve = false;
  app.add_flag("--travel-curve", travel_curve,
               "also train one SVR per --travel-times knot for the machine's travel that long "
               "after the trigger (files <stem>.travel<k>.model): V2 then follows the predicted "
               "curve instead of a constant deceleration over d");
  std::vector<double> travel_times = {0.5, 1.0, 1.5, 2.0, 2.5, 3.0};
  app.add_option("--travel-times", travel_times, "knots of the travel curve [s after the trigger]")
      ->delimiter(',')
      ->capture_default_str();
  bool intake_factor = false;
  app.add_flag("--intake-factor", intake_factor,
               "also fit the intake factor per material (payload over V1 + V2 on the training "
               "runs whose bucket did not fill) and write it to the .scale file: the trigger then "
               "compares it times V1 + V2 with V_t (penetration_predictor.h)");
  std::string compare_with;
  app.add_option("--compare", compare_with,
                 "also score this model (path stem) on the same test runs, e.g. the shipped "
                 "models/prediction/penetration_svr");
  double envelope_speed = 1.25;
  app.add_option("--envelope-speed", envelope_speed,
                 "also score the test runs approached at most this fast, and the faster ones "
                 "apart [m/s] (the scoop cycle attacks at 1 m/s)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  predictor::SvrGrid grid;
  app.add_option("--c", grid.c, "SVR cost values of the grid search")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--gamma", grid.gamma, "RBF gamma values of the grid search")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--epsilon", grid.epsilon, "epsilon-tube widths of the grid search [m]")
      ->delimiter(',')
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  predictor::PlantTrainingOptions o;
  o.machine = machine_name;
  o.models_dir = models_dir;
  o.out = out;
  o.samples_csv = samples_csv;
  o.runs = runs;
  o.seed = seed;
  o.threads = threads;
  o.run_options = run_options;
  o.scoop_deceleration = scoop_deceleration;
  o.dug_face_fraction = dug_face_fraction;
  o.travel_curve = travel_curve;
  o.travel_times = travel_times;
  o.intake_factor = intake_factor;
  o.compare_with = compare_with;
  o.envelope_speed = envelope_speed;
  o.grid = grid;
  o.command = "train_predictor";
  return predictor::RunPlantTraining(o, std::cout, std::cerr);
}
