// The production report (Tables 6–7, the adaptive-vs-Stairway-#3 comparison, Fig. 22) on a
// campaign database with known rows; Tukey's box statistics by hand; a restocked yard.
#include "runtime/app/campaign/production_report.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "runtime/app/campaign/campaign_spec.h"
#include "runtime/app/campaign/campaign_store.h"
#include "runtime/plant/scenario.h"
#include "runtime/plant/scenario_builder.h"
#include "runtime/plot/box_plot.h"
#include "runtime/results/results_db.h"

namespace autoshovel::app {
namespace {

namespace fs = std::filesystem;

TEST(BoxStatistics, TukeyByHand) {
  // 1…9 and 100: quartiles by linear interpolation at positions 2.25, 4.5, 6.75.
  const plot::BoxStatistics s = plot::ComputeBoxStatistics({5, 1, 9, 2, 8, 3, 7, 4, 6, 100, NAN});
  EXPECT_EQ(s.count, 10);
  EXPECT_DOUBLE_EQ(s.q1, 3.25);
  EXPECT_DOUBLE_EQ(s.median, 5.5);
  EXPECT_DOUBLE_EQ(s.q3, 7.75);
  EXPECT_DOUBLE_EQ(s.low_whisker, 1);
  EXPECT_DOUBLE_EQ(s.high_whisker, 9);  // 100 lies beyond q3 + 1.5 IQR = 14.5
  ASSERT_EQ(s.outliers.size(), 1u);
  EXPECT_EQ(s.outliers[0], 100);
  EXPECT_EQ(plot::ComputeBoxStatistics({}).count, 0);
}

fs::path TempDir() {
  const fs::path dir =
      fs::temp_directory_path() / ("autoshovel_production_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

results::CycleRecord Cycle(int index, const std::string& material, const std::string& strategy,
                           const std::string& actions, double crowd_s, double scoop_s,
                           double crowd_kj, double scoop_kj, double fill) {
  results::CycleRecord c;
  c.cycle = index;
  c.scenario = "mixing_station";
  c.machine = "xcmg_968ev";
  c.bin = "bin_1";
  c.material = material;
  c.strategy = strategy;
  c.atomic_actions = actions;
  c.fill_rate = fill;
  c.time_s.crowd = crowd_s, c.time_s.scoop = scoop_s;
  c.energy_kj.crowd = crowd_kj, c.energy_kj.scoop = scoop_kj;
  return c;
}

TEST(ProductionReport, TablesAndTheComparisonFromKnownRows) {
  const fs::path dir = TempDir();
  CampaignSpec spec;
  spec.name = "t";
  spec.weeks = 2;
  spec.shifts_per_week = 1;
  spec.cycles_per_shift = 2;
  spec.policies = {"auto", "stairway_fixed"};
  const std::vector<CampaignJob> jobs = CampaignJobs(spec);
  const fs::path db_file = dir / "results.sqlite";
  PrepareCampaignDatabase(db_file, spec, jobs);
  {
    results::ResultsDb db(db_file);
    for (const CampaignJob& job : jobs) {
      results::RunInfo info;
      info.run_id = job.run_id;
      info.scenario = "mixing_station";
      info.machine = "xcmg_968ev";
      info.cycles_planned = 2;
      db.BeginRun(info);
      if (job.policy == "auto") {  // gravel: Just in & out 4 s / 200 kJ; sand: Stairway #1
        db.WriteCycle(job.run_id, Cycle(0, "big_gravel", "just_in_out", "retract_bucket,lift_boom",
                                        1, 3, 50, 150, 0.98));
        db.WriteCycle(job.run_id, Cycle(1, "river_sand", "stairway",
                                        "lift_boom,retract_bucket,lift_boom", 2, 4, 60, 240, 0.96));
      } else {  // Stairway #3: 10 s / 500 kJ
        const std::string three =
            "lift_boom,retract_bucket,lift_boom,retract_bucket,lift_boom,retract_bucket,lift_boom";
        db.WriteCycle(job.run_id,
                      Cycle(0, "big_gravel", "stairway_fixed", three, 2, 8, 100, 400, 0.97));
        db.WriteCycle(job.run_id,
                      Cycle(1, "river_sand", "stairway_fixed", three, 2, 8, 100, 400, 0.97));
      }
    }
  }
  ProductionReportOptions o;
  o.database = db_file;
  std::ostringstream out, err;
  ASSERT_EQ(RunProductionReport(o, out, err), 0) << err.str();
  const std::string text = out.str();
  // Table 6: per week one Just in & out on gravel (4 s, 200 kJ) and one Stairway #1 on sand.
  EXPECT_NE(text.find("| 1 | 1 | 0 | 4.00 | 200.0 | 0 | 1 | 6.00 | 300.0 |"), std::string::npos)
      << text;
  EXPECT_NE(text.find("| all | 2 | 0 | 4.00 | 200.0 | 0 | 2 | 6.00 | 300.0 |"), std::string::npos)
      << text;
  // Table 7.
  EXPECT_NE(text.find("| big_gravel | 2 | 0 | 4.00 | 200.0 |"), std::string::npos) << text;
  EXPECT_NE(text.find("| river_sand | 0 | 2 | 6.00 | 300.0 |"), std::string::npos) << text;
  // Adaptive 5 s / 250 kJ against 10 s / 500 kJ: 50 % less of each; fill 97 % against 97 %.
  EXPECT_NE(text.find("scooping time 50.0 % less"), std::string::npos) << text;
  EXPECT_NE(text.find("energy 50.0 % less"), std::string::npos) << text;
  EXPECT_NE(text.find("fill +0.0 points"), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(dir / "production_fig22.png"));

  // Not a campaign database.
  std::ofstream(dir / "notes.sqlite") << "not sqlite";
  o.database = dir / "notes.sqlite";
  std::ostringstream out2, err2;
  EXPECT_EQ(RunProductionReport(o, out2, err2), 2);
  EXPECT_NE(err2.str().find("notes.sqlite"), std::string::npos) << err2.str();
  o.database = dir / "missing.sqlite";
  EXPECT_EQ(RunProductionReport(o, out2, err2), 2);
  fs::remove_all(dir);
}

TEST(VaryPiles, LowersPilesWithinTheFractionAndIsDeterministic) {
  const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  const plant::Scenario written =
      plant::LoadScenario(plant::ResolveScenario("mixing_station", models));
  plant::Scenario a = written, b = written, c = written;
  plant::VaryPiles(a, 7, 0.2);
  plant::VaryPiles(b, 7, 0.2);
  plant::VaryPiles(c, 8, 0.2);
  double volume_a = 0, volume_written = 0;
  for (std::size_t i = 0; i < written.piles.size(); ++i) {
    EXPECT_LE(a.piles[i].height, written.piles[i].height);
    EXPECT_GE(a.piles[i].height, 0.8 * written.piles[i].height - 1e-12);
    EXPECT_EQ(a.piles[i].height, b.piles[i].height);
    volume_a += a.piles[i].volume;
    volume_written += written.piles[i].volume;
  }
  EXPECT_LT(volume_a, volume_written);
  EXPECT_EQ(a.world.terrain.MaterialVolume(), b.world.terrain.MaterialVolume());
  EXPECT_NE(a.world.terrain.MaterialVolume(), c.world.terrain.MaterialVolume());
  EXPECT_NEAR(a.world.terrain.MaterialVolume(), volume_a, 1e-6 * volume_a);
  plant::Scenario same = written;
  plant::VaryPiles(same, 7, 0.0);
  EXPECT_EQ(same.world.terrain.MaterialVolume(), written.world.terrain.MaterialVolume());
  EXPECT_THROW(plant::VaryPiles(same, 7, 1.5), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::app
