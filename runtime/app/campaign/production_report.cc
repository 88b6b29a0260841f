#include "runtime/app/campaign/production_report.h"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <ostream>
#include <set>
#include <vector>

#include "runtime/plot/box_plot.h"

namespace autoshovel::app {
namespace {

constexpr const char* kCommand = "autoshovel report production";

struct Row {
  int week = 0;
  std::string policy, material, strategy;
  bool gravel = false;
  double fill = NAN, time = NAN, energy = NAN;  ///< scooping: contact to end of scoop [s, kJ]
  bool completed = false;
  int violations = 0;
};

std::string Text(sqlite3_stmt* s, int column) {
  const unsigned char* t = sqlite3_column_text(s, column);
  return t != nullptr ? reinterpret_cast<const char*>(t) : "";
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

struct Mean {
  double sum = 0;
  int n = 0;
  void Add(double v) {
    if (std::isfinite(v)) sum += v, ++n;
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

}  // namespace

int RunProductionReport(const ProductionReportOptions& o, std::ostream& out, std::ostream& err) {
  if (!std::filesystem::is_regular_file(o.database)) {
    err << kCommand << ": " << o.database.string() << ": no such file\n";
    return 2;
  }
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(o.database.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    err << kCommand << ": " << o.database.string() << ": " << sqlite3_errmsg(db) << "\n";
    sqlite3_close(db);
    return 2;
  }
  const char* sql =
      "SELECT r.week, r.policy, c.material, c.strategy, c.atomic_actions, c.fill_rate, "
      "c.completed, c.time_crowd_s + c.time_scoop_s, c.energy_crowd_kj + c.energy_scoop_kj, "
      "c.safety_violations FROM cycles c JOIN campaign_runs r USING (run_id) "
      "ORDER BY r.week, c.run_id, c.cycle";
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &s, nullptr) != SQLITE_OK) {
    err << kCommand << ": " << o.database.string()
        << ": not a campaign database (no cycles or campaign_runs table: " << sqlite3_errmsg(db)
        << ")\n";
    sqlite3_close(db);
    return 2;
  }
  std::vector<Row> rows;
  while (sqlite3_step(s) == SQLITE_ROW) {
    Row r;
    r.week = sqlite3_column_int(s, 0);
    r.policy = Text(s, 1);
    r.material = Text(s, 2);
    r.gravel = r.material.find("gravel") != std::string::npos;
    r.completed = sqlite3_column_int(s, 6) != 0;
    if (r.completed) {
      r.strategy = StrategyLabel(Text(s, 3), Text(s, 4));
      r.fill = sqlite3_column_double(s, 5);
      r.time = sqlite3_column_double(s, 7);
      r.energy = sqlite3_column_double(s, 8);
    }
    r.violations = sqlite3_column_int(s, 9);
    rows.push_back(r);
  }
  sqlite3_finalize(s);
  sqlite3_close(db);
  if (rows.empty()) {
    err << kCommand << ": " << o.database.string() << " holds no campaign cycles\n";
    return 2;
  }

  // Table 6: the adaptive policy per week and strategy.
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

  // Table 7: per material.
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

  // The seed's comparison: adaptive against the fixed Stairway #3 on the same shifts.
  struct PolicyStats {
    int cycles = 0, completed = 0, violations = 0;
    Mean fill, time, energy;
  };
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

  // Fig. 22.
  std::vector<plot::BoxGroup> time_groups, energy_groups;
  for (const std::string& l : labels) {
    plot::BoxGroup t{l, {}}, e{l, {}};
    for (const Row& r : rows) {
      if (r.policy == o.adaptive_policy && r.completed && r.strategy == l) {
        t.samples.push_back(r.time);
        e.samples.push_back(r.energy);
      }
    }
    time_groups.push_back(t);
    energy_groups.push_back(e);
  }
  if (baseline != policies.end()) {
    plot::BoxGroup t{"fixed #3", {}}, e{"fixed #3", {}};
    for (const Row& r : rows) {
      if (r.policy == o.baseline_policy && r.completed) {
        t.samples.push_back(r.time);
        e.samples.push_back(r.energy);
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
