// `autoshovel compare audit` (energy_audit_command.h).
#include "runtime/app/energy_audit_command.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/app/compare_run_options.h"
#include "runtime/app/shovel_run.h"
#include "runtime/core/file_output.h"
#include "runtime/core/strings.h"
#include "runtime/plot/stacked_area_plot.h"

namespace autoshovel::app {

namespace {

using plant::EnergyAudit;
using plant::EnergyTerm;

struct Case {
  const char* material;  ///< as the seed names it
  const char* bin;
  control::ScoopPolicy policy;
  const char* policy_name;
  double seed_time, seed_energy_kj;  ///< the seed's field figures for that scoop (Tables 6–7)
};

// The seed's measured scoops (contact to the end of the scooping motion, travel + hydraulic
// motor): "Just in & out" on gravel 4.95 s / 202 kJ, Stairway on sand 5.38 s / 242 kJ (Tables
// 6–7). "Just in & out" on sand is the seed's Table 5 row that filled 82.4 % (§7.4); its time and
// energy are not given (NaN).
constexpr Case kCases[] = {
    {"gravel", "bin_1", control::ScoopPolicy::kJustInOut, "Just in & out", 4.95, 202.0},
    {"sand", "bin_4", control::ScoopPolicy::kAutoSelection, "auto-selection", 5.38, 242.0},
    {"sand", "bin_4", control::ScoopPolicy::kJustInOut, "Just in & out", NAN, NAN},
};

// The plot's groups of terms, bottom of the stack first.
struct Group {
  const char* name;
  std::vector<EnergyTerm> terms;
};

const std::vector<Group>& PlotGroups() {
  static const std::vector<Group> groups = {
      {"lifting (potential energy)", {EnergyTerm::kLifting}},
      {"soil cutting and lifting (arm + drive)",
       {EnergyTerm::kSoilByArm, EnergyTerm::kSoilByDrive}},
      {"arm kinetic, friction, end stops, oil compression",
       {EnergyTerm::kArmKinetic, EnergyTerm::kArmFriction, EnergyTerm::kEndStops,
        EnergyTerm::kCompression}},
      {"throttling into the cylinders (compensator, LS margin, backflow)",
       {EnergyTerm::kCompensator, EnergyTerm::kMeterIn, EnergyTerm::kBackflow}},
      {"meter-out throttling and relief", {EnergyTerm::kMeterOut, EnergyTerm::kRelief}},
      {"pump and pump motor loss", {EnergyTerm::kPumpLoss}},
      {"tyre slip", {EnergyTerm::kTyreSlip}},
      {"rolling resistance", {EnergyTerm::kRolling}},
      {"machine kinetic energy", {EnergyTerm::kMachineKinetic}},
      {"drive motor and drivetrain loss, brake, not recovered",
       {EnergyTerm::kTravelDriveLoss, EnergyTerm::kTravelNotRecovered, EnergyTerm::kBrake}},
  };
  return groups;
}

// Okabe–Ito for the first seven groups, then three darker tones that stay apart from them.
plot::Color GroupColor(int g) {
  static constexpr plot::Color kExtra[] = {{110, 110, 110}, {30, 60, 120}, {110, 40, 110}};
  return g < 7 ? plot::PaletteColor(g) : kExtra[(g - 7) % 3];
}

double GroupValue(const EnergyAudit& a, const Group& g) {
  double sum = 0;
  for (EnergyTerm t : g.terms) sum += a[t];
  return sum;
}

struct CaseResult {
  int cycles = 0, completed = 0;
  std::map<std::string, EnergyAudit> phases;  ///< summed over completed cycles [J]
  double crowd_time = 0, scoop_time = 0, fill = 0;
  double drawn_contact_to_end = 0;  ///< the energy counters' crowd + scoop [J], summed
  std::vector<std::string> strategies;
  // Seed 1, for the figure and the CSV.
  std::vector<plant::EnergyAuditSample> trace;
  double contact_time = NAN, trigger_time = NAN, scoop_end_time = NAN;
};

using core::Fixed;

void PrintTable(const Case& c, const CaseResult& r, const std::string& machine, std::ostream& out) {
  const double n = std::max(1, r.completed);
  auto phase = [&](const char* name) {
    const auto it = r.phases.find(name);
    EnergyAudit a = it == r.phases.end() ? EnergyAudit{} : it->second;
    for (double& v : a.terms) v /= n;
    return a;
  };
  const EnergyAudit crowd = phase("crowd"), scoop = phase("scoop");
  EnergyAudit seed_phase = crowd;
  seed_phase += scoop;
  EnergyAudit cycle;
  for (const auto& [name, a] : r.phases) cycle += a;
  for (double& v : cycle.terms) v /= n;
  const double total = seed_phase.total();

  out << "Energy audit: " << c.policy_name << " on " << c.material << " (mixing_station " << c.bin
      << (machine.empty() ? std::string() : ", machine " + machine) << "), " << r.completed << "/"
      << r.cycles << " cycles completed; strategies " <<
      [&] {
        std::string s;
        for (const std::string& k : r.strategies) s += (s.empty() ? "" : " ") + k;
        return s;
      }()
      << ". Means in kJ; the seed's phase is bucket contact to the end of the scooping motion "
         "(crowd + scoop), travel + hydraulic.\n\n";
  out << "| term | crowd | scoop | contact → scoop end | share % | whole cycle |\n"
         "| --- | --- | --- | --- | --- | --- |\n";
  auto row = [&](const std::string& name, double a, double b, double s, double w, bool bold) {
    const std::string open = bold ? "**" : "";
    out << "| " << open << name << open << " | " << Fixed(a / 1e3, 1) << " | " << Fixed(b / 1e3, 1)
        << " | " << open << Fixed(s / 1e3, 1) << open << " | "
        << (total > 0 ? Fixed(100 * s / total, 1) : "-") << " | " << Fixed(w / 1e3, 1) << " |\n";
  };
  for (const bool travel : {true, false}) {
    for (int k = 0; k < plant::kEnergyTermCount; ++k) {
      const auto t = static_cast<EnergyTerm>(k);
      if (plant::IsTravelTerm(t) != travel) continue;
      row(std::string(travel ? "travel: " : "hydraulic: ") + plant::EnergyTermName(t), crowd[t],
          scoop[t], seed_phase[t], cycle[t], false);
    }
    if (travel) {
      row("travel drive, total", crowd.travel(), scoop.travel(), seed_phase.travel(),
          cycle.travel(), true);
    } else {
      row("hydraulic pump, total", crowd.hydraulic(), scoop.hydraulic(), seed_phase.hydraulic(),
          cycle.hydraulic(), true);
    }
  }
  row("of which useful cylinder work", crowd.cylinder_work(), scoop.cylinder_work(),
      seed_phase.cylinder_work(), cycle.cylinder_work(), false);
  row("soil cutting and lifting, drive + arm", crowd.soil(), scoop.soil(), seed_phase.soil(),
      cycle.soil(), false);
  row("total (sum of the terms)", crowd.total(), scoop.total(), seed_phase.total(), cycle.total(),
      true);
  out << "\nContact → scoop end: " << Fixed((r.crowd_time + r.scoop_time) / n, 2) << " s and "
      << Fixed(total / 1e3, 1) << " kJ by the audit, " << Fixed(r.drawn_contact_to_end / n / 1e3, 1)
      << " kJ by the plant's energy counters ("
      << (std::isnan(c.seed_time) ? std::string("the seed gives no time or energy for this row")
                                  : "seed, measured: " + Fixed(c.seed_time, 2) + " s, " +
                                        Fixed(c.seed_energy_kj, 0) + " kJ")
      << "); fill " << Fixed(100 * r.fill / n, 1) << " %.\n\n";
}

// audit_gravel_just_in_out, audit_sand_auto_selection, …
std::string FileStem(const Case& c) {
  std::string policy;
  for (const char* p = c.policy_name; *p != '\0'; ++p) {
    const char ch = *p;
    if (std::isalnum(static_cast<unsigned char>(ch))) {
      policy += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    } else if (!policy.empty() && policy.back() != '_') {
      policy += '_';
    }
  }
  while (!policy.empty() && policy.back() == '_') policy.pop_back();
  return std::string("audit_") + c.material + "_" + policy;
}

void WriteFigures(const Case& c, const CaseResult& r, const std::filesystem::path& dir) {
  if (r.trace.empty() || std::isnan(r.contact_time)) return;
  const double t0 = r.contact_time - 1.0, t1 = r.scoop_end_time + 1.0;
  // Cumulative since contact (the trace sample at or just before it).
  EnergyAudit at_contact = r.trace.front().cumulative;
  for (const auto& s : r.trace) {
    if (s.time <= r.contact_time + 1e-9) at_contact = s.cumulative;
  }
  const std::vector<Group>& groups = PlotGroups();
  plot::StackedAreaPlot energy, power;
  energy.title = std::string("Energy since bucket contact: ") + c.policy_name + " on " +
                 c.material + " (seed 1)";
  energy.x_label = "time since contact [s]";
  energy.y_label = "energy [kJ]";
  power.title = "Power by group (50 ms means; a group giving energy back draws as 0)";
  power.x_label = energy.x_label;
  power.y_label = "power [kW]";
  // Wide enough that the legend on the right leaves the time axis room.
  energy.width_px = power.width_px = 1500;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    energy.series.push_back({groups[g].name, {}, GroupColor(static_cast<int>(g))});
    power.series.push_back({groups[g].name, {}, GroupColor(static_cast<int>(g))});
  }
  constexpr int kLag = 5;  // ticks over which the power is averaged
  for (std::size_t i = 0; i < r.trace.size(); ++i) {
    const auto& s = r.trace[i];
    if (s.time < t0 || s.time > t1 || i < kLag) continue;
    const auto& before = r.trace[i - kLag];
    const double dt = s.time - before.time;
    energy.x.push_back(s.time - r.contact_time);
    power.x.push_back(s.time - r.contact_time);
    for (std::size_t g = 0; g < groups.size(); ++g) {
      energy.series[g].values.push_back(
          (GroupValue(s.cumulative, groups[g]) - GroupValue(at_contact, groups[g])) / 1e3);
      power.series[g].values.push_back(
          (GroupValue(s.cumulative, groups[g]) - GroupValue(before.cumulative, groups[g])) / dt /
          1e3);
    }
  }
  for (plot::StackedAreaPlot* p : {&energy, &power}) {
    p->vertical = {{0.0, "contact"},
                   {r.trigger_time - r.contact_time, "trigger"},
                   {r.scoop_end_time - r.contact_time, "scoop end"}};
  }
  plot::WriteStackedAreaPlotsPng({energy, power}, dir / (FileStem(c) + ".png"));

  std::ostringstream csv;
  csv << "time_s,phase";
  for (int k = 0; k < plant::kEnergyTermCount; ++k) {
    std::string name = plant::EnergyTermName(static_cast<EnergyTerm>(k));
    std::replace(name.begin(), name.end(), ',', ';');
    csv << "," << name << " [J]";
  }
  csv << "\n";
  char cell[64];
  for (const auto& s : r.trace) {
    std::snprintf(cell, sizeof cell, "%.3f", s.time);
    csv << cell << "," << s.phase;
    for (double v : s.cumulative.terms) {
      std::snprintf(cell, sizeof cell, ",%.1f", v);
      csv << cell;
    }
    csv << "\n";
  }
  core::WriteFileAtomically(dir / (FileStem(c) + ".csv"), csv.str());
}

}  // namespace

int RunEnergyAudit(const CompareOptions& o, const std::filesystem::path& output_dir,
                   std::ostream& out, std::ostream& err) {
  if (o.trials < 1) {
    err << "autoshovel compare audit: --trials must be >= 1\n";
    return 2;
  }
  const auto started = std::chrono::steady_clock::now();
  int status = 0;
  try {
    if (!output_dir.empty()) core::CreateFolders(output_dir);
    for (const Case& c : kCases) {
      CaseResult r;
      for (int t = 1; t <= o.trials; ++t) {
        ShovelRunOptions options = SingleCycleRunOptions(o);
        options.scenario = "mixing_station";
        options.bins = {c.bin};
        options.policy = c.policy;
        options.seed = static_cast<std::uint64_t>(t);
        options.energy_audit = true;
        ShovelJob job(options);
        if (const std::string m = job.PredictorMachineMismatch(); !m.empty() && t == 1) {
          err << "autoshovel compare audit: warning: " << m << "\n";
        }
        const CycleOutcome cycle = job.RunCycle(0, {}, nullptr);
        ++r.cycles;
        err << "  " << c.material << " seed " << t << ": "
            << (cycle.record.completed ? "completed" : cycle.failure) << "\n";
        if (!cycle.record.completed) {
          status = 1;
          continue;
        }
        ++r.completed;
        for (const auto& [name, a] : cycle.energy_audit_by_phase) r.phases[name] += a;
        r.crowd_time += cycle.record.time_s.crowd;
        r.scoop_time += cycle.record.time_s.scoop;
        r.drawn_contact_to_end += cycle.scoop.ContactToScoopEndEnergy();
        r.fill += cycle.record.fill_rate;
        if (std::find(r.strategies.begin(), r.strategies.end(), cycle.record.strategy) ==
            r.strategies.end()) {
          r.strategies.push_back(cycle.record.strategy);
        }
        if (r.trace.empty()) {
          r.trace = cycle.energy_audit_trace;
          const control::PhaseRecord* crowd = cycle.scoop.Phase("crowd");
          const control::PhaseRecord* scoop = cycle.scoop.Phase("scoop");
          if (crowd != nullptr && scoop != nullptr) {
            r.contact_time = crowd->start;
            r.trigger_time = scoop->start;
            r.scoop_end_time = scoop->start + scoop->duration;
          }
        }
      }
      PrintTable(c, r, o.machine, out);
      if (!output_dir.empty()) WriteFigures(c, r, output_dir);
      out << std::flush;
    }
  } catch (const std::exception& e) {
    err << "autoshovel compare audit: " << e.what() << "\n";
    return 2;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  out << "(" << Fixed(seconds, 1) << " s";
  if (!output_dir.empty()) out << "; figures and per-tick terms in " << output_dir.string();
  out << ")\n";
  return status;
}

}  // namespace autoshovel::app
