#include "runtime/app/campaign/production_report.h"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>
#include <vector>

#include "runtime/plot/box_plot.h"
#include "runtime/results/results_db.h"

namespace autoshovel::app {
namespace {

constexpr const char* kCommand = "autoshovel report production";

// nullopt: not measured (NULL in the database), left out of every mean and box.
struct Row {
  int week = 0;
  std::string policy, material, strategy;
  bool gravel = false;
  std::optional<double> fill, time, energy;  ///< scooping: contact to end of scoop [s, kJ]
  bool completed = false;
  long long violations = 0;
};

// Scooping is the crowd and scoop phases together: not measured when either is not.
std::optional<double> Sum(const std::optional<double>& a, const std::optional<double>& b) {
  if (!a || !b) return std::nullopt;
  return *a + *b;
}

// "Just in & out", or "Stairway #N" with N the bucket retractions (its atomic actions).
std::string StrategyLabel(const std::string& strategy, const std::string& actions) {
  if (strategy == "just_in_out") return "Just in & out";
  int steps = 0;
  for (std::size_t at = actions.find("retract_bucket"); at != std::string::npos;
       at = actions.find("retract_bucket", at + 1)) {
    ++steps;
  }
  return "Stairway #" + std::to_string(steps);
}

// The reader refuses non-finite values, so every value that reaches a mean is finite; NULL
// ("not measured") is counted, so the report can say how many cycles a mean leaves out.
struct Mean {
  double sum = 0;
  int n = 0, not_measured = 0;
  void Add(const std::optional<double>& v) {
    if (v) {
      sum += *v, ++n;
    } else {
      ++not_measured;
    }
  }
  double value() const { return n > 0 ? sum / n : NAN; }
};

struct Cell {
  int gravel = 0, sand = 0;
  Mean time, energy;
  void Add(const Row& r) {
    (r.gravel ? gravel : sand) += 1;
    time.Add(r.time);
    energy.Add(r.energy);
  }
};

std::string Num(double v, const char* format) {
  if (!std::isfinite(v)) return "—";
  char text[32];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

// Every cycle of the campaign through the typed reader: the database is opened read-only and
// checked (PRAGMA integrity_check) first; text, blobs or infinities in a numeric column are
// refused naming the row and column, NULL stays "not measured".
std::vector<Row> ReadRows(const std::filesystem::path& file) {
  const results::SqliteConnection db = results::OpenCheckedReadOnly(file);
  const char* sql =
      "SELECT c.rowid, c.run_id, c.cycle, r.week, r.policy, c.material, c.strategy, "
      "c.atomic_actions, c.fill_rate, c.completed, c.time_crowd_s, c.time_scoop_s, "
      "c.energy_crowd_kj, c.energy_scoop_kj, c.safety_violations "
      "FROM cycles c JOIN campaign_runs r USING (run_id) ORDER BY r.week, c.run_id, c.cycle";
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db.get(), sql, -1, &raw, nullptr) != SQLITE_OK) {
    const std::string why = sqlite3_errmsg(db.get());
    sqlite3_finalize(raw);
    throw std::runtime_error(file.string() +
                             ": not a campaign database (no cycles or campaign_runs table: " + why +
                             ")");
  }
  const std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> statement(raw, sqlite3_finalize);
  results::ColumnReader cycles(raw, file, "cycles");
  results::ColumnReader runs(raw, file, "campaign_runs");
  std::vector<Row> rows;
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(raw)) == SQLITE_ROW) {
    const std::string run_id = cycles.Text(1);
    cycles.SetRow("rowid " + std::to_string(cycles.RequiredInteger(0)) + " (run '" + run_id +
                  "', cycle " + std::to_string(cycles.RequiredInteger(2)) + ")");
    runs.SetRow("run '" + run_id + "'");
    Row r;
    const std::optional<int> week = runs.SmallInteger(3);
    if (!week) runs.Refuse(3, "NULL where the week is required");
    r.week = *week;
    r.policy = runs.Text(4);
    r.material = cycles.Text(5);
    r.gravel = r.material.find("gravel") != std::string::npos;
    r.completed = cycles.RequiredBool(9);
    // Every value is read (and checked) whether or not the cycle completed: a damaged row is
    // refused, not skipped.
    const std::string strategy = cycles.Text(6), actions = cycles.Text(7);
    const std::optional<double> fill = cycles.Real(8);
    const std::optional<double> time = Sum(cycles.Real(10), cycles.Real(11));
    const std::optional<double> energy = Sum(cycles.Real(12), cycles.Real(13));
    if (r.completed) {
      r.strategy = StrategyLabel(strategy, actions);
      r.fill = fill, r.time = time, r.energy = energy;
    }
    r.violations = cycles.RequiredInteger(14);
    rows.push_back(r);
  }
  if (rc != SQLITE_DONE) {
    throw std::runtime_error(file.string() + " is not a valid SQLite database: " +
                             sqlite3_errmsg(db.get()) + " (reading cycles)");
  }
  return rows;
}

// The means of one policy over the campaign (the seed's comparison).
struct PolicyStats {
  int cycles = 0, completed = 0;
  long long violations = 0;
  Mean fill, time, energy;
};

// Table 6: the adaptive policy per week and strategy. Returns the strategies' labels.
std::set<std::string> PrintTable6(const std::vector<Row>& rows, const ProductionReportOptions& o,
                                  std::ostream& out) {
  std::set<std::string> labels;
  std::map<int, std::map<std::string, Cell>> weeks;
  std::map<std::string, Cell> all;
  for (const Row& r : rows) {
    if (r.policy != o.adaptive_policy || !r.completed) continue;
    labels.insert(r.strategy);
    weeks[r.week][r.strategy].Add(r);
    all[r.strategy].Add(r);
  }
  out << "Table 6: the adaptive policy ('" << o.adaptive_policy
      << "') per week: cycles by strategy and material, mean scooping time [s] and energy [kJ] "
         "(contact to end of scoop)\n\n| week |";
  for (const std::string& l : labels) out << " " << l << " gravel | sand | time s | energy kJ |";
  out << "\n| --- |";
  for (std::size_t k = 0; k < labels.size(); ++k) out << " --- | --- | --- | --- |";
  out << "\n";
  const auto print_cells = [&](const std::map<std::string, Cell>& cells) {
    for (const std::string& l : labels) {
      const auto it = cells.find(l);
      const Cell c = it != cells.end() ? it->second : Cell{};
      out << " " << c.gravel << " | " << c.sand << " | " << Num(c.time.value(), "%.2f") << " | "
          << Num(c.energy.value(), "%.1f") << " |";
    }
    out << "\n";
  };
  for (const auto& [week, cells] : weeks) {
    out << "| " << week << " |";
    print_cells(cells);
  }
  out << "| all |";
  print_cells(all);

  return labels;
}

// Table 7: the adaptive policy per material.
void PrintTable7(const std::vector<Row>& rows, const ProductionReportOptions& o,
                 std::ostream& out) {
  std::map<std::string, std::pair<int, int>> counts;  // JIO, Stairway
  std::map<std::string, Mean> material_time, material_energy;
  for (const Row& r : rows) {
    if (r.policy != o.adaptive_policy || !r.completed) continue;
    auto& c = counts[r.material];
    (r.strategy == "Just in & out" ? c.first : c.second) += 1;
    material_time[r.material].Add(r.time);
    material_energy[r.material].Add(r.energy);
  }
  out << "\nTable 7: the adaptive policy per material\n\n| material | Just in & out | Stairway | "
         "time s | energy kJ |\n| --- | --- | --- | --- | --- |\n";
  for (const auto& [material, c] : counts) {
    out << "| " << material << " | " << c.first << " | " << c.second << " | "
        << Num(material_time[material].value(), "%.2f") << " | "
        << Num(material_energy[material].value(), "%.1f") << " |\n";
  }
}

// Every policy on the same shifts, the adaptive against the baseline, and what was not measured.
std::map<std::string, PolicyStats> PrintPolicies(const std::vector<Row>& rows,
                                                 const ProductionReportOptions& o,
                                                 std::ostream& out) {
  // The seed's comparison: adaptive against the fixed Stairway #3 on the same shifts.
  std::map<std::string, PolicyStats> policies;
  for (const Row& r : rows) {
    PolicyStats& p = policies[r.policy];
    ++p.cycles;
    p.violations += r.violations;
    if (!r.completed) continue;
    ++p.completed;
    p.fill.Add(r.fill);
    p.time.Add(r.time);
    p.energy.Add(r.energy);
  }
  out << "\nPolicies on the same shifts\n\n| policy | cycles | completed | mean fill | scooping "
         "time s | scooping energy kJ | safety violations |\n| --- | --- | --- | --- | --- | --- | "
         "--- |\n";
  for (const auto& [name, p] : policies) {
    out << "| " << name << " | " << p.cycles << " | "
        << Num(100.0 * p.completed / std::max(1, p.cycles), "%.1f %%") << " | "
        << Num(100 * p.fill.value(), "%.1f %%") << " | " << Num(p.time.value(), "%.2f") << " | "
        << Num(p.energy.value(), "%.1f") << " | " << p.violations << " |\n";
  }
  const auto adaptive = policies.find(o.adaptive_policy);
  const auto baseline = policies.find(o.baseline_policy);
  if (adaptive != policies.end() && baseline != policies.end()) {
    const double dt = 1 - adaptive->second.time.value() / baseline->second.time.value();
    const double de = 1 - adaptive->second.energy.value() / baseline->second.energy.value();
    const double df = adaptive->second.fill.value() - baseline->second.fill.value();
    out << "\n'" << o.adaptive_policy << "' against '" << o.baseline_policy << "': scooping time "
        << Num(100 * dt, "%.1f") << " % less (seed: 22 %, goal >= 20 %), "
        << "energy " << Num(100 * de, "%.1f") << " % less (seed: 13 %, goal >= 13 %), fill "
        << Num(100 * df, "%+.1f") << " points\n";
  }

  // What the means above leave out: NULL is "not measured" (docs/results_and_reports.md), so a
  // mean is over the measured cycles only, and the reader is told how many those are.
  bool noted = false;
  for (const auto& [name, p] : policies) {
    const std::pair<const char*, const Mean*> columns[] = {
        {"fill_rate", &p.fill},
        {"scooping time (time_crowd_s + time_scoop_s)", &p.time},
        {"scooping energy (energy_crowd_kj + energy_scoop_kj)", &p.energy}};
    for (const auto& [column, mean] : columns) {
      if (mean->not_measured == 0) continue;
      if (!noted) out << "\nNot measured (NULL), left out of the means:\n";
      noted = true;
      out << "- " << name << ": " << column << ": " << mean->not_measured << " of " << p.completed
          << " completed cycles not measured, left out of the mean\n";
    }
  }

  return policies;
}

}  // namespace

int RunProductionReport(const ProductionReportOptions& o, std::ostream& out, std::ostream& err) {
  std::vector<Row> rows;
  try {
    rows = ReadRows(o.database);
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
  if (rows.empty()) {
    err << kCommand << ": " << o.database.string()
        << " holds no campaign cycles (its cycles table is empty)\n";
    return 2;
  }

  const std::set<std::string> labels = PrintTable6(rows, o, out);
  PrintTable7(rows, o, out);
  const std::map<std::string, PolicyStats> policies = PrintPolicies(rows, o, out);
  const auto baseline = policies.find(o.baseline_policy);

  // Fig. 22.
  std::vector<plot::BoxGroup> time_groups, energy_groups;
  for (const std::string& l : labels) {
    plot::BoxGroup t{l, {}}, e{l, {}};
    for (const Row& r : rows) {
      if (r.policy == o.adaptive_policy && r.completed && r.strategy == l) {
        if (r.time) t.samples.push_back(*r.time);
        if (r.energy) e.samples.push_back(*r.energy);
      }
    }
    time_groups.push_back(t);
    energy_groups.push_back(e);
  }
  if (baseline != policies.end()) {
    plot::BoxGroup t{"fixed #3", {}}, e{"fixed #3", {}};
    for (const Row& r : rows) {
      if (r.policy == o.baseline_policy && r.completed) {
        if (r.time) t.samples.push_back(*r.time);
        if (r.energy) e.samples.push_back(*r.energy);
      }
    }
    time_groups.push_back(t);
    energy_groups.push_back(e);
  }
  const std::filesystem::path png =
      o.png.empty() ? o.database.parent_path() / "production_fig22.png" : o.png;
  try {
    plot::WriteBoxPlotsPng({{"(a) scooping time per strategy", "s", time_groups},
                            {"(b) scooping energy per strategy", "kJ", energy_groups}},
                           png);
    out << "\nFig. 22: " << png.string() << "\n";
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
  return 0;
}

}  // namespace autoshovel::app
