// Issue 39, item 6: a trained penetration model says which machine and plant it was trained on
// (`<stem>.meta.yaml`, runtime/prediction/model_provenance.h), and a command driving another
// machine with it is warned. `autoshovel train predictor --machine M` (no database) trains on
// M's plant and writes the provenance; M may be a description's path.
#include "runtime/prediction/model_provenance.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "identification/predictor/retrain_command.h"
#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"
#include "runtime/prediction/penetration_predictor.h"

namespace autoshovel::prediction {
namespace {

namespace fs = std::filesystem;

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

model::MachineDescription Machine(const std::string& name) {
  return model::LoadMachineDescription(model::ResolveMachineDescription(name, kModels));
}

fs::path TempDir() {
  const fs::path dir = fs::temp_directory_path() /
                       ("autoshovel_provenance_" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  return dir;
}

std::string Slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The three shipped models were trained on the XCMG's plant from the description as it is now
// (retrained at this commit with the commands in identification/predictor/README.md: the same
// bytes): their provenance names it and no warning is due.
TEST(ModelProvenance, ShippedModelsRecordTheMachineTheyWereTrainedOn) {
  const model::MachineDescription xcmg = Machine("xcmg_968ev");
  for (const char* stem : {"penetration_svr", "penetration_svr_fast", "penetration_svr_push"}) {
    SCOPED_TRACE(stem);
    const std::string path = kModels + "/prediction/" + stem;
    const std::optional<ModelProvenance> p = LoadProvenance(path);
    ASSERT_TRUE(p.has_value());
    EXPECT_EQ(p->machine, "xcmg_968ev");
    EXPECT_EQ(p->description, "xcmg_968ev.yaml");
    EXPECT_EQ(p->sha256, xcmg.sha256);
    EXPECT_EQ(p->plant_code, "compiled in (generated/xcmg_968ev/)");
    // The command line is the one in the .scale file's note.
    const FeatureScaling scaling = PenetrationPredictor::LoadScaling(path);
    ASSERT_FALSE(scaling.notes.empty());
    EXPECT_EQ("trained by: " + p->trained_by, scaling.notes.front());
    EXPECT_EQ(scaling.machine, p->machine);
    EXPECT_EQ(ProvenanceMismatch(path, xcmg, "xcmg_968ev"), "");
  }
}

TEST(ModelProvenance, AnotherMachineIsNamedWithBothHashesAndTheRetrainCommand) {
  const model::MachineDescription sdlg = Machine("sdlg_l955he");
  const model::MachineDescription xcmg = Machine("xcmg_968ev");
  const std::string stem = kModels + "/prediction/penetration_svr_fast";
  const std::string why = ProvenanceMismatch(stem, sdlg, "models/loaders/sdlg_l955he.yaml");
  EXPECT_EQ(why, "penetration model " + stem + ".model was trained on xcmg_968ev (sha " +
                     xcmg.sha256.substr(0, 12) + "), not on sdlg_l955he (sha " +
                     sdlg.sha256.substr(0, 12) +
                     "): retrain with `autoshovel train predictor --machine "
                     "models/loaders/sdlg_l955he.yaml -o STEM` and run with --predictor STEM");
}

TEST(ModelProvenance, SameNameButAnotherVersionOfTheDescriptionIsNamed) {
  // A copy of the XCMG's description with one more comment line: same name, other SHA-256.
  const fs::path dir = TempDir();
  const fs::path file = dir / "xcmg_968ev.yaml";
  std::ofstream(file) << Slurp(kModels + "/loaders/xcmg_968ev.yaml") << "# edited\n";
  model::LoadOptions options;
  options.materials_dir = kModels + "/materials";
  const model::MachineDescription edited = model::LoadMachineDescription(file.string(), options);
  const std::string why =
      ProvenanceMismatch(kModels + "/prediction/penetration_svr_fast", edited, file.string());
  EXPECT_NE(why.find("was trained on xcmg_968ev (sha "), std::string::npos) << why;
  EXPECT_NE(why.find("not on this version of xcmg_968ev (sha " + edited.sha256.substr(0, 12) +
                     ", " + file.string() + ")"),
            std::string::npos)
      << why;
  fs::remove_all(dir);
}

TEST(ModelProvenance, SavedAndReadBackAtomically) {
  const fs::path dir = TempDir();
  const std::string stem = (dir / "m").string();
  ModelProvenance p;
  p.machine = "my_loader";
  p.description = "my_loader.yaml";
  p.sha256 = std::string(64, 'a');
  p.plant_samples = "simulated crowding runs";
  p.plant_code = "machine library (/home/u/.cache/x.so)";
  p.trained_by = "autoshovel train predictor --machine \"my loader.yaml\" -o m\\n";
  EXPECT_FALSE(LoadProvenance(stem).has_value());  // none yet
  SaveProvenance(stem, p);
  const std::optional<ModelProvenance> q = LoadProvenance(stem);
  ASSERT_TRUE(q.has_value());
  EXPECT_EQ(q->machine, p.machine);
  EXPECT_EQ(q->description, p.description);
  EXPECT_EQ(q->sha256, p.sha256);
  EXPECT_EQ(q->plant_samples, p.plant_samples);
  EXPECT_EQ(q->plant_code, p.plant_code);
  EXPECT_EQ(q->trained_by, p.trained_by);  // quotes and backslashes survive
  // Only the sidecar in the folder: the atomic write left no temporary file.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1);
  // What cannot be a provenance is not written.
  p.sha256 = "ABC";
  EXPECT_THROW(SaveProvenance(stem, p), std::invalid_argument);
  fs::remove_all(dir);
}

TEST(ModelProvenance, AModelWithoutOrWithABrokenSidecarIsWarnedAbout) {
  const fs::path dir = TempDir();
  const std::string stem = (dir / "copied").string();
  fs::copy_file(kModels + "/prediction/penetration_svr.model", stem + ".model");
  fs::copy_file(kModels + "/prediction/penetration_svr.scale", stem + ".scale");
  const model::MachineDescription xcmg = Machine("xcmg_968ev");
  const std::string none = ProvenanceMismatch(stem, xcmg, "xcmg_968ev");
  EXPECT_EQ(none, "penetration model " + stem + ".model has no provenance (" + stem +
                      ".meta.yaml): it may have been trained on another machine than xcmg_968ev: "
                      "retrain with `autoshovel train predictor --machine xcmg_968ev -o STEM` "
                      "and run with --predictor STEM");
  std::ofstream(stem + ".meta.yaml") << "format: autoshovel-model-provenance 1\nmachine: [\n";
  const std::string broken = ProvenanceMismatch(stem, xcmg, "xcmg_968ev");
  EXPECT_NE(broken.find("its provenance cannot be read (" + stem + ".meta.yaml:"),
            std::string::npos)
      << broken;
  fs::remove_all(dir);
}

// `autoshovel train predictor --machine FILE -o STEM` without a database: crowding runs on that
// machine's plant (a few, to keep the test short), the model and its provenance written.
TEST(ModelProvenance, TrainingOnTheMachinesPlantWritesItsProvenance) {
  const fs::path dir = TempDir();
  predictor::RetrainOptions o;
  o.machine = kModels + "/loaders/sdlg_l955he.yaml";  // a description's path
  o.models_dir = kModels;
  o.out = (dir / "sdlg_svr").string();
  o.threads = 2;
  o.plant.runs = 15;
  std::ostringstream out, err;
  ASSERT_EQ(predictor::RunRetrainPredictor(o, out, err), 0) << err.str() << out.str();
  EXPECT_NE(out.str().find("autoshovel train predictor: 15 crowding runs of sdlg_l955he"),
            std::string::npos)
      << out.str();
  const PenetrationPredictor model = PenetrationPredictor::Load(o.out);
  EXPECT_EQ(model.scaling().machine, "sdlg_l955he");
  EXPECT_EQ(model.scaling().travel_times.size(), 6u);  // the main job's recipe: travel curve
  const std::optional<ModelProvenance> p = LoadProvenance(o.out);
  ASSERT_TRUE(p.has_value());
  const model::MachineDescription sdlg = Machine("sdlg_l955he");
  EXPECT_EQ(p->machine, "sdlg_l955he");
  EXPECT_EQ(p->sha256, sdlg.sha256);
  EXPECT_EQ(p->plant_code, "compiled in (generated/sdlg_l955he/)");
  EXPECT_NE(p->trained_by.find("autoshovel train predictor --machine sdlg_l955he --runs 15 "),
            std::string::npos)
      << p->trained_by;
  EXPECT_NE(p->trained_by.find("--min-speed 1.5 --max-speed 1.5 --dug-face-fraction 0.4 "
                               "--scoop-deceleration 0.6 --travel-curve"),
            std::string::npos)
      << p->trained_by;
  // Trained on the SDLG, so the SDLG drives with it silently and the XCMG is warned.
  EXPECT_EQ(ProvenanceMismatch(o.out, sdlg, o.machine), "");
  EXPECT_NE(ProvenanceMismatch(o.out, Machine("xcmg_968ev"), "xcmg_968ev")
                .find("was trained on sdlg_l955he"),
            std::string::npos);
  // Never over an existing model.
  std::ostringstream out2, err2;
  EXPECT_EQ(predictor::RunRetrainPredictor(o, out2, err2), 2);
  EXPECT_NE(err2.str().find("already exists; a model is never overwritten"), std::string::npos)
      << err2.str();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace autoshovel::prediction
