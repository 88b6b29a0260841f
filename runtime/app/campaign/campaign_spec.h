// A production campaign (issue 8; wheel-loader seed §7.5, Tables 6–7): weeks of a yard's work,
// shift after shift, each shift once per scooping policy so that the policies meet the same
// piles. Read strictly from YAML; every problem is reported as `file:line:column: key: what`.
//
//   name: mixing_station_production   # names the runs: <name>/w01s03/<policy>
//   scenario: mixing_station          # yard (models/scenarios) and its machine
//   machine: xcmg_968ev               # optional: another wheel loader
//   seed: 1                           # each shift's seed derives from it
//   weeks: 4
//   shifts_per_week: 21
//   cycles_per_shift: 12              # the yard persists across a shift's cycles (piles dug);
//                                     # each shift starts from the scenario's yard (restocked)
//   policies: [auto, stairway_fixed]  # auto | just_in_out | stairway | stairway_fixed
//   stairway_steps: 3                 # N of "Stairway #N" (stairway_fixed)
//   trigger: predicted                # predicted | perception | pressure
//   truth_labels: true                # simulator labels instead of the network (faster)
//   attack_speed: 1.5                 # scoop profile (app::ShovelRunOptions): attack [m/s],
//   scoop_deceleration: 0.6           # speed reference's fall once the arm moves [m/s²], and
//   predictor: penetration_svr_fast   # its model: a name under <models>/prediction, or a path
//                                     # stem; all three default to the main job's
//   yard_variation: 0.25              # each shift's piles up to 25 % lower than written, and
//                                     # irregular heaps re-seeded (plant::VaryPiles); default 0
//   faults: [...]                     # injected faults, as in a scenario (plant/fault_spec.h)
//   max_cycle_time_s: 40              # a cycle not done by then ends incomplete; default 120
//
// A fault campaign (issue 9) runs every shift on several yards and under several fault cases,
// each a named list of faults on top of `faults`; the summary is then a fault × scenario table
// (also stored as the view `fault_summary` in results.sqlite):
//
//   scenarios: [mixing_station, pile_behind_loader]   # instead of `scenario`
//   fault_cases:
//     - name: none                    # no fault: the reference row
//     - name: lidar_dropout
//       faults:
//         - {kind: lidar_dropout, start_s: 2.0, duration_s: 1.5}
//
// Runs are then named <name>/<scenario>/<case>/wWWsSS/<policy>; a shift's seed is the same on
// every yard and under every case, so that each case meets the very yards of "none".
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/control/scoop_cycle.h"
#include "runtime/plant/fault_spec.h"

namespace autoshovel::app {

/// A named set of faults of a fault campaign.
struct FaultCase {
  std::string name;
  std::vector<plant::FaultSpec> faults;
};

struct CampaignSpec {
  std::string source_file;
  std::string name;
  std::string scenario;                ///< the first of `scenarios`
  std::vector<std::string> scenarios;  ///< `scenario`, or the `scenarios` list
  std::string machine;                 ///< empty: the scenario's
  std::uint64_t seed = 1;
  int weeks = 1;
  int shifts_per_week = 1;
  int cycles_per_shift = 1;
  std::vector<std::string> policies;  ///< as written: auto, just_in_out, stairway, stairway_fixed
  int stairway_steps = 3;
  std::string trigger = "predicted";
  bool truth_labels = true;
  double attack_speed = NAN;        ///< [m/s]; NaN: the main job's
  double scoop_deceleration = NAN;  ///< [m/s²]; NaN: the main job's
  std::string predictor;            ///< as written; empty: the main job's
  double yard_variation = 0;
  double max_cycle_time_s = 120;
  /// Faults every shift's cycles meet (plant/fault_spec.h), on top of the scenario's own.
  std::vector<plant::FaultSpec> faults;
  std::vector<FaultCase> fault_cases;  ///< empty: not a fault campaign

  /// Run ids carry the scenario and the fault case (several yards, or fault cases).
  bool matrix() const { return scenarios.size() > 1 || !fault_cases.empty(); }
  int cases() const { return fault_cases.empty() ? 1 : static_cast<int>(fault_cases.size()); }
  int shifts() const { return weeks * shifts_per_week; }
  int jobs() const {
    return shifts() * std::max<int>(1, static_cast<int>(scenarios.size())) * cases() *
           static_cast<int>(policies.size());
  }
  long long cycles() const { return static_cast<long long>(jobs()) * cycles_per_shift; }
};

/// Reads and validates a campaign file. Throws core::InputError with every problem found.
CampaignSpec LoadCampaignSpec(const std::string& path);

/// Whether two campaign files say the same thing: their YAML trees are equal once parsed, so
/// comments, blank lines and quoting/flow style do not count, while any key or value does
/// (a number is compared as written: 0.1 and 0.10 differ, which only ever refuses a resume).
/// False when either file does not parse.
bool SameCampaignContent(const std::string& path_a, const std::string& path_b);

control::ScoopPolicy ParseScoopPolicy(const std::string& name);

/// One unit of work: a shift under one policy (on one yard, under one fault case),
/// `cycles_per_shift` cycles in one yard.
struct CampaignJob {
  int index = 0;  ///< 0 … jobs − 1, shift-major
  int week = 0;   ///< 1-based
  int shift = 0;  ///< 1-based within the week
  std::string policy;
  std::string scenario;
  std::string fault_case;                ///< "" outside a fault campaign
  std::vector<plant::FaultSpec> faults;  ///< the spec's and the case's
  std::string run_id;      ///< <name>/wWWsSS/<policy>, or <name>/<scenario>/<case>/wWWsSS/<policy>
  std::uint64_t seed = 0;  ///< the shift's seed: the same for every policy of the shift
};

std::vector<CampaignJob> CampaignJobs(const CampaignSpec& spec);

}  // namespace autoshovel::app
