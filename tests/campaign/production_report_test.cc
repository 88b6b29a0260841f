// The production report (Tables 6–7, the adaptive-vs-Stairway-#3 comparison, Fig. 22) on a
// campaign database with known rows; Tukey's box statistics by hand; a restocked yard.
#include "runtime/app/campaign/production_report.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
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

// A campaign database of one week, one shift and the two policies: 4 cycles each, written by
// `write` (policy "auto" or "stairway_fixed", cycle index).
fs::path SmallCampaign(const fs::path& dir,
                       const std::function<results::CycleRecord(const std::string&, int)>& write) {
  CampaignSpec spec;
  spec.name = "t";
  spec.weeks = 1;
  spec.shifts_per_week = 1;
  spec.cycles_per_shift = 4;
  spec.policies = {"auto", "stairway_fixed"};
  const std::vector<CampaignJob> jobs = CampaignJobs(spec);
  const fs::path file = dir / "results.sqlite";
  PrepareCampaignDatabase(file, spec, jobs);
  results::ResultsDb db(file);
  for (const CampaignJob& job : jobs) {
    results::RunInfo info;
    info.run_id = job.run_id;
    info.scenario = "mixing_station";
    info.machine = "xcmg_968ev";
    info.cycles_planned = 4;
    db.BeginRun(info);
    for (int c = 0; c < 4; ++c) db.WriteCycle(job.run_id, write(job.policy, c));
  }
  return file;
}

// Fill 0.96 + 0.01 c, Just in & out, crowd 1 s + scoop (3 + c) s, 50 + 150 kJ.
results::CycleRecord Plain(const std::string& policy, int c) {
  return Cycle(c, "big_gravel", policy == "auto" ? "just_in_out" : "stairway_fixed",
               "retract_bucket,lift_boom", 1, 3 + c, 50, 150, 0.96 + 0.01 * c);
}

void Exec(const fs::path& file, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK)
      << (error != nullptr ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

std::string Bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Outcome {
  int code;
  std::string out, err;
};
Outcome Report(const fs::path& database) {
  ProductionReportOptions o;
  o.database = database;
  o.png = database.parent_path() / "fig22.png";
  std::ostringstream out, err;
  const int code = RunProductionReport(o, out, err);
  return {code, out.str(), err.str()};
}

TEST(ProductionReport, NullFillRatesAreNotMeasuredLeftOutOfTheMeanAndCounted) {
  const fs::path dir = TempDir();
  // Adaptive: cycles 1 and 3 did not measure their fill (NULL); 0 and 2 measured 0.96 and 0.98.
  const fs::path file = SmallCampaign(dir, [](const std::string& policy, int c) {
    results::CycleRecord r = Plain(policy, c);
    if (policy == "auto" && c % 2 == 1) r.fill_rate = results::kNotMeasured;
    return r;
  });
  const Outcome o = Report(file);
  ASSERT_EQ(o.code, 0) << o.err;
  // Mean of the measured rows (0.96 + 0.98) / 2 = 97.0 %; reading NULL as 0 gives 48.5 %.
  EXPECT_NE(o.out.find("| auto | 4 | 100.0 % | 97.0 % |"), std::string::npos) << o.out;
  // The baseline measured all four: (0.96 + 0.97 + 0.98 + 0.99) / 4 = 97.5 %.
  EXPECT_NE(o.out.find("| stairway_fixed | 4 | 100.0 % | 97.5 % |"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("auto: fill_rate: 2 of 4 completed cycles not measured, left out of the "
                       "mean"),
            std::string::npos)
      << o.out;
  EXPECT_EQ(o.out.find("stairway_fixed: fill_rate"), std::string::npos) << o.out;
  fs::remove_all(dir);
}

TEST(ProductionReport, TextInARealColumnIsRefusedNamingTheRowAndColumn) {
  const fs::path dir = TempDir();
  const fs::path file = SmallCampaign(dir, Plain);
  // A hand edit: the unit typed into the cell. SQLite keeps it as text (REAL affinity converts
  // only well-formed numbers), and sqlite3_column_double would read it as 0.
  Exec(file, "UPDATE cycles SET time_scoop_s = '16.65 s' WHERE run_id LIKE '%auto%' AND cycle = 2");
  const std::string rowid = [&] {
    sqlite3* db = nullptr;
    sqlite3_open(file.c_str(), &db);
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db, "SELECT rowid FROM cycles WHERE typeof(time_scoop_s) = 'text'", -1, &s,
                       nullptr);
    std::string id = sqlite3_step(s) == SQLITE_ROW ? std::to_string(sqlite3_column_int64(s, 0))
                                                   : std::string("?");
    sqlite3_finalize(s);
    sqlite3_close(db);
    return id;
  }();
  const std::string before = Bytes(file);
  const Outcome o = Report(file);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_EQ(o.out, "");  // no table computed from the damaged row
  EXPECT_NE(o.err.find(file.string() + ": table cycles, rowid " + rowid + " (run '"),
            std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("cycle 2), column time_scoop_s: text '16.65 s' where a number belongs"),
            std::string::npos)
      << o.err;
  EXPECT_EQ(Bytes(file), before);  // read-only: nothing changed
  fs::remove_all(dir);
}

TEST(ProductionReport, InfinityIsRefusedNotDropped) {
  const fs::path dir = TempDir();
  const fs::path file = SmallCampaign(dir, Plain);
  Exec(file, "UPDATE cycles SET fill_rate = 9e999 WHERE run_id LIKE '%auto%' AND cycle = 1");
  const Outcome o = Report(file);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.err.find("cycle 1), column fill_rate: +inf where a finite number belongs"),
            std::string::npos)
      << o.err;
  Exec(file, "UPDATE cycles SET fill_rate = 0.97 WHERE fill_rate > 1e308");
  ASSERT_EQ(Report(file).code, 0);
  Exec(file,
       "UPDATE cycles SET energy_crowd_kj = -9e999 WHERE run_id LIKE '%fixed%' AND cycle = 3");
  const Outcome second = Report(file);
  EXPECT_EQ(second.code, 2) << second.out;
  EXPECT_NE(second.err.find("cycle 3), column energy_crowd_kj: -inf where a finite number belongs"),
            std::string::npos)
      << second.err;
  fs::remove_all(dir);
}

TEST(ProductionReport, DatabaseFailingTheIntegrityCheckIsRefused) {
  const fs::path dir = TempDir();
  // Enough samples that the `samples` table, which the report does not read, spans pages.
  const fs::path file = SmallCampaign(dir, [](const std::string& policy, int c) {
    results::CycleRecord r = Plain(policy, c);
    for (int k = 0; k < 200; ++k) {
      results::CycleSample s;
      s.t = 0.05 * k;
      s.v1 = 0.01 * k;
      r.samples.push_back(s);
    }
    return r;
  });
  ASSERT_EQ(Report(file).code, 0);
  ASSERT_FALSE(fs::exists(file.string() + "-wal") && fs::file_size(file.string() + "-wal") > 0);
  // Overwrite the b-tree header of the root page of `samples` in the file.
  long long root = 0, page_size = 0;
  {
    sqlite3* db = nullptr;
    sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db, "SELECT rootpage FROM sqlite_master WHERE name = 'samples'", -1, &s,
                       nullptr);
    if (sqlite3_step(s) == SQLITE_ROW) root = sqlite3_column_int64(s, 0);
    sqlite3_finalize(s);
    sqlite3_prepare_v2(db, "PRAGMA page_size", -1, &s, nullptr);
    if (sqlite3_step(s) == SQLITE_ROW) page_size = sqlite3_column_int64(s, 0);
    sqlite3_finalize(s);
    sqlite3_close(db);
  }
  ASSERT_GT(root, 1);
  ASSERT_GT(page_size, 0);
  {
    std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp((root - 1) * page_size);
    const std::string garbage(64, '\x5a');
    io.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  const std::string before = Bytes(file);
  const Outcome o = Report(file);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_EQ(o.out, "");
  EXPECT_EQ(o.err.rfind("autoshovel report production: " + file.string() +
                            " is not a valid SQLite database: ",
                        0),
            0u)
      << o.err;
  EXPECT_EQ(o.err.find("holds no campaign cycles"), std::string::npos) << o.err;
  EXPECT_EQ(Bytes(file), before);
  fs::remove_all(dir);
}

TEST(ProductionReport, TextFileNamedSqliteIsRefused) {
  const fs::path dir = TempDir();
  const fs::path file = dir / "results.sqlite";
  {
    std::ofstream out(file);
    for (int i = 0; i < 50; ++i) out << "week,policy,fill_rate\n1,auto,0.98\n";
  }
  const std::string before = Bytes(file);
  const Outcome o = Report(file);
  EXPECT_EQ(o.code, 2);
  EXPECT_EQ(o.err, "autoshovel report production: " + file.string() +
                       " is not a valid SQLite database: file is not a database\n");
  EXPECT_EQ(Bytes(file), before);
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
