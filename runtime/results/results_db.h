// The results database of `autoshovel run` (DESIGN.md, "Outputs"; issue 9 item 3): one SQLite
// file per run folder, one `cycles` row per shoveling cycle with its time series in `samples`.
//
// Crash safety: WAL journal, synchronous=NORMAL, and each cycle (its row and all its samples) is
// written in one transaction. A process killed at any instant (SIGKILL included) leaves every
// committed cycle whole and nothing of the cycle in flight; CompletedCycles() then says what a
// resumed run still has to do. synchronous=NORMAL may lose the last commits on a power cut or OS
// crash (never corrupting the file); a killed process loses nothing committed.
//
// NaN is stored as SQL NULL ("not measured / not applicable", e.g. the trigger time of a cycle
// that never triggered) and read back as NaN. +inf is stored as is where it has a meaning (the
// safety margin of a cycle with nothing in reach).
//
// Reading back (issue 38): every reader of a results database goes through ColumnReader, which
// keeps NULL as "not measured" and refuses what a careless edit or a damaged file leaves behind
// (text or a blob in a numeric column, a non-integral number in an INTEGER column, infinities
// where none belongs) with the file, table, row and column, instead of reading it as 0 the way
// sqlite3_column_double does. Reports open the file read-only and run PRAGMA integrity_check
// first, so a damaged file is refused before any figure is computed from it.
//
// Schema, units and example queries: docs/results_and_reports.md.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace autoshovel::results {

inline constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

/// Thrown for any failure of the database; what() starts with the database file's path.
class ResultsDbError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Thrown by WriteCycle when the run already holds that cycle index; nothing was written.
class DuplicateCycleError : public ResultsDbError {
 public:
  using ResultsDbError::ResultsDbError;
};

/// Closes a connection opened by OpenCheckedReadOnly.
struct SqliteCloser {
  void operator()(sqlite3* db) const;
};
using SqliteConnection = std::unique_ptr<sqlite3, SqliteCloser>;

/// How thoroughly CheckIntegrity looks: `quick_check` is linear in the file (opening a campaign's
/// databases to resume or merge them), `integrity_check` also checks every index against its
/// table (before a report).
enum class IntegrityCheck { kQuick, kFull };

/// Runs PRAGMA quick_check or integrity_check on `db`. Throws ResultsDbError
/// "FILE is not a valid SQLite database: WHY" when the file is not SQLite or is damaged.
void CheckIntegrity(sqlite3* db, const std::filesystem::path& file,
                    IntegrityCheck how = IntegrityCheck::kFull);

/// Opens `file` with SQLITE_OPEN_READONLY (nothing in it is changed by reading it) and runs
/// CheckIntegrity(kFull). Throws ResultsDbError naming the file when it does not exist, is not a
/// regular file, is not SQLite or is damaged.
SqliteConnection OpenCheckedReadOnly(const std::filesystem::path& file);

/// The one typed reader of values in a results database (see the top of this file). A view over
/// a statement whose current row comes from `table`; SetRow says how errors name that row.
/// Errors: ResultsDbError "FILE: table T, ROW, column C: WHY".
class ColumnReader {
 public:
  /// Whether +inf is a value of the column (only `safety_margin_m`: nothing was in reach).
  enum class Infinity { kRefused, kPlusAllowed };

  ColumnReader(sqlite3_stmt* statement, std::filesystem::path file, std::string table);

  /// How errors name the current row, e.g. "rowid 17 (run 'w1s1-auto', cycle 3)".
  void SetRow(std::string row) { row_ = std::move(row); }

  /// A REAL (or INTEGER) column: nullopt for NULL ("not measured"). Refuses text, blobs and
  /// non-finite values (+inf is let through with Infinity::kPlusAllowed).
  std::optional<double> Real(int column, Infinity infinity = Infinity::kRefused) const;
  /// Real() with NULL as kNotMeasured (NaN): the in-memory form of the record structs.
  double RealOrNotMeasured(int column, Infinity infinity = Infinity::kRefused) const;
  /// An INTEGER column: nullopt for NULL. Refuses text, blobs and non-integral numbers.
  std::optional<std::int64_t> Integer(int column) const;
  /// Integer() where NULL is refused too (NOT NULL columns, counts, keys).
  std::int64_t RequiredInteger(int column) const;
  /// Integer() of a 0/1 column; other values are refused.
  bool RequiredBool(int column) const;
  /// Integer() narrowed to int; values outside int's range are refused.
  std::optional<int> SmallInteger(int column) const;
  /// A TEXT column: "" for NULL. Refuses blobs; numbers are read as their text.
  std::string Text(int column) const;

  /// Throws ResultsDbError naming the file, table, row and column.
  [[noreturn]] void Refuse(int column, const std::string& why) const;

 private:
  sqlite3_stmt* statement_;
  std::filesystem::path file_;
  std::string table_;
  std::string row_;
};

/// Reads every numeric column of every `cycles` row through ColumnReader (throws on the first
/// bad value), so that SQL aggregates over them (AVG, SUM in the campaign summary and the
/// fault_summary view) cannot fold text into 0 or let an infinity through.
void CheckCycleValues(sqlite3* db, const std::filesystem::path& file);

/// One run: a row of `runs`.
struct RunInfo {
  std::string run_id;          ///< unique in the file; by default the run folder's name
  std::string scenario;        ///< scenario name (models/scenarios/…)
  std::string machine;         ///< machine name (models/loaders/…)
  std::uint64_t seed = 0;      ///< stored as the same 64 bits in a signed INTEGER
  int cycles_planned = 0;      ///< cycles the run was asked for (--cycles)
  std::string start_time_utc;  ///< ISO 8601; empty: now, when BeginRun inserts the row
  std::string git_describe;    ///< `git describe` of the build; empty is stored as NULL
};

/// Per-phase values of one cycle. "total" is the whole cycle, given by the caller (it may exceed
/// the phases' sum when they do not cover the cycle). NaN: not measured, stored as NULL.
struct PhaseValues {
  double approach = kNotMeasured;
  double crowd = kNotMeasured;
  double scoop = kNotMeasured;
  double level = kNotMeasured;
  double retreat = kNotMeasured;
  double total = kNotMeasured;
};

/// One time-series sample of a cycle (the report's volume and bucket-path figures).
struct CycleSample {
  double t = 0.0;                         ///< time since the cycle started [s]
  double v1 = kNotMeasured;               ///< estimated bucket volume V1, Eq. (19) [m³]
  double v1v2 = kNotMeasured;             ///< V1 + predicted V2 [m³]
  bool triggered = false;                 ///< the scoop trigger has fired at or before t
  double predicted_tip_x = kNotMeasured;  ///< predicted bucket tip, vehicle frame [m]
  double predicted_tip_z = kNotMeasured;  ///< [m]
  double actual_tip_x = kNotMeasured;     ///< actual bucket tip, vehicle frame [m]
  double actual_tip_z = kNotMeasured;     ///< [m]
};

/// The penetration predictor's inputs at the scoop trigger and the travel that followed: a row
/// of `crowding_samples`, the data `autoshovel train predictor DB` retrains on (seed §7.6).
struct CrowdingSample {
  bool present = false;  ///< false: the cycle computed no prediction at its trigger
  std::string strategy;  ///< the scoop that followed, e.g. "just_in_out"
  std::string trigger;   ///< what fired, e.g. "prediction", "stopped"
  std::string material;
  double speed = kNotMeasured;        ///< v at the trigger [m/s]
  double v1 = kNotMeasured;           ///< V1 at the trigger [m³]
  std::array<double, 6> heights{};    ///< h1..h6 ahead of the tip [m]
  double penetration = kNotMeasured;  ///< forward travel from the trigger to the scoop's end [m]
  /// The predictor's travel at the trigger [m]: what the run itself predicted for these inputs
  /// (NULL: not logged, as in a file from before the column, or the prediction failed).
  double predicted_penetration = kNotMeasured;
};

/// One shoveling cycle: a row of `cycles` and its `samples`.
struct CycleRecord {
  int cycle = 0;  ///< index within the run, 0-based; unique per run
  std::string scenario;
  std::string machine;
  std::string bin;             ///< the pile / bin shovelled from
  std::string material;        ///< material name (models/materials/…)
  std::string strategy;        ///< e.g. "prediction", "perception_only", "pressure_stairway3"
  std::string atomic_actions;  ///< the scoop's atomic actions in order, e.g. "lift,tilt,lift"
  double trigger_time_s = kNotMeasured;   ///< scoop trigger, from the cycle start [s]
  double fill_rate = kNotMeasured;        ///< payload / rated bucket capacity [1]
  double payload_m3 = kNotMeasured;       ///< material in the bucket at the end [m³]
  PhaseValues time_s;                     ///< duration per phase [s]
  PhaseValues energy_kj;                  ///< energy per phase [kJ]
  double safety_margin_m = kNotMeasured;  ///< smallest clearance to obstacles/people [m]
  int safety_violations = 0;              ///< safety-rule violations in the cycle (must be 0)
  bool completed = true;  ///< ran to the end; false: aborted (safety stop, timeout), row whole
  // Schema version 2 (issue 9). −1: not recorded (a row written before version 2; NULL).
  int safe_stops = 0;      ///< stops the safety supervisor held
  int recoveries = 0;      ///< of those, the ones the machine drove on from
  int refused_frames = 0;  ///< late or out-of-order sensor frames not used
  std::string faults;      ///< the fault kinds declared for the cycle, comma-separated; "" none
  std::string failure;     ///< why it did not complete ("" when it did; stored as NULL)
  std::vector<CycleSample> samples;
  CrowdingSample crowding;
};

class ResultsDb {
 public:
  static constexpr int kSchemaVersion = 2;

  enum class Access {
    kReadWrite,  ///< create or check the schema, migrate, write cycles (runs, campaigns)
    kReadOnly,   ///< read back only (reports, retraining): nothing in the file is changed
  };

  /// Opens `file`, creating it and the schema when it does not exist or is empty, and migrating
  /// a version-1 file to version 2 in place (one transaction; its rows keep their values and
  /// read −1 / "" for the new fields). Throws ResultsDbError naming the file when it is not a
  /// SQLite database, is a SQLite database without our schema_version table, or has another
  /// schema version. A foreign file is not modified. An existing file is checked with
  /// PRAGMA quick_check before anything is read or written ("FILE is not a valid SQLite
  /// database: ...").
  ///
  /// Access::kReadOnly: the file must exist; it is opened read-only and checked with
  /// PRAGMA integrity_check; a version-1 file is refused (migrating would write to it).
  explicit ResultsDb(const std::filesystem::path& file, Access access = Access::kReadWrite);
  ~ResultsDb();
  ResultsDb(const ResultsDb&) = delete;
  ResultsDb& operator=(const ResultsDb&) = delete;

  const std::filesystem::path& file() const { return file_; }

  /// PRAGMA integrity_check on the open file (before a report); throws ResultsDbError.
  void CheckIntegrity() const;

  /// Inserts the run, or finds it when resuming. Returns true when it already existed; then
  /// scenario, machine and seed must match, else throws (the rows would not be comparable).
  bool BeginRun(const RunInfo& run);
  std::optional<RunInfo> FindRun(const std::string& run_id) const;
  std::vector<RunInfo> Runs() const;

  /// Writes the row and its samples in one transaction: all of it or nothing. Throws
  /// DuplicateCycleError when `run_id` already holds `record.cycle`, ResultsDbError when the run
  /// was not begun or the cycle index is negative.
  void WriteCycle(const std::string& run_id, const CycleRecord& record);

  /// Cycle indices the run holds (each whole), ascending: what a resumed run skips.
  std::vector<int> CompletedCycles(const std::string& run_id) const;
  /// Indices in [0, cycles_planned) not yet written, ascending: what a resumed run still runs.
  std::vector<int> MissingCycles(const std::string& run_id, int cycles_planned) const;

  /// All cycles of the run ordered by index; samples are read only when asked for.
  std::vector<CycleRecord> Cycles(const std::string& run_id, bool with_samples = false) const;
  std::optional<CycleRecord> Cycle(const std::string& run_id, int cycle) const;
  std::vector<CycleSample> Samples(const std::string& run_id, int cycle) const;
  /// Every stored crowding sample, with its run and cycle.
  struct StoredCrowdingSample {
    std::string run_id;
    int cycle = 0;
    CrowdingSample sample;
  };
  std::vector<StoredCrowdingSample> CrowdingSamples() const;

 private:
  class Statement;
  void Execute(const char* sql) const;
  [[noreturn]] void Fail(const std::string& what) const;
  void CreateOrCheckSchema();
  void CheckSchemaReadOnly();
  bool HasColumn(const std::string& table, const std::string& column) const;
  void AddPredictedPenetrationColumn();

  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
  bool has_crowding_samples_ = true;  ///< false: a read-only file from before the table
  /// false: a read-only file from before crowding_samples.predicted_penetration_m
  bool has_predicted_penetration_ = true;
};

}  // namespace autoshovel::results
