#include "runtime/results/results_db.h"

#include <sqlite3.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>

#include "runtime/results/run_folder.h"

namespace autoshovel::results {

namespace {

// Column order of `cycles` after (run_id, cycle); shared by the INSERT and the SELECT.
constexpr const char* kCycleColumns =
    "scenario, machine, bin, material, strategy, atomic_actions, trigger_time_s, fill_rate, "
    "payload_m3, "
    "time_approach_s, time_crowd_s, time_scoop_s, time_level_s, time_retreat_s, time_total_s, "
    "energy_approach_kj, energy_crowd_kj, energy_scoop_kj, energy_level_kj, energy_retreat_kj, "
    "energy_total_kj, safety_margin_m, safety_violations, completed, safe_stops, recoveries, "
    "refused_frames, faults, failure";

constexpr const char* kSampleColumns =
    "t_s, v1_m3, v1v2_m3, triggered, predicted_tip_x_m, predicted_tip_z_m, actual_tip_x_m, "
    "actual_tip_z_m";

constexpr const char* kSchema = R"sql(
CREATE TABLE schema_version (
  version INTEGER NOT NULL
);
CREATE TABLE runs (
  run_id          TEXT PRIMARY KEY NOT NULL,
  scenario        TEXT NOT NULL,
  machine         TEXT NOT NULL,
  seed            INTEGER NOT NULL,
  cycles_planned  INTEGER NOT NULL,
  start_time_utc  TEXT NOT NULL,
  git_describe    TEXT
);
CREATE TABLE cycles (
  run_id              TEXT NOT NULL REFERENCES runs(run_id),
  cycle               INTEGER NOT NULL CHECK (cycle >= 0),
  scenario            TEXT NOT NULL,
  machine             TEXT NOT NULL,
  bin                 TEXT NOT NULL,
  material            TEXT NOT NULL,
  strategy            TEXT NOT NULL,
  atomic_actions      TEXT NOT NULL,
  trigger_time_s      REAL,
  fill_rate           REAL,
  payload_m3          REAL,
  time_approach_s     REAL,
  time_crowd_s        REAL,
  time_scoop_s        REAL,
  time_level_s        REAL,
  time_retreat_s      REAL,
  time_total_s        REAL,
  energy_approach_kj  REAL,
  energy_crowd_kj     REAL,
  energy_scoop_kj     REAL,
  energy_level_kj     REAL,
  energy_retreat_kj   REAL,
  energy_total_kj     REAL,
  safety_margin_m     REAL,
  safety_violations   INTEGER NOT NULL,
  completed           INTEGER NOT NULL CHECK (completed IN (0, 1)),
  safe_stops          INTEGER,
  recoveries          INTEGER,
  refused_frames      INTEGER,
  faults              TEXT,
  failure             TEXT,
  UNIQUE (run_id, cycle)
);
CREATE TABLE samples (
  run_id             TEXT NOT NULL,
  cycle              INTEGER NOT NULL,
  k                  INTEGER NOT NULL,
  t_s                REAL NOT NULL,
  v1_m3              REAL,
  v1v2_m3            REAL,
  triggered          INTEGER NOT NULL CHECK (triggered IN (0, 1)),
  predicted_tip_x_m  REAL,
  predicted_tip_z_m  REAL,
  actual_tip_x_m     REAL,
  actual_tip_z_m     REAL,
  PRIMARY KEY (run_id, cycle, k),
  FOREIGN KEY (run_id, cycle) REFERENCES cycles(run_id, cycle)
) WITHOUT ROWID;
)sql";

// Version 1 → 2: the safety supervisor's counts, the faults a cycle was declared to meet and
// why it did not complete (issue 9). Columns are appended, so that a migrated file and a new one
// have the same column order (the campaign merges shards with INSERT … SELECT *); rows written
// before the migration hold NULL there ("not recorded").
constexpr const char* kMigrateV1ToV2 = R"sql(
ALTER TABLE cycles ADD COLUMN safe_stops INTEGER;
ALTER TABLE cycles ADD COLUMN recoveries INTEGER;
ALTER TABLE cycles ADD COLUMN refused_frames INTEGER;
ALTER TABLE cycles ADD COLUMN faults TEXT;
ALTER TABLE cycles ADD COLUMN failure TEXT;
UPDATE schema_version SET version = 2;
)sql";

// Added after schema version 1 without changing it: created where missing when a database is
// opened (an older file gains an empty table; nothing else changes).
constexpr const char* kCrowdingSamplesSchema = R"sql(
CREATE TABLE IF NOT EXISTS crowding_samples (
  run_id         TEXT NOT NULL,
  cycle          INTEGER NOT NULL,
  strategy       TEXT NOT NULL,
  trigger_cause  TEXT NOT NULL,
  material       TEXT NOT NULL,
  speed_mps      REAL,
  v1_m3          REAL,
  h1_m REAL, h2_m REAL, h3_m REAL, h4_m REAL, h5_m REAL, h6_m REAL,
  penetration_m  REAL,
  predicted_penetration_m  REAL,
  PRIMARY KEY (run_id, cycle)
) WITHOUT ROWID;
)sql";

// The predictor's travel at the trigger (issue 41, item 5), added to crowding_samples after the
// table, again without a schema version: a writer appends the column where it is missing (the
// last, as in a new file, so that shards still merge with INSERT … SELECT *; older rows hold NULL,
// "not logged"); a read-only reader of such a file reads every row as not logged.
constexpr const char* kAddPredictedPenetration =
    "ALTER TABLE crowding_samples ADD COLUMN predicted_penetration_m REAL";

constexpr const char* kCrowdingColumns =
    "run_id, cycle, strategy, trigger_cause, material, speed_mps, v1_m3, h1_m, h2_m, h3_m, h4_m, "
    "h5_m, h6_m, penetration_m";

// A short, printable excerpt of a refused text value.
std::string Excerpt(const unsigned char* text, int bytes) {
  std::string out;
  for (int i = 0; i < bytes && out.size() < 40; ++i) {
    const char c = static_cast<char>(text[i]);
    out += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  return bytes > 40 ? out + "..." : out;
}

std::string NotValid(const std::filesystem::path& file, const std::string& why) {
  return file.string() + " is not a valid SQLite database: " + why;
}

}  // namespace

void SqliteCloser::operator()(sqlite3* db) const { sqlite3_close(db); }

void CheckIntegrity(sqlite3* db, const std::filesystem::path& file, IntegrityCheck how) {
  // At most 3 problems: the first names the damage; the rest are usually its consequences.
  const char* sql =
      how == IntegrityCheck::kQuick ? "PRAGMA quick_check(3)" : "PRAGMA integrity_check(3)";
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &statement, nullptr) != SQLITE_OK) {
    const std::string why = sqlite3_errmsg(db);
    sqlite3_finalize(statement);
    throw ResultsDbError(NotValid(file, why));
  }
  // The check answers "ok", or up to 10 lines naming the damage.
  std::string problems;
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(statement)) == SQLITE_ROW) {
    const unsigned char* line = sqlite3_column_text(statement, 0);
    std::string text = line != nullptr ? reinterpret_cast<const char*>(line) : "";
    if (text == "ok") continue;
    // One line for the error: the answer may hold several, and a header naming the schema.
    const std::string header = "*** in database main ***";
    if (text.rfind(header, 0) == 0) text.erase(0, header.size());
    for (std::size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at)) {
      text.replace(at, 1, "; ");
    }
    while (!text.empty() && (text.front() == ';' || text.front() == ' ')) text.erase(0, 1);
    problems += (problems.empty() ? "" : "; ") + text;
  }
  const std::string error = rc == SQLITE_DONE ? "" : sqlite3_errmsg(db);
  sqlite3_finalize(statement);
  if (!error.empty()) throw ResultsDbError(NotValid(file, error));
  if (!problems.empty()) {
    throw ResultsDbError(
        NotValid(file, std::string(how == IntegrityCheck::kQuick ? "PRAGMA quick_check: "
                                                                 : "PRAGMA integrity_check: ") +
                           problems));
  }
}

SqliteConnection OpenCheckedReadOnly(const std::filesystem::path& file) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(file, error);
  if (!std::filesystem::exists(status)) throw ResultsDbError(file.string() + ": no such file");
  if (!std::filesystem::is_regular_file(status)) {
    throw ResultsDbError(file.string() + ": not a regular file (a results database is one file)");
  }
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(file.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
  SqliteConnection db(raw);
  if (rc != SQLITE_OK) {
    throw ResultsDbError(file.string() + ": cannot open: " +
                         (raw != nullptr ? sqlite3_errmsg(raw) : sqlite3_errstr(rc)));
  }
  sqlite3_extended_result_codes(raw, 1);
  sqlite3_busy_timeout(raw, 10000);  // a campaign may be writing it
  CheckIntegrity(raw, file, IntegrityCheck::kFull);
  return db;
}

ColumnReader::ColumnReader(sqlite3_stmt* statement, std::filesystem::path file, std::string table)
    : statement_(statement), file_(std::move(file)), table_(std::move(table)) {}

void ColumnReader::Refuse(int column, const std::string& why) const {
  const char* name = sqlite3_column_name(statement_, column);
  throw ResultsDbError(file_.string() + ": table " + table_ + ", " +
                       (row_.empty() ? std::string("a row") : row_) + ", column " +
                       (name != nullptr ? name : std::to_string(column)) + ": " + why);
}

std::optional<double> ColumnReader::Real(int column, Infinity infinity) const {
  switch (sqlite3_column_type(statement_, column)) {
    case SQLITE_NULL:
      return std::nullopt;
    case SQLITE_INTEGER:
      return static_cast<double>(sqlite3_column_int64(statement_, column));
    case SQLITE_FLOAT: {
      const double value = sqlite3_column_double(statement_, column);
      if (std::isnan(value)) Refuse(column, "NaN where a number belongs (NULL means not measured)");
      if (std::isinf(value) && !(value > 0 && infinity == Infinity::kPlusAllowed)) {
        Refuse(column, std::string(value > 0 ? "+inf" : "-inf") + " where a finite number belongs");
      }
      return value;
    }
    case SQLITE_TEXT:
      Refuse(column, "text '" +
                         Excerpt(sqlite3_column_text(statement_, column),
                                 sqlite3_column_bytes(statement_, column)) +
                         "' where a number belongs");
    default:
      Refuse(column, "a blob of " + std::to_string(sqlite3_column_bytes(statement_, column)) +
                         " bytes where a number belongs");
  }
}

double ColumnReader::RealOrNotMeasured(int column, Infinity infinity) const {
  return Real(column, infinity).value_or(kNotMeasured);
}

std::optional<std::int64_t> ColumnReader::Integer(int column) const {
  switch (sqlite3_column_type(statement_, column)) {
    case SQLITE_NULL:
      return std::nullopt;
    case SQLITE_INTEGER:
      return sqlite3_column_int64(statement_, column);
    case SQLITE_FLOAT: {
      // INTEGER affinity stores 3.0 as 3: a REAL here is not a whole number (or out of range).
      char text[40];
      std::snprintf(text, sizeof text, "%.17g", sqlite3_column_double(statement_, column));
      Refuse(column, std::string("the number ") + text + " where a whole number belongs");
    }
    case SQLITE_TEXT:
      Refuse(column, "text '" +
                         Excerpt(sqlite3_column_text(statement_, column),
                                 sqlite3_column_bytes(statement_, column)) +
                         "' where a whole number belongs");
    default:
      Refuse(column, "a blob of " + std::to_string(sqlite3_column_bytes(statement_, column)) +
                         " bytes where a whole number belongs");
  }
}

std::int64_t ColumnReader::RequiredInteger(int column) const {
  const std::optional<std::int64_t> value = Integer(column);
  if (!value) Refuse(column, "NULL where a whole number is required");
  return *value;
}

bool ColumnReader::RequiredBool(int column) const {
  const std::int64_t value = RequiredInteger(column);
  if (value != 0 && value != 1) Refuse(column, std::to_string(value) + " where 0 or 1 belongs");
  return value == 1;
}

std::optional<int> ColumnReader::SmallInteger(int column) const {
  const std::optional<std::int64_t> value = Integer(column);
  if (!value) return std::nullopt;
  if (*value < std::numeric_limits<int>::min() || *value > std::numeric_limits<int>::max()) {
    Refuse(column, std::to_string(*value) + " is out of range");
  }
  return static_cast<int>(*value);
}

std::string ColumnReader::Text(int column) const {
  const int type = sqlite3_column_type(statement_, column);
  if (type == SQLITE_NULL) return {};
  if (type == SQLITE_BLOB) {
    Refuse(column, "a blob of " + std::to_string(sqlite3_column_bytes(statement_, column)) +
                       " bytes where text belongs");
  }
  const unsigned char* text = sqlite3_column_text(statement_, column);
  return text == nullptr
             ? std::string()
             : std::string(reinterpret_cast<const char*>(text),
                           static_cast<std::size_t>(sqlite3_column_bytes(statement_, column)));
}

namespace {

// The numeric columns of `cycles`, and the one that may hold +inf.
constexpr const char* kCycleRealColumns[] = {
    "trigger_time_s",  "fill_rate",          "payload_m3",      "time_approach_s",
    "time_crowd_s",    "time_scoop_s",       "time_level_s",    "time_retreat_s",
    "time_total_s",    "energy_approach_kj", "energy_crowd_kj", "energy_scoop_kj",
    "energy_level_kj", "energy_retreat_kj",  "energy_total_kj", "safety_margin_m"};
constexpr const char* kCycleIntegerColumns[] = {"safety_violations", "completed", "safe_stops",
                                                "recoveries", "refused_frames"};

}  // namespace

void CheckCycleValues(sqlite3* db, const std::filesystem::path& file) {
  std::string sql = "SELECT rowid, run_id, cycle";
  for (const char* c : kCycleRealColumns) sql += std::string(", ") + c;
  for (const char* c : kCycleIntegerColumns) sql += std::string(", ") + c;
  sql += " FROM cycles";
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &raw, nullptr) != SQLITE_OK) {
    const std::string why = sqlite3_errmsg(db);
    sqlite3_finalize(raw);
    throw ResultsDbError(file.string() + ": cannot read the cycles table: " + why);
  }
  const std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> statement(raw, sqlite3_finalize);
  ColumnReader read(raw, file, "cycles");
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(raw)) == SQLITE_ROW) {
    read.SetRow("rowid " + std::to_string(sqlite3_column_int64(raw, 0)));
    read.SetRow("rowid " + std::to_string(sqlite3_column_int64(raw, 0)) + " (run '" + read.Text(1) +
                "', cycle " + std::to_string(read.RequiredInteger(2)) + ")");
    int i = 3;
    for (const char* name : kCycleRealColumns) {
      read.Real(i++, std::string(name) == "safety_margin_m" ? ColumnReader::Infinity::kPlusAllowed
                                                            : ColumnReader::Infinity::kRefused);
    }
    for (const char* name : kCycleIntegerColumns) {
      const std::string column = name;
      if (column == "completed") {
        read.RequiredBool(i++);
      } else if (column == "safety_violations") {
        read.RequiredInteger(i++);
      } else {
        read.SmallInteger(i++);
      }
    }
  }
  if (rc != SQLITE_DONE) {
    throw ResultsDbError(NotValid(file, std::string(sqlite3_errmsg(db)) + " (reading cycles)"));
  }
}

// A prepared statement; errors name the database file.
class ResultsDb::Statement {
 public:
  Statement(const ResultsDb& owner, const std::string& sql) : owner_(owner) {
    if (sqlite3_prepare_v2(owner_.db_, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) {
      owner_.Fail("cannot prepare '" + sql.substr(0, 60) + "'");
    }
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& Bind(int index, const std::string& value) {
    Check(sqlite3_bind_text(statement_, index, value.c_str(), static_cast<int>(value.size()),
                            SQLITE_TRANSIENT));
    return *this;
  }
  Statement& Bind(int index, std::int64_t value) {
    Check(sqlite3_bind_int64(statement_, index, value));
    return *this;
  }
  Statement& Bind(int index, double value) {  // NaN -> NULL
    Check(std::isnan(value) ? sqlite3_bind_null(statement_, index)
                            : sqlite3_bind_double(statement_, index, value));
    return *this;
  }
  Statement& BindNull(int index) {
    Check(sqlite3_bind_null(statement_, index));
    return *this;
  }

  /// true: a row is available; false: done. Throws on errors.
  bool Step() {
    const int rc = sqlite3_step(statement_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;  // (extended codes only differ for errors)
    owner_.Fail("query failed");
  }
  /// Steps a statement that returns no row, then resets it for the next binding. Returns the
  /// extended result code on a constraint violation (so the caller can name it), else throws.
  int Run() {
    const int rc = sqlite3_step(statement_);  // extended codes are on: mask for the primary
    const int extended = sqlite3_extended_errcode(owner_.db_);
    if (rc == SQLITE_DONE) {
      sqlite3_reset(statement_);
      return SQLITE_OK;
    }
    if ((rc & 0xff) == SQLITE_CONSTRAINT) {
      sqlite3_reset(statement_);
      return extended;
    }
    owner_.Fail("write failed");
  }
  sqlite3_stmt* get() const { return statement_; }

 private:
  void Check(int rc) const {
    if (rc != SQLITE_OK) owner_.Fail("cannot bind a value");
  }
  const ResultsDb& owner_;
  sqlite3_stmt* statement_ = nullptr;
};

ResultsDb::ResultsDb(const std::filesystem::path& file, Access access) : file_(file) {
  if (access == Access::kReadOnly) {
    db_ = OpenCheckedReadOnly(file_).release();
    try {
      CheckSchemaReadOnly();
    } catch (...) {
      sqlite3_close(db_);
      db_ = nullptr;
      throw;
    }
    return;
  }
  const int rc =
      sqlite3_open_v2(file_.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw ResultsDbError(file_.string() + ": cannot open the results database: " + message);
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    sqlite3_busy_timeout(db_, 10000);  // campaigns: other processes may hold the write lock
    // Before anything is read or written: a damaged file is refused, not extended (quick: this
    // runs on every resume and merge; reports run the full check).
    results::CheckIntegrity(db_, file_, IntegrityCheck::kQuick);
    CreateOrCheckSchema();
    Execute("PRAGMA foreign_keys = ON");
    Execute("PRAGMA synchronous = NORMAL");
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

ResultsDb::~ResultsDb() {
  // Closing the last connection checkpoints the WAL into the main file.
  if (db_ != nullptr) sqlite3_close(db_);
}

void ResultsDb::Fail(const std::string& what) const {
  const int code = sqlite3_extended_errcode(db_);
  std::string message = file_.string() + ": " + what + ": " + sqlite3_errmsg(db_);
  if ((code & 0xff) == SQLITE_NOTADB || (code & 0xff) == SQLITE_CORRUPT) {
    message = NotValid(file_, std::string(sqlite3_errmsg(db_)) + " (" + what + ")");
  }
  throw ResultsDbError(message);
}

void ResultsDb::CheckIntegrity() const { results::CheckIntegrity(db_, file_); }

void ResultsDb::CheckSchemaReadOnly() {
  has_crowding_samples_ = false;
  bool has_version_table = false;
  int tables = 0;
  {
    Statement list(*this, "SELECT name FROM sqlite_master WHERE type = 'table'");
    ColumnReader read(list.get(), file_, "sqlite_master");
    while (list.Step()) {
      ++tables;
      const std::string name = read.Text(0);
      has_version_table |= name == "schema_version";
      has_crowding_samples_ |= name == "crowding_samples";
    }
  }
  if (!has_version_table) {
    throw ResultsDbError(file_.string() +
                         ": not an autoshovel results database (a SQLite file with " +
                         std::to_string(tables) + " table(s) but no schema_version table)");
  }
  Statement version(*this, "SELECT version FROM schema_version");
  ColumnReader read(version.get(), file_, "schema_version");
  read.SetRow("its row");
  if (!version.Step()) {
    throw ResultsDbError(file_.string() + ": results database without a schema version row");
  }
  const std::int64_t found = read.RequiredInteger(0);
  has_predicted_penetration_ =
      has_crowding_samples_ && HasColumn("crowding_samples", "predicted_penetration_m");
  if (found == 1) {
    throw ResultsDbError(file_.string() + ": results schema version 1; reading it needs a " +
                         "migration to version 2, which a read-only open does not do (open it " +
                         "once with a writer, e.g. resume its run)");
  }
  if (found != kSchemaVersion) {
    throw ResultsDbError(file_.string() + ": results schema version " + std::to_string(found) +
                         ", this build reads version " + std::to_string(kSchemaVersion) +
                         " (written by another autoshovel version)");
  }
}

void ResultsDb::Execute(const char* sql) const {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    sqlite3_free(error);
    Fail(std::string("cannot run '") + std::string(sql).substr(0, 60) + "'");
  }
}

void ResultsDb::CreateOrCheckSchema() {
  // Reading sqlite_master first: a non-SQLite file fails here, before anything is written.
  int tables = 0;
  bool has_version_table = false;
  {
    Statement list(*this, "SELECT name FROM sqlite_master WHERE type = 'table'");
    ColumnReader read(list.get(), file_, "sqlite_master");
    while (list.Step()) {
      ++tables;
      if (read.Text(0) == "schema_version") has_version_table = true;
    }
  }
  if (tables == 0) {
    Execute("PRAGMA journal_mode = WAL");
    Execute("BEGIN IMMEDIATE");
    try {
      // Another process may have created it between our read and the write lock.
      Statement again(*this, "SELECT count(*) FROM sqlite_master WHERE name = 'schema_version'");
      again.Step();
      if (ColumnReader(again.get(), file_, "sqlite_master").RequiredInteger(0) == 0) {
        Execute(kSchema);
        Execute(kCrowdingSamplesSchema);
        Statement version(*this, "INSERT INTO schema_version (version) VALUES (?)");
        version.Bind(1, static_cast<std::int64_t>(kSchemaVersion));
        if (version.Run() != SQLITE_OK) Fail("cannot write the schema version");
      }
      Execute("COMMIT");
    } catch (...) {
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
      throw;
    }
    return;
  }
  if (!has_version_table) {
    throw ResultsDbError(file_.string() +
                         ": not an autoshovel results database (a SQLite file with " +
                         std::to_string(tables) + " table(s) but no schema_version table)");
  }
  int found = 0;
  {
    Statement version(*this, "SELECT version FROM schema_version");
    if (!version.Step()) {
      throw ResultsDbError(file_.string() + ": results database without a schema version row");
    }
    ColumnReader read(version.get(), file_, "schema_version");
    read.SetRow("its row");
    found = read.SmallInteger(0).value_or(0);
  }
  if (found == 1) {
    // Migrated in one transaction; a concurrent opener that migrated first is seen again here.
    Execute("BEGIN IMMEDIATE");
    try {
      Statement again(*this, "SELECT version FROM schema_version");
      again.Step();
      ColumnReader read(again.get(), file_, "schema_version");
      read.SetRow("its row");
      if (read.SmallInteger(0) == 1) Execute(kMigrateV1ToV2);
      Execute("COMMIT");
    } catch (...) {
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
      throw;
    }
    found = 2;
  }
  if (found != kSchemaVersion) {
    throw ResultsDbError(file_.string() + ": results schema version " + std::to_string(found) +
                         ", this build reads version " + std::to_string(kSchemaVersion) +
                         " (written by another autoshovel version)");
  }
  Execute("PRAGMA journal_mode = WAL");
  Execute(kCrowdingSamplesSchema);
  AddPredictedPenetrationColumn();
}

bool ResultsDb::HasColumn(const std::string& table, const std::string& column) const {
  Statement columns(*this, "SELECT name FROM pragma_table_info(?)");
  columns.Bind(1, table);
  ColumnReader read(columns.get(), file_, "pragma_table_info('" + table + "')");
  while (columns.Step()) {
    if (read.Text(0) == column) return true;
  }
  return false;
}

void ResultsDb::AddPredictedPenetrationColumn() {
  if (HasColumn("crowding_samples", "predicted_penetration_m")) return;
  // In one transaction; a concurrent opener (a campaign's workers) that added it first is seen
  // again here.
  Execute("BEGIN IMMEDIATE");
  try {
    if (!HasColumn("crowding_samples", "predicted_penetration_m")) {
      Execute(kAddPredictedPenetration);
    }
    Execute("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

bool ResultsDb::BeginRun(const RunInfo& run) {
  if (run.run_id.empty()) Fail("BeginRun: empty run id");
  if (const std::optional<RunInfo> existing = FindRun(run.run_id)) {
    if (existing->scenario != run.scenario || existing->machine != run.machine ||
        existing->seed != run.seed) {
      throw ResultsDbError(file_.string() + ": run '" + run.run_id + "' exists with scenario '" +
                           existing->scenario + "', machine '" + existing->machine + "', seed " +
                           std::to_string(existing->seed) + "; cannot resume it with scenario '" +
                           run.scenario + "', machine '" + run.machine + "', seed " +
                           std::to_string(run.seed));
    }
    return true;
  }
  Statement insert(*this,
                   "INSERT INTO runs (run_id, scenario, machine, seed, cycles_planned, "
                   "start_time_utc, git_describe) VALUES (?, ?, ?, ?, ?, ?, ?)");
  insert.Bind(1, run.run_id).Bind(2, run.scenario).Bind(3, run.machine);
  insert.Bind(4, static_cast<std::int64_t>(run.seed));
  insert.Bind(5, static_cast<std::int64_t>(run.cycles_planned));
  insert.Bind(6, run.start_time_utc.empty() ? UtcTimestampIso() : run.start_time_utc);
  if (run.git_describe.empty()) {
    insert.BindNull(7);
  } else {
    insert.Bind(7, run.git_describe);
  }
  if (insert.Run() != SQLITE_OK) Fail("cannot insert run '" + run.run_id + "'");
  return false;
}

std::vector<RunInfo> ResultsDb::Runs() const {
  std::vector<RunInfo> runs;
  Statement select(*this,
                   "SELECT run_id, scenario, machine, seed, cycles_planned, start_time_utc, "
                   "git_describe, rowid FROM runs ORDER BY start_time_utc, run_id");
  ColumnReader read(select.get(), file_, "runs");
  while (select.Step()) {
    RunInfo run;
    read.SetRow("rowid " + std::to_string(sqlite3_column_int64(select.get(), 7)));
    run.run_id = read.Text(0);
    read.SetRow("rowid " + std::to_string(sqlite3_column_int64(select.get(), 7)) + " (run '" +
                run.run_id + "')");
    run.scenario = read.Text(1);
    run.machine = read.Text(2);
    run.seed = static_cast<std::uint64_t>(read.RequiredInteger(3));  // the same 64 bits
    const std::optional<int> planned = read.SmallInteger(4);
    if (!planned) read.Refuse(4, "NULL where the planned cycle count is required");
    run.cycles_planned = *planned;
    run.start_time_utc = read.Text(5);
    run.git_describe = read.Text(6);
    runs.push_back(std::move(run));
  }
  return runs;
}

std::optional<RunInfo> ResultsDb::FindRun(const std::string& run_id) const {
  for (RunInfo& run : Runs()) {
    if (run.run_id == run_id) return std::move(run);
  }
  return std::nullopt;
}

void ResultsDb::WriteCycle(const std::string& run_id, const CycleRecord& record) {
  if (record.cycle < 0) {
    throw ResultsDbError(file_.string() + ": cycle index must be >= 0, got " +
                         std::to_string(record.cycle));
  }
  if (!FindRun(run_id)) {
    throw ResultsDbError(file_.string() + ": cycle " + std::to_string(record.cycle) + " for run '" +
                         run_id + "', which was not begun (call BeginRun first)");
  }
  Execute("BEGIN IMMEDIATE");
  try {
    {
      Statement insert(*this, std::string("INSERT INTO cycles (run_id, cycle, ") + kCycleColumns +
                                  ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, "
                                  "?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
      // One Bind per statement: chained `Bind(i++, ...).Bind(i++, ...)` is sequenced in C++17
      // but GCC's -Wsequence-point still flags it.
      int i = 0;
      auto text = [&](const std::string& value) { insert.Bind(++i, value); };
      auto real = [&](double value) { insert.Bind(++i, value); };
      auto integer = [&](std::int64_t value) { insert.Bind(++i, value); };
      text(run_id);
      integer(record.cycle);
      for (const std::string* value :
           {&record.scenario, &record.machine, &record.bin, &record.material, &record.strategy,
            &record.atomic_actions}) {
        text(*value);
      }
      for (const double value : {record.trigger_time_s, record.fill_rate, record.payload_m3}) {
        real(value);
      }
      for (const PhaseValues* v : {&record.time_s, &record.energy_kj}) {
        for (const double value :
             {v->approach, v->crowd, v->scoop, v->level, v->retreat, v->total}) {
          real(value);
        }
      }
      real(record.safety_margin_m);
      integer(record.safety_violations);
      integer(record.completed ? 1 : 0);
      for (const int count : {record.safe_stops, record.recoveries, record.refused_frames}) {
        if (count < 0) {
          insert.BindNull(++i);
        } else {
          integer(count);
        }
      }
      text(record.faults);
      if (record.completed) {
        insert.BindNull(++i);
      } else {
        text(record.failure);
      }
      const int rc = insert.Run();
      if (rc == SQLITE_CONSTRAINT_UNIQUE || rc == SQLITE_CONSTRAINT_PRIMARYKEY) {
        throw DuplicateCycleError(file_.string() + ": run '" + run_id + "' already holds cycle " +
                                  std::to_string(record.cycle) + "; nothing was written");
      }
      if (rc != SQLITE_OK) Fail("cannot write cycle " + std::to_string(record.cycle));
    }
    Statement sample(*this, std::string("INSERT INTO samples (run_id, cycle, k, ") +
                                kSampleColumns + ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    for (std::size_t k = 0; k < record.samples.size(); ++k) {
      const CycleSample& s = record.samples[k];
      if (std::isnan(s.t)) {
        throw ResultsDbError(file_.string() + ": cycle " + std::to_string(record.cycle) +
                             ", sample " + std::to_string(k) +
                             ": time is NaN; nothing of the cycle was written");
      }
      sample.Bind(1, run_id).Bind(2, static_cast<std::int64_t>(record.cycle));
      sample.Bind(3, static_cast<std::int64_t>(k)).Bind(4, s.t).Bind(5, s.v1).Bind(6, s.v1v2);
      sample.Bind(7, static_cast<std::int64_t>(s.triggered ? 1 : 0));
      sample.Bind(8, s.predicted_tip_x).Bind(9, s.predicted_tip_z);
      sample.Bind(10, s.actual_tip_x).Bind(11, s.actual_tip_z);
      if (sample.Run() != SQLITE_OK) {
        Fail("cannot write sample " + std::to_string(k) + " of cycle " +
             std::to_string(record.cycle));
      }
    }
    if (record.crowding.present) {
      const CrowdingSample& c = record.crowding;
      Statement crowding(*this, std::string("INSERT INTO crowding_samples (") + kCrowdingColumns +
                                    ", predicted_penetration_m) VALUES "
                                    "(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
      crowding.Bind(1, run_id).Bind(2, static_cast<std::int64_t>(record.cycle));
      crowding.Bind(3, c.strategy).Bind(4, c.trigger).Bind(5, c.material);
      crowding.Bind(6, c.speed).Bind(7, c.v1);
      for (int k = 0; k < 6; ++k) crowding.Bind(8 + k, c.heights[k]);
      crowding.Bind(14, c.penetration);
      crowding.Bind(15, c.predicted_penetration);  // NaN (not logged) -> NULL
      if (crowding.Run() != SQLITE_OK) {
        Fail("cannot write the crowding sample of cycle " + std::to_string(record.cycle));
      }
    }
    Execute("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

std::vector<ResultsDb::StoredCrowdingSample> ResultsDb::CrowdingSamples() const {
  std::vector<StoredCrowdingSample> out;
  if (!has_crowding_samples_) return out;  // a read-only file from before the table
  // A read-only file from before predicted_penetration_m: every row reads it as not logged.
  Statement select(*this, std::string("SELECT ") + kCrowdingColumns + ", " +
                              (has_predicted_penetration_ ? "predicted_penetration_m" : "NULL") +
                              " FROM crowding_samples ORDER BY run_id, cycle");
  ColumnReader read(select.get(), file_, "crowding_samples");
  while (select.Step()) {
    StoredCrowdingSample s;
    s.run_id = read.Text(0);
    read.SetRow("run '" + s.run_id + "'");
    s.cycle = read.SmallInteger(1).value_or(-1);
    read.SetRow("run '" + s.run_id + "', cycle " + std::to_string(s.cycle));
    s.sample.present = true;
    s.sample.strategy = read.Text(2);
    s.sample.trigger = read.Text(3);
    s.sample.material = read.Text(4);
    s.sample.speed = read.RealOrNotMeasured(5);
    s.sample.v1 = read.RealOrNotMeasured(6);
    for (int k = 0; k < 6; ++k) s.sample.heights[k] = read.RealOrNotMeasured(7 + k);
    s.sample.penetration = read.RealOrNotMeasured(13);
    s.sample.predicted_penetration = read.RealOrNotMeasured(14);  // NULL: kNotMeasured, never 0
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<int> ResultsDb::CompletedCycles(const std::string& run_id) const {
  std::vector<int> cycles;
  Statement select(*this, "SELECT cycle FROM cycles WHERE run_id = ? ORDER BY cycle");
  select.Bind(1, run_id);
  ColumnReader read(select.get(), file_, "cycles");
  read.SetRow("run '" + run_id + "'");
  while (select.Step()) {
    const std::optional<int> cycle = read.SmallInteger(0);
    if (!cycle) read.Refuse(0, "NULL where the cycle index is required");
    cycles.push_back(*cycle);
  }
  return cycles;
}

std::vector<int> ResultsDb::MissingCycles(const std::string& run_id, int cycles_planned) const {
  const std::vector<int> done = CompletedCycles(run_id);
  std::vector<int> missing;
  std::size_t j = 0;
  for (int cycle = 0; cycle < cycles_planned; ++cycle) {
    while (j < done.size() && done[j] < cycle) ++j;
    if (j == done.size() || done[j] != cycle) missing.push_back(cycle);
  }
  return missing;
}

std::vector<CycleRecord> ResultsDb::Cycles(const std::string& run_id, bool with_samples) const {
  std::vector<CycleRecord> records;
  {
    Statement select(*this, std::string("SELECT rowid, cycle, ") + kCycleColumns +
                                " FROM cycles WHERE run_id = ? ORDER BY cycle");
    select.Bind(1, run_id);
    ColumnReader read(select.get(), file_, "cycles");
    while (select.Step()) {
      const std::string rowid = "rowid " + std::to_string(sqlite3_column_int64(select.get(), 0));
      read.SetRow(rowid + " (run '" + run_id + "')");
      CycleRecord r;
      int i = 1;
      const std::optional<int> cycle = read.SmallInteger(i);
      if (!cycle) read.Refuse(i, "NULL where the cycle index is required");
      r.cycle = *cycle;
      ++i;
      read.SetRow(rowid + " (run '" + run_id + "', cycle " + std::to_string(r.cycle) + ")");
      r.scenario = read.Text(i++);
      r.machine = read.Text(i++);
      r.bin = read.Text(i++);
      r.material = read.Text(i++);
      r.strategy = read.Text(i++);
      r.atomic_actions = read.Text(i++);
      r.trigger_time_s = read.RealOrNotMeasured(i++);
      r.fill_rate = read.RealOrNotMeasured(i++);
      r.payload_m3 = read.RealOrNotMeasured(i++);
      for (PhaseValues* values : {&r.time_s, &r.energy_kj}) {
        values->approach = read.RealOrNotMeasured(i++);
        values->crowd = read.RealOrNotMeasured(i++);
        values->scoop = read.RealOrNotMeasured(i++);
        values->level = read.RealOrNotMeasured(i++);
        values->retreat = read.RealOrNotMeasured(i++);
        values->total = read.RealOrNotMeasured(i++);
      }
      // +inf: nothing came within reach during the cycle (the writer's starting minimum).
      r.safety_margin_m = read.RealOrNotMeasured(i++, ColumnReader::Infinity::kPlusAllowed);
      const std::optional<int> violations = read.SmallInteger(i);
      if (!violations) read.Refuse(i, "NULL where the violation count is required");
      r.safety_violations = *violations;
      ++i;
      r.completed = read.RequiredBool(i++);
      for (int* count : {&r.safe_stops, &r.recoveries, &r.refused_frames}) {
        *count = read.SmallInteger(i++).value_or(-1);  // NULL: not recorded (before version 2)
      }
      r.faults = read.Text(i++);
      r.failure = read.Text(i++);
      records.push_back(std::move(r));
    }
  }
  if (with_samples) {
    for (CycleRecord& r : records) r.samples = Samples(run_id, r.cycle);
  }
  return records;
}

std::optional<CycleRecord> ResultsDb::Cycle(const std::string& run_id, int cycle) const {
  for (CycleRecord& r : Cycles(run_id, false)) {
    if (r.cycle == cycle) {
      r.samples = Samples(run_id, cycle);
      return std::move(r);
    }
  }
  return std::nullopt;
}

std::vector<CycleSample> ResultsDb::Samples(const std::string& run_id, int cycle) const {
  std::vector<CycleSample> samples;
  Statement select(*this, std::string("SELECT ") + kSampleColumns +
                              ", k FROM samples WHERE run_id = ? AND cycle = ? ORDER BY k");
  select.Bind(1, run_id).Bind(2, static_cast<std::int64_t>(cycle));
  ColumnReader read(select.get(), file_, "samples");
  while (select.Step()) {
    read.SetRow("run '" + run_id + "', cycle " + std::to_string(cycle) + ", k " +
                std::to_string(sqlite3_column_int64(select.get(), 8)));
    CycleSample sample;
    const std::optional<double> t = read.Real(0);
    if (!t) read.Refuse(0, "NULL where the sample time is required");
    sample.t = *t;
    sample.v1 = read.RealOrNotMeasured(1);
    sample.v1v2 = read.RealOrNotMeasured(2);
    sample.triggered = read.RequiredBool(3);
    sample.predicted_tip_x = read.RealOrNotMeasured(4);
    sample.predicted_tip_z = read.RealOrNotMeasured(5);
    sample.actual_tip_x = read.RealOrNotMeasured(6);
    sample.actual_tip_z = read.RealOrNotMeasured(7);
    samples.push_back(sample);
  }
  return samples;
}

}  // namespace autoshovel::results
