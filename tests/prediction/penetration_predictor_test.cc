// The shipped penetration predictor (models/prediction/penetration_svr.*): it loads, refuses bad
// files and bad features with clear messages, and on a small set of fresh plant runs (a seed the
// training never used) it predicts within the error buckets of the seed's §7.4.1.
#include "runtime/prediction/penetration_predictor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "generated/registry.h"
#include "identification/predictor/crowding_runs.h"
#include "identification/predictor/evaluation.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::prediction {
namespace {

const std::string kShipped =
    std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/prediction/penetration_svr";
// Trained for the pushing scoop (scoop deceleration 0.3 m/s², approached at the 1 m/s attack
// speed): identification/predictor/README.md.
const std::string kPushing =
    std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/prediction/penetration_svr_push";

PenetrationFeatures SomeFeatures() {
  PenetrationFeatures f;
  f.speed = 0.8;
  f.shoveled_volume = 0.6;
  f.material = "small_gravel";
  f.heights = {0.9, 1.2, 1.5, 1.8, 2.0, 2.1};
  return f;
}

std::string TempStem(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("autoshovel_prediction_test_" + name)).string();
}

void Write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string LoadError(const std::string& stem) {
  try {
    PenetrationPredictor::Load(stem);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PenetrationPredictor, ShippedModelLoadsAndPredicts) {
  const PenetrationPredictor predictor = PenetrationPredictor::Load(kShipped);
  EXPECT_EQ(predictor.scaling().machine, "xcmg_968ev");
  EXPECT_EQ(predictor.scaling().names.size(), 2 + predictor.scaling().materials.size() + 6);
  const PenetrationPrediction p = predictor.Predict(SomeFeatures());
  ASSERT_TRUE(p.ok) << p.message;
  EXPECT_GE(p.penetration, 0.0);
  EXPECT_LT(p.penetration, 5.0);
}

// The intake factor round-trips through the .scale file; a material without one has κ = 1. The
// braking scoop's model has none (its trigger is the seed's V1 + V2 ≥ V_t); the pushing scoop's
// was fitted on its training runs and lies between 1 and 1.5 for every material, largest in
// sand (README: 1.06 / 1.23 / 1.07 for big gravel / river sand / small gravel).
TEST(PenetrationPredictor, IntakeFactorRoundTripsAndDefaultsToOne) {
  EXPECT_TRUE(PenetrationPredictor::Load(kShipped).scaling().intake_factor.empty());
  EXPECT_EQ(PenetrationPredictor::Load(kShipped).IntakeFactor("river_sand"), 1.0);
  const PenetrationPredictor pushing = PenetrationPredictor::Load(kPushing);
  ASSERT_EQ(pushing.scaling().intake_factor.size(), pushing.scaling().materials.size());
  for (const std::string& material : pushing.scaling().materials) {
    EXPECT_GT(pushing.IntakeFactor(material), 1.0) << material;
    EXPECT_LT(pushing.IntakeFactor(material), 1.5) << material;
  }
  EXPECT_GT(pushing.IntakeFactor("river_sand"), pushing.IntakeFactor("big_gravel"));
  EXPECT_EQ(pushing.IntakeFactor("no_such_material"), 1.0);

  const std::string stem = TempStem("intake");
  FeatureScaling scaling = PenetrationPredictor::LoadScaling(kShipped);
  scaling.intake_factor = {{"river_sand", 1.25}, {"big_gravel", 1.0 / 3.0}};
  PenetrationPredictor::SaveScaling(stem, scaling);
  EXPECT_EQ(PenetrationPredictor::LoadScaling(stem).intake_factor, scaling.intake_factor);
  std::filesystem::remove(stem + ".scale");
}

TEST(PenetrationPredictor, RefusesNanAndUnknownFeatures) {
  const PenetrationPredictor predictor = PenetrationPredictor::Load(kShipped);
  PenetrationFeatures f = SomeFeatures();
  f.heights[2] = std::nan("");
  PenetrationPrediction p = predictor.Predict(f);
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.message.find("h3"), std::string::npos) << p.message;
  f = SomeFeatures();
  f.speed = std::nan("");
  EXPECT_FALSE(predictor.Predict(f).ok);
  f = SomeFeatures();
  f.shoveled_volume = -1;
  EXPECT_FALSE(predictor.Predict(f).ok);
  f = SomeFeatures();
  f.material = "granite";
  p = predictor.Predict(f);
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.message.find("granite"), std::string::npos) << p.message;
}

TEST(PenetrationPredictor, BadModelFilesGiveClearErrors) {
  const std::string stem = TempStem("bad");
  std::filesystem::copy_file(kShipped + ".scale", stem + ".scale",
                             std::filesystem::copy_options::overwrite_existing);
  // Missing model file.
  std::filesystem::remove(stem + ".model");
  std::string error = LoadError(stem);
  EXPECT_NE(error.find(stem + ".model"), std::string::npos) << error;
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
  // Not a libsvm model.
  Write(stem + ".model", "this is not a model\n");
  error = LoadError(stem);
  EXPECT_NE(error.find(stem + ".model"), std::string::npos) << error;
  EXPECT_NE(error.find("not a libsvm model"), std::string::npos) << error;
  // A classifier instead of an ε-SVR.
  Write(stem + ".model",
        "svm_type c_svc\nkernel_type rbf\ngamma 0.5\nnr_class 2\ntotal_sv 2\nrho 0\nlabel 1 -1\n"
        "nr_sv 1 1\nSV\n1 1:0.5\n-1 1:-0.5\n");
  error = LoadError(stem);
  EXPECT_NE(error.find("epsilon_svr"), std::string::npos) << error;
  // A support vector on a feature the scaling does not have.
  Write(stem + ".model",
        "svm_type epsilon_svr\nkernel_type rbf\ngamma 0.5\nnr_class 2\ntotal_sv 1\nrho 0\nSV\n"
        "1 1:0.5 40:0.1\n");
  error = LoadError(stem);
  EXPECT_NE(error.find("feature index 40"), std::string::npos) << error;
  // A malformed scaling file names its line.
  std::filesystem::copy_file(kShipped + ".model", stem + ".model",
                             std::filesystem::copy_options::overwrite_existing);
  Write(stem + ".scale", "format autoshovel-penetration-svr 1\nmaterials a b\nfeature speed x y\n");
  error = LoadError(stem);
  EXPECT_NE(error.find(stem + ".scale:3:"), std::string::npos) << error;
  EXPECT_NE(error.find("expected 10 features"), std::string::npos) << error;
  std::filesystem::remove(stem + ".scale");
  error = LoadError(stem);
  EXPECT_NE(error.find(stem + ".scale"), std::string::npos) << error;
  std::filesystem::remove(stem + ".model");
}

// The optional travel curve: its times survive a save and load, a bad line names itself, and a
// scaling that names travel times needs their model files.
TEST(PenetrationPredictor, TravelCurveRoundTripsAndBadOnesNameTheirLineOrFile) {
  const std::string stem = TempStem("travel");
  FeatureScaling scaling = PenetrationPredictor::LoadScaling(kShipped);
  EXPECT_TRUE(scaling.travel_times.empty());  // the braking scoop's model has none
  scaling.travel_times = {0.5, 1.0, 1.5};
  PenetrationPredictor::SaveScaling(stem, scaling);
  const FeatureScaling back = PenetrationPredictor::LoadScaling(stem);
  EXPECT_EQ(back.travel_times, scaling.travel_times);
  EXPECT_EQ(back.names, scaling.names);

  // The d model stands in for every knot: the curve then predicts d at each time.
  std::filesystem::copy_file(kShipped + ".model", stem + ".model",
                             std::filesystem::copy_options::overwrite_existing);
  for (std::size_t k = 0; k < 3; ++k) {
    std::filesystem::copy_file(kShipped + ".model", PenetrationPredictor::TravelModelPath(stem, k),
                               std::filesystem::copy_options::overwrite_existing);
  }
  const PenetrationPrediction p = PenetrationPredictor::Load(stem).Predict(SomeFeatures());
  ASSERT_TRUE(p.ok) << p.message;
  ASSERT_EQ(p.travel.size(), 3u);
  for (double s : p.travel) EXPECT_DOUBLE_EQ(s, p.penetration);

  std::filesystem::remove(PenetrationPredictor::TravelModelPath(stem, 2));
  std::string error = LoadError(stem);
  EXPECT_NE(error.find(stem + ".travel3.model"), std::string::npos) << error;
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;

  std::ifstream in(stem + ".scale");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find("travel_times ");
  ASSERT_NE(at, std::string::npos);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  const std::size_t end = text.find('\n', at);
  for (const char* bad : {"travel_times 0.5 0.4", "travel_times 0 1", "travel_times",
                          "travel_times 0.5 nan", "travel_times 0.5 x"}) {
    Write(stem + ".scale", text.substr(0, at) + bad + text.substr(end));
    error.clear();
    try {
      PenetrationPredictor::LoadScaling(stem);
    } catch (const core::InputError& e) {
      error = e.what();
    }
    EXPECT_NE(error.find(stem + ".scale:" + std::to_string(line) + ":"), std::string::npos)
        << bad << ": " << error;
    EXPECT_NE(error.find("travel_times"), std::string::npos) << error;
  }
  std::filesystem::remove(stem + ".scale");
  std::filesystem::remove(stem + ".model");
  for (std::size_t k = 0; k < 2; ++k) {
    std::filesystem::remove(PenetrationPredictor::TravelModelPath(stem, k));
  }
}

// Plant runs of seed 2024 (the models were trained on seed 1) scored with the model `stem`:
// `dug_face_fraction` of them on a face an earlier scoop left (crowding_runs.h), in the regime
// `options` (default: the shipped model's).
predictor::PredictorEvaluation ScoreModel(const std::string& stem, double dug_face_fraction,
                                          predictor::CrowdingRunOptions options = {}) {
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription(
          "xcmg_968ev", std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"));
  const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
  EXPECT_NE(functions, nullptr);
  if (functions == nullptr) return {};
  const PenetrationPredictor predictor = PenetrationPredictor::Load(stem);
  options.dug_face_fraction = dug_face_fraction;
  const std::vector<predictor::CrowdingRun> runs =
      predictor::RunCrowdingBatch(machine, *functions, options, 2024, 0, 100, 2);
  std::vector<const predictor::CrowdingRun*> pointers;
  for (const auto& run : runs) {
    EXPECT_TRUE(run.ok) << "run " << run.spec.index << ": " << run.failure;
    pointers.push_back(&run);
  }
  double capacity = 0;
  for (const auto& run : runs) capacity = std::max(capacity, run.payload);
  const predictor::PredictorEvaluation e =
      predictor::EvaluatePredictor(predictor, machine, pointers, capacity);
  std::printf("%s\n", predictor::FormatEvaluation(e).c_str());
  EXPECT_EQ(e.samples, 100);
  EXPECT_EQ(e.refused, 0);
  return e;
}

// Fresh piles. On these 100 runs the shipped model is within 0.10 m on all of them, MSE
// 0.0002 m² (README: 100 % of its 249 fresh test runs of seed 1). Asserted: the seed's §7.4.1
// goals of issue 6 (80 / 97 / 99.5 %), the outer one as at most one miss in 100.
TEST(PenetrationPredictor, FreshPlantRunsFallInTheErrorBuckets) {
  const predictor::PredictorEvaluation e = ScoreModel(kShipped, 0.0);
  SCOPED_TRACE(predictor::FormatEvaluation(e));
  EXPECT_GE(e.within_010, 0.80);
  EXPECT_GE(e.within_015, 0.97);
  EXPECT_GE(e.within_020, 0.99);
  EXPECT_GE(e.volume_accuracy, 0.93);
  EXPECT_GE(e.volume_accuracy_capped, 0.93);
}

// Every run on a dug face, the pile of every revisit. On these 100 runs the shipped model is
// within 0.10 / 0.15 / 0.20 m on 99 / 99 / 99 %, MSE 0.0024 m², volume accuracy 95.2 % (README,
// on the 151 dug test runs of seed 1: 96.0 / 98.0 / 99.3 %, MSE 0.0015 m²). On those same 151
// runs the model shipped before it (1000 runs approached at up to 2 m/s) had MSE 0.0079 m²,
// above the bound here.
TEST(PenetrationPredictor, DugFaceRunsFallInTheErrorBuckets) {
  const predictor::PredictorEvaluation e = ScoreModel(kShipped, 1.0);
  SCOPED_TRACE(predictor::FormatEvaluation(e));
  EXPECT_GE(e.within_010, 0.90);
  EXPECT_GE(e.within_015, 0.95);
  EXPECT_GE(e.within_020, 0.97);
  EXPECT_LE(e.mse, 0.006);
  EXPECT_GE(e.volume_accuracy, 0.93);
}

// The pushing scoop's model on runs of its own regime (40 % dug faces, as it was trained): the
// §7.4.1 goals, the outer one as at most one miss in 100. Trained with the approach speed free
// in 0.5–1.25 m/s, the same runs gave 83.2 / 91.0 / 93.8 %: under the pushing scoop the speed
// reference restarts from the attack speed, not from the speed at the trigger, so the approach
// speed was a hidden variable of d (docs/scooping_control.md).
TEST(PenetrationPredictor, PushingScoopModelFallsInTheErrorBuckets) {
  predictor::CrowdingRunOptions options;
  options.scoop_deceleration = 0.3;
  options.min_speed = options.max_speed = 1.0;
  const predictor::PredictorEvaluation e = ScoreModel(kPushing, 0.4, options);
  SCOPED_TRACE(predictor::FormatEvaluation(e));
  EXPECT_GE(e.within_010, 0.80);
  EXPECT_GE(e.within_015, 0.97);
  EXPECT_GE(e.within_020, 0.99);
  EXPECT_LE(e.mse, 0.004);
  // Its travel curve: six knots, 0.5–3 s after the trigger, as close as d itself.
  EXPECT_EQ(e.travel_knots, 6);
  EXPECT_GE(e.travel_within_010, 0.95);
  EXPECT_LE(e.travel_mse, 0.002);
  // κ_M·(V1 + V2) against the payload (seed §7.4.1's final volume accuracy; the seed: 92.6 %).
  EXPECT_GE(e.volume_accuracy_capped, 0.93);
}

}  // namespace
}  // namespace autoshovel::prediction
