// The results database: schema, exact round trip, NaN as NULL, duplicate refusal with nothing
// partial left, resume bookkeeping, foreign and corrupt files named in the error.
#include "runtime/results/results_db.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "tests/results/test_records.h"

namespace autoshovel::results {
namespace {

using testing::ScratchDir;
using testing::TestRecord;
using testing::TestRun;

// A query's single integer or text answer through the raw SQLite API (not through ResultsDb).
std::string Query(const std::filesystem::path& file, const std::string& sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* statement = nullptr;
  std::string answer = "<error>";
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &statement, nullptr) == SQLITE_OK) {
    answer = "<none>";
    if (sqlite3_step(statement) == SQLITE_ROW) {
      const unsigned char* text = sqlite3_column_text(statement, 0);
      answer = text == nullptr ? "NULL" : reinterpret_cast<const char*>(text);
    }
  } else {
    ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db);
  }
  sqlite3_finalize(statement);
  sqlite3_close(db);
  return answer;
}

void Exec(const std::filesystem::path& file, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK)
      << (error != nullptr ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

TEST(ResultsDb, CreatesSchemaInWalMode) {
  const auto file = ScratchDir("") / "results.sqlite";
  { ResultsDb db(file); }
  EXPECT_EQ(Query(file, "SELECT version FROM schema_version"),
            std::to_string(ResultsDb::kSchemaVersion));
  for (const char* table : {"runs", "cycles", "samples"}) {
    EXPECT_EQ(
        Query(file, std::string("SELECT count(*) FROM sqlite_master WHERE name = '") + table + "'"),
        "1")
        << table;
  }
  EXPECT_EQ(Query(file, "PRAGMA journal_mode"), "wal");
  // Reopening an existing database checks it and keeps it.
  ResultsDb again(file);
  EXPECT_TRUE(again.Runs().empty());
}

TEST(ResultsDb, CycleWithSamplesRoundTripsExactly) {
  const auto file = ScratchDir("") / "results.sqlite";
  CycleRecord record = TestRecord(3, 250);
  record.energy_kj.level = 1e-310;  // subnormal
  record.time_s.total = std::numeric_limits<double>::max();
  record.safety_violations = 2;
  record.completed = false;
  record.material = "sand \"wet\" ' <>";
  {
    ResultsDb db(file);
    EXPECT_FALSE(db.BeginRun(TestRun()));
    db.WriteCycle("run-1", record);
  }
  ResultsDb db(file);
  const std::optional<CycleRecord> read = db.Cycle("run-1", 3);
  ASSERT_TRUE(read.has_value());
  testing::ExpectSameRecord(*read, record);
  const std::vector<CycleRecord> all = db.Cycles("run-1", true);
  ASSERT_EQ(all.size(), 1u);
  testing::ExpectSameRecord(all[0], record);
  EXPECT_TRUE(db.Cycles("run-1", false)[0].samples.empty());

  const std::optional<RunInfo> run = db.FindRun("run-1");
  ASSERT_TRUE(run.has_value());
  EXPECT_EQ(run->scenario, "yard_small");
  EXPECT_EQ(run->machine, "loader_20t");
  EXPECT_EQ(run->seed, 42u);
  EXPECT_EQ(run->cycles_planned, 10);
  EXPECT_EQ(run->start_time_utc, "2025-06-01T12:00:00.000Z");
  EXPECT_EQ(run->git_describe, "v0.1.0-12-gabcdef");
}

TEST(ResultsDb, SeedKeepsAll64Bits) {
  const auto file = ScratchDir("") / "results.sqlite";
  ResultsDb db(file);
  RunInfo run = TestRun("big-seed");
  run.seed = std::numeric_limits<std::uint64_t>::max() - 5;
  run.git_describe.clear();
  run.start_time_utc.clear();
  db.BeginRun(run);
  const std::optional<RunInfo> read = db.FindRun("big-seed");
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->seed, run.seed);
  EXPECT_EQ(read->git_describe, "");
  EXPECT_FALSE(read->start_time_utc.empty());  // filled with the current time
  EXPECT_EQ(Query(file, "SELECT git_describe IS NULL FROM runs"), "1");
}

TEST(ResultsDb, NanIsStoredAsNull) {
  const auto file = ScratchDir("") / "results.sqlite";
  CycleRecord record = TestRecord(0, 3);
  record.trigger_time_s = kNotMeasured;  // never triggered
  record.energy_kj.level = kNotMeasured;
  record.samples[1].v1v2 = kNotMeasured;
  {
    ResultsDb db(file);
    db.BeginRun(TestRun());
    db.WriteCycle("run-1", record);
  }
  EXPECT_EQ(Query(file, "SELECT trigger_time_s IS NULL FROM cycles"), "1");
  EXPECT_EQ(Query(file, "SELECT energy_level_kj IS NULL FROM cycles"), "1");
  EXPECT_EQ(Query(file, "SELECT fill_rate IS NULL FROM cycles"), "0");
  EXPECT_EQ(Query(file, "SELECT count(*) FROM samples WHERE v1v2_m3 IS NULL"), "1");
  EXPECT_EQ(Query(file, "SELECT k FROM samples WHERE v1v2_m3 IS NULL"), "1");
  // SQL aggregates skip NULL, so AVG() means "mean over measured cycles".
  ResultsDb db(file);
  const std::optional<CycleRecord> read = db.Cycle("run-1", 0);
  ASSERT_TRUE(read.has_value());
  EXPECT_TRUE(std::isnan(read->trigger_time_s));
  EXPECT_TRUE(std::isnan(read->energy_kj.level));
  EXPECT_TRUE(std::isnan(read->samples[1].v1v2));
  testing::ExpectSameRecord(*read, record);
}

TEST(ResultsDb, DuplicateCycleIsRefusedAndNothingPartialRemains) {
  const auto file = ScratchDir("") / "results.sqlite";
  ResultsDb db(file);
  db.BeginRun(TestRun());
  const CycleRecord first = TestRecord(3, 5);
  db.WriteCycle("run-1", first);
  CycleRecord second = TestRecord(3, 12);
  second.fill_rate = 0.5;
  try {
    db.WriteCycle("run-1", second);
    FAIL() << "a duplicate cycle was accepted";
  } catch (const DuplicateCycleError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cycle 3"), std::string::npos) << e.what();
  }
  testing::ExpectSameRecord(*db.Cycle("run-1", 3), first);
  EXPECT_EQ(Query(file, "SELECT count(*) FROM samples"), "5");
  EXPECT_EQ(Query(file, "SELECT count(*) FROM cycles"), "1");
  // The same index in another run is fine.
  db.BeginRun(TestRun("run-2"));
  db.WriteCycle("run-2", second);
  EXPECT_EQ(Query(file, "SELECT count(*) FROM samples"), "17");
}

TEST(ResultsDb, FailedSampleRollsBackTheWholeCycle) {
  const auto file = ScratchDir("") / "results.sqlite";
  ResultsDb db(file);
  db.BeginRun(TestRun());
  CycleRecord bad = TestRecord(4, 20);
  bad.samples[7].t = kNotMeasured;  // the time axis must be known
  EXPECT_THROW(db.WriteCycle("run-1", bad), ResultsDbError);
  EXPECT_TRUE(db.CompletedCycles("run-1").empty());
  EXPECT_EQ(Query(file, "SELECT count(*) FROM samples"), "0");
  // The database is still usable, and the cycle can be written once fixed.
  bad.samples[7].t = 0.35;
  db.WriteCycle("run-1", bad);
  EXPECT_EQ(db.CompletedCycles("run-1"), std::vector<int>{4});
}

TEST(ResultsDb, RefusesCycleOfUnknownRunAndNegativeIndex) {
  const auto file = ScratchDir("") / "results.sqlite";
  ResultsDb db(file);
  EXPECT_THROW(db.WriteCycle("nobody", TestRecord(0, 1)), ResultsDbError);
  db.BeginRun(TestRun());
  EXPECT_THROW(db.WriteCycle("run-1", TestRecord(-1, 1)), ResultsDbError);
  EXPECT_EQ(Query(file, "SELECT count(*) FROM cycles"), "0");
}

TEST(ResultsDb, ResumeListsCompletedAndMissingCycles) {
  const auto file = ScratchDir("") / "results.sqlite";
  {
    ResultsDb db(file);
    EXPECT_FALSE(db.BeginRun(TestRun()));
    for (int c : {0, 1, 3, 7}) db.WriteCycle("run-1", TestRecord(c, 4));
  }
  ResultsDb db(file);
  EXPECT_TRUE(db.BeginRun(TestRun()));  // resumed
  EXPECT_EQ(db.CompletedCycles("run-1"), (std::vector<int>{0, 1, 3, 7}));
  EXPECT_EQ(db.MissingCycles("run-1", 8), (std::vector<int>{2, 4, 5, 6}));
  EXPECT_TRUE(db.CompletedCycles("other").empty());
  for (int c : db.MissingCycles("run-1", 8)) db.WriteCycle("run-1", TestRecord(c, 4));
  EXPECT_EQ(db.CompletedCycles("run-1"), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_TRUE(db.MissingCycles("run-1", 8).empty());

  RunInfo other_seed = TestRun();
  other_seed.seed = 43;
  try {
    db.BeginRun(other_seed);
    FAIL() << "resumed with another seed";
  } catch (const ResultsDbError& e) {
    EXPECT_NE(std::string(e.what()).find("seed 43"), std::string::npos) << e.what();
  }
}

TEST(ResultsDb, NonSqliteFileIsRefusedNamingIt) {
  const auto file = ScratchDir("") / "notes.sqlite";
  {
    std::ofstream out(file);
    for (int i = 0; i < 100; ++i) out << "these are field notes, not a database\n";
  }
  const auto size = std::filesystem::file_size(file);
  try {
    ResultsDb db(file);
    FAIL() << "opened a text file";
  } catch (const ResultsDbError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.string() + " is not a valid SQLite database"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(std::filesystem::file_size(file), size);  // untouched
}

TEST(ResultsDb, ForeignSqliteDatabaseIsRefusedAndLeftUntouched) {
  const auto file = ScratchDir("") / "inventory.sqlite";
  Exec(file, "CREATE TABLE parts (id INTEGER, name TEXT); INSERT INTO parts VALUES (1, 'pin');");
  try {
    ResultsDb db(file);
    FAIL() << "opened a foreign database";
  } catch (const ResultsDbError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no schema_version"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Query(file, "PRAGMA journal_mode"), "delete");  // not switched to WAL
  EXPECT_EQ(Query(file, "SELECT count(*) FROM sqlite_master"), "1");
}

TEST(ResultsDb, OtherSchemaVersionIsRefusedNamingBoth) {
  const auto file = ScratchDir("") / "results.sqlite";
  { ResultsDb db(file); }
  Exec(file, "UPDATE schema_version SET version = 99");
  try {
    ResultsDb db(file);
    FAIL() << "opened schema version 99";
  } catch (const ResultsDbError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    EXPECT_NE(what.find("version 99"), std::string::npos) << what;
    EXPECT_NE(what.find("version " + std::to_string(ResultsDb::kSchemaVersion)), std::string::npos)
        << what;
  }
}

// Schema version 2: the supervisor's counts, the declared faults and the failure round-trip.
TEST(ResultsDb, SafetyFieldsRoundTrip) {
  const auto file = ScratchDir("") / "results.sqlite";
  ResultsDb db(file);
  db.BeginRun(TestRun());
  CycleRecord failed = TestRecord(0, 3);
  failed.completed = false;
  failed.safe_stops = 2;
  failed.recoveries = 1;
  failed.refused_frames = 17;
  failed.faults = "lidar_dropout,person_enters_path";
  failed.failure = "safe stop: localisation jumped";
  db.WriteCycle("run-1", failed);
  CycleRecord fine = TestRecord(1, 3);
  fine.failure = "ignored when completed";
  db.WriteCycle("run-1", fine);
  const std::vector<CycleRecord> back = db.Cycles("run-1");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].safe_stops, 2);
  EXPECT_EQ(back[0].recoveries, 1);
  EXPECT_EQ(back[0].refused_frames, 17);
  EXPECT_EQ(back[0].faults, "lidar_dropout,person_enters_path");
  EXPECT_EQ(back[0].failure, "safe stop: localisation jumped");
  EXPECT_EQ(back[1].safe_stops, 0);
  EXPECT_EQ(back[1].faults, "");
  EXPECT_EQ(Query(file, "SELECT failure IS NULL FROM cycles WHERE cycle = 1"), "1");
}

// A version-1 file (as the last build before version 2 wrote it) is migrated in place: its rows
// keep every value and read "not recorded" for the new fields; new rows store them; the column
// order is a new file's (campaign shards merge with INSERT … SELECT *).
TEST(ResultsDb, VersionOneFileIsMigrated) {
  const auto dir = ScratchDir("");
  const auto file = dir / "v1.sqlite";
  {
    ResultsDb db(file);
    db.BeginRun(TestRun());
    db.WriteCycle("run-1", TestRecord(0, 3));
  }
  Exec(file,
       "ALTER TABLE cycles DROP COLUMN safe_stops; ALTER TABLE cycles DROP COLUMN recoveries; "
       "ALTER TABLE cycles DROP COLUMN refused_frames; ALTER TABLE cycles DROP COLUMN faults; "
       "ALTER TABLE cycles DROP COLUMN failure; UPDATE schema_version SET version = 1");
  ASSERT_EQ(Query(file, "SELECT count(*) FROM pragma_table_info('cycles')"), "26");
  const CycleRecord before = TestRecord(0, 3);
  {
    ResultsDb db(file);
    std::vector<CycleRecord> rows = db.Cycles("run-1");
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_EQ(rows[0].fill_rate, before.fill_rate);
    EXPECT_EQ(rows[0].energy_kj.total, before.energy_kj.total);
    EXPECT_EQ(rows[0].safe_stops, -1);
    EXPECT_EQ(rows[0].recoveries, -1);
    EXPECT_EQ(rows[0].refused_frames, -1);
    CycleRecord next = TestRecord(1, 3);
    next.safe_stops = 1;
    db.WriteCycle("run-1", next);
    EXPECT_EQ(db.Cycles("run-1")[1].safe_stops, 1);
  }
  EXPECT_EQ(Query(file, "SELECT version FROM schema_version"), "2");
  const auto fresh = dir / "v2.sqlite";
  { ResultsDb db(fresh); }
  EXPECT_EQ(Query(file, "SELECT group_concat(name) FROM pragma_table_info('cycles')"),
            Query(fresh, "SELECT group_concat(name) FROM pragma_table_info('cycles')"));
  { ResultsDb again(file); }  // opening a migrated file again changes nothing
  EXPECT_EQ(Query(file, "SELECT count(*) FROM cycles"), "2");
}

TEST(ResultsDb, CorruptedPagesAreReportedNamingTheFile) {
  const auto file = ScratchDir("") / "results.sqlite";
  {
    ResultsDb db(file);
    db.BeginRun(TestRun());
    for (int c = 0; c < 20; ++c) db.WriteCycle("run-1", TestRecord(c, 200));
  }  // closed: the WAL is checkpointed into the file
  {
    // Overwrite everything after the 100-byte header of page 1 with garbage.
    std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(100);
    const std::string garbage(8192, '\x5a');
    io.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  try {
    ResultsDb db(file);
    db.Cycles("run-1", true);
    FAIL() << "read a corrupt database";
  } catch (const ResultsDbError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
}

std::string Bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A database of one run with cycles 0..2, closed (the WAL checkpointed into the file).
std::filesystem::path ThreeCycles() {
  const auto file = ScratchDir("") / "results.sqlite";
  ResultsDb db(file);
  db.BeginRun(TestRun());
  for (int c = 0; c < 3; ++c) db.WriteCycle("run-1", TestRecord(c, 4));
  return file;
}

// The message of the ResultsDbError that `read` throws, or "" when it throws none.
template <typename Read>
std::string Refusal(Read read) {
  try {
    read();
  } catch (const ResultsDbError& e) {
    return e.what();
  }
  return "";
}

TEST(ResultsDb, NullIsNotMeasuredWhenReadBack) {
  const auto file = ThreeCycles();
  Exec(file, "UPDATE cycles SET fill_rate = NULL, safe_stops = NULL WHERE cycle = 1");
  const ResultsDb db(file, ResultsDb::Access::kReadOnly);
  const std::vector<CycleRecord> cycles = db.Cycles("run-1");
  ASSERT_EQ(cycles.size(), 3u);
  EXPECT_TRUE(std::isnan(cycles[1].fill_rate));
  EXPECT_EQ(cycles[1].safe_stops, -1);
  EXPECT_EQ(cycles[0].fill_rate, TestRecord(0, 4).fill_rate);
}

TEST(ResultsDb, TextInARealColumnIsRefusedNamingFileTableRowAndColumn) {
  const auto file = ThreeCycles();
  Exec(file, "UPDATE cycles SET time_scoop_s = 'n/a' WHERE cycle = 2");
  const std::string rowid = Query(file, "SELECT rowid FROM cycles WHERE cycle = 2");
  for (const ResultsDb::Access access :
       {ResultsDb::Access::kReadOnly, ResultsDb::Access::kReadWrite}) {
    const ResultsDb db(file, access);
    EXPECT_EQ(Refusal([&] { db.Cycles("run-1"); }),
              file.string() + ": table cycles, rowid " + rowid +
                  " (run 'run-1', cycle 2), column time_scoop_s: text 'n/a' where a number "
                  "belongs");
  }
}

TEST(ResultsDb, TextOrFractionInAnIntegerColumnIsRefused) {
  const auto file = ThreeCycles();
  Exec(file, "UPDATE cycles SET safety_violations = 'none' WHERE cycle = 0");
  const ResultsDb db(file, ResultsDb::Access::kReadOnly);
  EXPECT_NE(Refusal([&] { db.Cycles("run-1"); })
                .find("(run 'run-1', cycle 0), column safety_violations: text 'none' where a whole "
                      "number belongs"),
            std::string::npos);
  Exec(file, "UPDATE cycles SET safety_violations = 0 WHERE cycle = 0");
  Exec(file, "UPDATE cycles SET safe_stops = 1.5 WHERE cycle = 1");
  EXPECT_NE(
      Refusal([&] { db.Cycles("run-1"); })
          .find("(run 'run-1', cycle 1), column safe_stops: the number 1.5 where a whole number "
                "belongs"),
      std::string::npos);
}

TEST(ResultsDb, InfinityIsRefusedExceptAnUnboundedSafetyMargin) {
  const auto file = ThreeCycles();
  // +inf clearance: nothing came within reach; the writer stores it and the reader keeps it.
  Exec(file, "UPDATE cycles SET safety_margin_m = 9e999 WHERE cycle = 0");
  {
    const ResultsDb db(file, ResultsDb::Access::kReadOnly);
    EXPECT_EQ(db.Cycles("run-1")[0].safety_margin_m, std::numeric_limits<double>::infinity());
  }
  Exec(file, "UPDATE cycles SET energy_total_kj = -9e999 WHERE cycle = 1");
  const ResultsDb db(file, ResultsDb::Access::kReadOnly);
  EXPECT_NE(Refusal([&] { db.Cycles("run-1"); })
                .find("(run 'run-1', cycle 1), column energy_total_kj: -inf where a finite "
                      "number belongs"),
            std::string::npos);
  Exec(file, "UPDATE cycles SET energy_total_kj = 1 WHERE cycle = 1");
  Exec(file, "UPDATE samples SET v1_m3 = 9e999 WHERE cycle = 2 AND k = 3");
  EXPECT_EQ(Refusal([&] { db.Samples("run-1", 2); }),
            file.string() +
                ": table samples, run 'run-1', cycle 2, k 3, column v1_m3: +inf where a finite "
                "number belongs");
}

TEST(ResultsDb, ReadOnlyOpenChangesNothingAndRunsTheIntegrityCheck) {
  const auto file = ThreeCycles();
  const std::string before = Bytes(file);
  const auto mtime = std::filesystem::last_write_time(file);
  {
    const ResultsDb db(file, ResultsDb::Access::kReadOnly);
    EXPECT_EQ(db.Cycles("run-1", true).size(), 3u);
    EXPECT_EQ(db.Runs().size(), 1u);
    EXPECT_NO_THROW(db.CheckIntegrity());
  }
  EXPECT_EQ(Bytes(file), before);
  EXPECT_EQ(std::filesystem::last_write_time(file), mtime);
}

TEST(ResultsDb, ReadOnlyOpenRefusesMissingTextAndDamagedFiles) {
  const auto dir = ScratchDir("");
  EXPECT_EQ(Refusal([&] { ResultsDb(dir / "none.sqlite", ResultsDb::Access::kReadOnly); }),
            (dir / "none.sqlite").string() + ": no such file");
  EXPECT_FALSE(std::filesystem::exists(dir / "none.sqlite"));  // not created
  const auto text = dir / "text.sqlite";
  std::ofstream(text) << "run,cycle,fill_rate\nrun-1,0,0.98\n";
  EXPECT_EQ(Refusal([&] { ResultsDb(text, ResultsDb::Access::kReadOnly); }),
            text.string() + " is not a valid SQLite database: file is not a database");
}

TEST(ResultsDb, DamagedIndexPageFailsTheIntegrityCheckBeforeAnyRead) {
  const auto file = ScratchDir("") / "results.sqlite";
  {
    ResultsDb db(file);
    db.BeginRun(TestRun());
    for (int c = 0; c < 10; ++c) db.WriteCycle("run-1", TestRecord(c, 300));
  }
  // The unique (run_id, cycle) index of `cycles`: the readers never walk it for Cycles(), so
  // only the integrity check sees the damage.
  const long long root =
      std::stoll(Query(file,
                       "SELECT rootpage FROM sqlite_master WHERE type = 'index' AND "
                       "tbl_name = 'cycles'"));
  const long long page = std::stoll(Query(file, "PRAGMA page_size"));
  {
    std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp((root - 1) * page);
    const std::string garbage(32, '\x5a');
    io.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  const std::string before = Bytes(file);
  const std::string what =
      Refusal([&] { ResultsDb(file, ResultsDb::Access::kReadOnly).Cycles("run-1"); });
  EXPECT_EQ(what.rfind(file.string() + " is not a valid SQLite database: ", 0), 0u) << what;
  EXPECT_EQ(Bytes(file), before);
}

// The predictor's travel at the trigger (issue 41, item 5): stored exactly, NaN as NULL and
// read back as NaN (never 0), in the last column of crowding_samples.
CycleRecord WithCrowding(int c, double penetration, double predicted) {
  CycleRecord r = TestRecord(c, 2);
  CrowdingSample& s = r.crowding;
  s.present = true;
  s.strategy = "just_in_out";
  s.trigger = "predicted_volume";
  s.material = "big_gravel";
  s.speed = 1.5;
  s.v1 = 0.75 + c;
  s.heights = {0.5, 0.7, 0.9, 1.1, 1.3, 1.5};
  s.penetration = penetration;
  s.predicted_penetration = predicted;
  return r;
}

TEST(ResultsDb, PredictedPenetrationRoundTripsAndNanIsNull) {
  const auto file = ScratchDir("") / "results.sqlite";
  {
    ResultsDb db(file);
    db.BeginRun(TestRun());
    db.WriteCycle("run-1", WithCrowding(0, 0.93, 1.0 / 3.0));
    db.WriteCycle("run-1", WithCrowding(1, 0.71, kNotMeasured));  // the prediction failed
    db.WriteCycle("run-1", TestRecord(2, 0));                     // no crowding sample
  }
  EXPECT_EQ(Query(file, "SELECT group_concat(name) FROM pragma_table_info('crowding_samples')"),
            "run_id,cycle,strategy,trigger_cause,material,speed_mps,v1_m3,h1_m,h2_m,h3_m,h4_m,"
            "h5_m,h6_m,penetration_m,predicted_penetration_m");
  EXPECT_EQ(Query(file,
                  "SELECT predicted_penetration_m IS NULL FROM crowding_samples WHERE "
                  "cycle = 1"),
            "1");
  EXPECT_EQ(Query(file,
                  "SELECT typeof(predicted_penetration_m) FROM crowding_samples WHERE "
                  "cycle = 0"),
            "real");
  for (const ResultsDb::Access access :
       {ResultsDb::Access::kReadWrite, ResultsDb::Access::kReadOnly}) {
    const ResultsDb db(file, access);
    const auto samples = db.CrowdingSamples();
    ASSERT_EQ(samples.size(), 2u);
    EXPECT_EQ(samples[0].cycle, 0);
    EXPECT_EQ(samples[0].sample.predicted_penetration, 1.0 / 3.0);  // bit for bit
    EXPECT_EQ(samples[0].sample.penetration, 0.93);
    EXPECT_EQ(samples[1].cycle, 1);
    EXPECT_TRUE(std::isnan(samples[1].sample.predicted_penetration))
        << samples[1].sample.predicted_penetration;
    EXPECT_EQ(samples[1].sample.penetration, 0.71);
  }
  // Text where the travel belongs is refused naming the column, not read as 0.
  Exec(file, "UPDATE crowding_samples SET predicted_penetration_m = 'n/a' WHERE cycle = 0");
  const ResultsDb db(file, ResultsDb::Access::kReadOnly);
  EXPECT_NE(Refusal([&] { db.CrowdingSamples(); })
                .find("table crowding_samples, run 'run-1', cycle 0, column "
                      "predicted_penetration_m: text 'n/a' where a number belongs"),
            std::string::npos)
      << Refusal([&] { db.CrowdingSamples(); });
}

// crowding_samples as builds before issue 41 item 5 created it, with one row.
constexpr const char* kOldCrowdingSamples = R"sql(
DROP TABLE crowding_samples;
CREATE TABLE crowding_samples (
  run_id         TEXT NOT NULL,
  cycle          INTEGER NOT NULL,
  strategy       TEXT NOT NULL,
  trigger_cause  TEXT NOT NULL,
  material       TEXT NOT NULL,
  speed_mps      REAL,
  v1_m3          REAL,
  h1_m REAL, h2_m REAL, h3_m REAL, h4_m REAL, h5_m REAL, h6_m REAL,
  penetration_m  REAL,
  PRIMARY KEY (run_id, cycle)
) WITHOUT ROWID;
INSERT INTO crowding_samples VALUES
  ('run-1', 0, 'just_in_out', 'predicted_volume', 'big_gravel', 1.25, 0.8,
   0.5, 0.7, 0.9, 1.1, 1.3, 1.5, 0.93);
)sql";

// An older file: read-only it reads as it is, every predicted travel not logged, and is left
// untouched; opened by a writer it gains the column (its row keeps its values and reads NaN),
// with the column order of a new file (campaign shards merge with INSERT … SELECT *).
TEST(ResultsDb, OldCrowdingSamplesTableGainsThePredictedColumn) {
  const auto dir = ScratchDir("");
  const auto file = dir / "old.sqlite";
  {
    ResultsDb db(file);
    db.BeginRun(TestRun());
    db.WriteCycle("run-1", TestRecord(0, 2));
  }
  Exec(file, kOldCrowdingSamples);
  ASSERT_EQ(Query(file, "SELECT count(*) FROM pragma_table_info('crowding_samples')"), "14");
  auto check_old_row = [](const ResultsDb& db) {
    const auto samples = db.CrowdingSamples();
    ASSERT_EQ(samples.size(), 1u);
    EXPECT_EQ(samples[0].run_id, "run-1");
    EXPECT_EQ(samples[0].cycle, 0);
    EXPECT_EQ(samples[0].sample.material, "big_gravel");
    EXPECT_EQ(samples[0].sample.speed, 1.25);
    EXPECT_EQ(samples[0].sample.heights[5], 1.5);
    EXPECT_EQ(samples[0].sample.penetration, 0.93);
    EXPECT_TRUE(std::isnan(samples[0].sample.predicted_penetration))
        << samples[0].sample.predicted_penetration;
  };
  const std::string before = Bytes(file);
  {
    const ResultsDb db(file, ResultsDb::Access::kReadOnly);
    check_old_row(db);
  }
  EXPECT_EQ(Bytes(file), before);  // a reader changes nothing
  EXPECT_EQ(Query(file, "SELECT count(*) FROM pragma_table_info('crowding_samples')"), "14");
  {
    ResultsDb db(file);
    check_old_row(db);
    db.WriteCycle("run-1", WithCrowding(1, 0.71, 0.625));
    const auto samples = db.CrowdingSamples();
    ASSERT_EQ(samples.size(), 2u);
    EXPECT_EQ(samples[1].sample.predicted_penetration, 0.625);
  }
  EXPECT_EQ(Query(file,
                  "SELECT predicted_penetration_m IS NULL FROM crowding_samples WHERE "
                  "cycle = 0"),
            "1");
  EXPECT_EQ(Query(file, "SELECT version FROM schema_version"), "2");  // nothing else changed
  EXPECT_EQ(Query(file, "SELECT count(*) FROM cycles"), "2");
  const auto fresh = dir / "new.sqlite";
  { ResultsDb db(fresh); }
  EXPECT_EQ(Query(file, "SELECT group_concat(name) FROM pragma_table_info('crowding_samples')"),
            Query(fresh, "SELECT group_concat(name) FROM pragma_table_info('crowding_samples')"));
  { ResultsDb again(file); }  // opening an upgraded file again changes nothing
  EXPECT_EQ(Query(file, "SELECT count(*) FROM pragma_table_info('crowding_samples')"), "15");
  EXPECT_EQ(Query(file, "SELECT count(*) FROM crowding_samples"), "2");
}

TEST(ColumnReader, NamesTheFileTableRowAndColumn) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(":memory:", &db), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db,
                               "SELECT NULL AS a, 2 AS b, 2.5 AS c, x'00ff' AS d, '7' AS e, "
                               "9e999 AS f",
                               -1, &s, nullptr),
            SQLITE_OK);
  ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
  ColumnReader read(s, "x.sqlite", "t");
  read.SetRow("rowid 4");
  EXPECT_FALSE(read.Real(0).has_value());
  EXPECT_FALSE(read.Integer(0).has_value());
  EXPECT_EQ(read.Text(0), "");
  EXPECT_EQ(read.Real(1), 2.0);
  EXPECT_EQ(read.Integer(1), 2);
  EXPECT_EQ(read.Real(2), 2.5);
  EXPECT_EQ(Refusal([&] { read.Integer(2); }),
            "x.sqlite: table t, rowid 4, column c: the number 2.5 where a whole number belongs");
  EXPECT_EQ(Refusal([&] { read.Real(3); }),
            "x.sqlite: table t, rowid 4, column d: a blob of 2 bytes where a number belongs");
  EXPECT_EQ(Refusal([&] { read.Real(4); }),
            "x.sqlite: table t, rowid 4, column e: text '7' where a number belongs");
  EXPECT_EQ(read.Real(5, ColumnReader::Infinity::kPlusAllowed),
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(Refusal([&] { read.Real(5); }),
            "x.sqlite: table t, rowid 4, column f: +inf where a finite number belongs");
  EXPECT_EQ(Refusal([&] { read.RequiredInteger(0); }),
            "x.sqlite: table t, rowid 4, column a: NULL where a whole number is required");
  sqlite3_finalize(s);
  sqlite3_close(db);
}

}  // namespace
}  // namespace autoshovel::results
