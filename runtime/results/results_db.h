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
// that never triggered) and read back as NaN. ±inf is stored as is.
//
// Schema, units and example queries: docs/results_and_reports.md.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
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

  /// Opens `file`, creating it and the schema when it does not exist or is empty, and migrating
  /// a version-1 file to version 2 in place (one transaction; its rows keep their values and
  /// read −1 / "" for the new fields). Throws ResultsDbError naming the file when it is not a
  /// SQLite database, is a SQLite database without our schema_version table, or has another
  /// schema version. A foreign file is not modified.
  explicit ResultsDb(const std::filesystem::path& file);
  ~ResultsDb();
  ResultsDb(const ResultsDb&) = delete;
  ResultsDb& operator=(const ResultsDb&) = delete;

  const std::filesystem::path& file() const { return file_; }

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

  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
};

}  // namespace autoshovel::results
