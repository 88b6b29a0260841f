// The valve-chain identification (valve_chain_fit.h) on logs made by the plant, not by the chain
// model: `identify hydraulics --simulate DIR --format controldesk` writes the boom's step tests
// in a real machine's ControlDesk layout (plant_logs.h: two duty channels, pilot, cap/rod
// pressures, degrees, noise, stalls at the pump limit, 100 % runs from the opposite stop) with
// the truth chain in DIR/truth.overlay.yaml; they are read back through the column expressions
// a real export needs and fitted, and the fit is held against that truth. The same campaign
// without sensor noise (WriteControlDeskCampaign, zero noise: the plant's motion is the same,
// the noise is only added to what is logged) is the plant's own response, on which what the
// truth does not say directly (the steady joint rate) is measured.
//
// What the plant adds to the chain model: real hydraulics. Oil compressibility against the
// boom's inertia is a lightly damped mode (~2.4 Hz: after an 80 % step the noise-free joint rate
// starts slowly, overshoots its steady value by ~40 % and rings for seconds), which the chain's
// first-order lags cannot follow. The output-error angle fit represents it by a longer pure
// delay and a near-zero motion lag (their correlation, -0.99, is flagged by the fit): the
// fitted command -> motion delay τ_p + τ_m is 35-60 ms longer than the truth's τ_p + τ_d and
// T_m is 5-15 ms for a 60 ms spool lag. What the angle pins down is their sum, the motion
// path's equivalent (low-frequency) delay τ_p + τ_m + T_m, which is the truth's τ_p + τ_d + T_s
// to within the mode's share (see MotionDelayIsThePlantsAsTheChainSeesIt). So: the pilot delay
// is held to the truth (±10 ms); the motion delay is held to the truth from below (no motion
// before the spool opens), and its equivalent delay to the truth and to the same fit on the
// noise-free plant (noise and stalls do not move it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "generated/registry.h"
#include "identification/hydraulics/chain_report.h"
#include "identification/hydraulics/identify_hydraulics_command.h"
#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/plant_logs.h"
#include "identification/hydraulics/step_events.h"
#include "identification/hydraulics/valve_chain_fit.h"
#include "runtime/model/description.h"
#include "tests/hydraulics/controldesk_campaign.h"

namespace autoshovel::identification {
namespace {

namespace fs = std::filesystem;

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
constexpr double kDeg = 3.141592653589793 / 180;
constexpr double kBar = 1e5;
constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// The boom's channels of a ControlDesk export as docs/hydraulic_identification.md reads them:
// up minus down duty (up raises the boom angle), the two pilot channels (one is zero at a time),
// head = cap side, rod side.
LogFormat BoomColumns() {
  LogFormat format = ParseColumnsSpec(
      "time=time,command=Boom_up_duty - Boom_dn_duty,joint_angle=Boom_ang,"
      "pilot_pressure=Boom_Up_eppr_P + Boom_Dn_eppr_P,pressure_a=Boom_UpH_Cyl_P,"
      "pressure_b=Boom_DnR_Cyl_P");
  format.command_units = CommandUnits::kPercent;
  format.angle_units = AngleUnits::kDegrees;
  format.pressure_units = PressureUnits::kBar;
  return format;
}

struct Recovery {
  model::MachineDescription truth;  ///< the description with truth.overlay.yaml
  int actuator = 0;
  std::vector<HydraulicLog> logs, clean;  ///< same files, same order
  ChainIdentification fit, clean_fit;
};

std::vector<HydraulicLog> ReadAll(const std::string& dir) {
  std::vector<std::string> paths;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".csv") paths.push_back(entry.path().string());
  }
  std::sort(paths.begin(), paths.end());
  std::vector<HydraulicLog> logs;
  for (const std::string& path : paths) logs.push_back(ReadHydraulicLog(path, BoomColumns()));
  return logs;
}

Recovery Campaign() {
  Recovery r;
  // The campaign as a user writes it: 2 directions × 40…100 % × high/low load.
  const std::string dir = ::testing::TempDir() + "/plant_chain_recovery";
  testing::WriteBoomControlDeskCampaign(dir, kModels);
  model::LoadOptions load;
  load.overlays = {dir + "/truth.overlay.yaml"};
  const std::string source = model::ResolveMachineDescription("excavator_25t", kModels);
  r.truth = model::LoadMachineDescription(source, load);
  r.actuator = r.truth.ActuatorOfJoint(0);
  // The plant's own motion: the same campaign with no sensor noise.
  const std::string clean = ::testing::TempDir() + "/plant_chain_recovery_clean";
  fs::remove_all(clean);
  ControlDeskOptions quiet;
  quiet.angle_noise = quiet.pressure_noise = quiet.pilot_noise = 0;
  const model::MachineDescription machine = model::LoadMachineDescription(source);
  WriteControlDeskCampaign(machine, *generated::FindMachine("excavator_25t"), {r.actuator}, clean,
                           7, quiet);
  r.logs = ReadAll(dir);
  r.clean = ReadAll(clean);
  ChainFitOptions fit;
  fit.bootstrap = 0;  // intervals are not asserted here
  fit.validate = false;
  r.fit = IdentifyValveChain(r.logs, fit);
  r.clean_fit = IdentifyValveChain(r.clean, fit);
  NamedChain named;
  named.actuator = "boom_cylinders";
  named.chain = r.fit;
  PrintChainTable(named, std::cout);
  return r;
}

const model::Valve& TruthValve(const Recovery& r) {
  return r.truth.hydraulics.actuators[r.actuator].valve;
}

// The log of `fit_file` (a path of the noisy campaign) in `logs`, by file name.
std::size_t IndexOf(const std::vector<HydraulicLog>& logs, const std::string& fit_file) {
  const std::string name = fs::path(fit_file).filename().string();
  for (std::size_t i = 0; i < logs.size(); ++i) {
    if (fs::path(logs[i].file).filename().string() == name) return i;
  }
  return kNone;
}

// First sample at or after `from` at which `angle` has moved `threshold` from angle[from] in
// direction `sign`; kNone if it never does (NaN samples skipped).
std::size_t Crossing(const std::vector<double>& angle, std::size_t from, int sign,
                     double threshold) {
  for (std::size_t k = from; k < angle.size(); ++k) {
    if (!std::isnan(angle[k]) && sign * (angle[k] - angle[from]) >= threshold) return k;
  }
  return kNone;
}

std::size_t StepOn(const HydraulicLog& log) {
  std::size_t on = 0;
  while (on < log.size() && std::abs(log.command[on]) <= 0.02) ++on;
  return on;
}

void ReadsTheCampaignAndFitsBothDirections(const Recovery& r) {
  ASSERT_EQ(r.logs.size(), 28u);
  ASSERT_EQ(r.clean.size(), r.logs.size());
  // The two campaigns are the same motion: they differ by the angle noise (0.02°) alone.
  for (std::size_t i = 0; i < r.logs.size(); ++i) {
    ASSERT_EQ(fs::path(r.logs[i].file).filename(), fs::path(r.clean[i].file).filename());
    ASSERT_EQ(r.logs[i].size(), r.clean[i].size()) << r.logs[i].file;
    double ss = 0;
    for (std::size_t k = 0; k < r.logs[i].size(); ++k) {
      ss += std::pow(r.logs[i].joint_angle[k] - r.clean[i].joint_angle[k], 2);
    }
    EXPECT_LT(std::sqrt(ss / r.logs[i].size()), 0.03 * kDeg) << r.logs[i].file;
  }
  ASSERT_EQ(r.fit.directions.size(), 2u);
  ASSERT_EQ(r.clean_fit.directions.size(), 2u);
  for (const DirectionFit& d : r.fit.directions) {
    EXPECT_EQ(d.files.size(), 14u);
    EXPECT_EQ(d.levels, (std::vector<double>{0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0}));
    EXPECT_TRUE(d.has_pilot);
    EXPECT_TRUE(d.has_pressure);
  }
}

void PilotDelayIsTheTruth(const Recovery& r) {
  const double truth = TruthValve(r).pilot_delay;
  for (const DirectionFit& d : r.fit.directions) {
    SCOPED_TRACE(d.sign > 0 ? "up" : "down");
    EXPECT_NEAR(d.pilot_delay.value, truth, 0.010);
    // And on every duty level alone.
    for (const LevelDelay& level : d.level_delays) {
      EXPECT_NEAR(level.pilot_delay, truth, 0.010) << level.level * 100 << " %";
    }
  }
}

void MotionDelayIsThePlantsAsTheChainSeesIt(const Recovery& r) {
  const model::Valve& valve = TruthValve(r);
  const double opens = valve.pilot_delay + valve.transport_delay;  // the spool starts to open
  // The low-frequency (equivalent) delay of the motion path, pilot lag left out (both have it):
  // the truth's τ_p + τ_d + T_s, the chain's τ_p + τ_m + T_m.
  const double truth_equivalent = opens + valve.spool_time_constant;
  for (std::size_t i = 0; i < r.fit.directions.size(); ++i) {
    const DirectionFit& d = r.fit.directions[i];
    const DirectionFit& c = r.clean_fit.directions[i];
    ASSERT_EQ(d.sign, c.sign);
    SCOPED_TRACE(d.sign > 0 ? "up" : "down");
    const double delay = d.pilot_delay.value + d.motion_delay.value;
    const double equivalent = delay + d.motion_lag.value;
    const double clean_equivalent = c.pilot_delay.value + c.motion_delay.value + c.motion_lag.value;
    // How much earlier than the noise-free plant the fitted chain, run from each log's
    // measured start (FileReport::angle_fit: a chunk starts at the step), has moved the joint
    // 0.3° (levels from 50 %: at 40 % that is a rate reading): reported, not asserted (the
    // chain's delay + first-order lag starts earlier and rises slower than the oil spring).
    double lead_sum = 0;
    int lead_count = 0;
    for (const FileReport& f : d.files) {
      if (f.level < 0.5) continue;
      const std::size_t i_clean = IndexOf(r.clean, f.file);
      ASSERT_NE(i_clean, kNone) << f.file;
      const HydraulicLog& plant = r.clean[i_clean];
      const std::size_t on = StepOn(plant);
      const std::size_t moved = Crossing(plant.joint_angle, on, d.sign, 0.3 * kDeg);
      const std::size_t fitted = Crossing(f.angle_fit, on, d.sign, 0.3 * kDeg);
      ASSERT_NE(moved, kNone) << f.file;
      ASSERT_NE(fitted, kNone) << f.file;
      lead_sum += plant.time[moved] - f.time[fitted];
      ++lead_count;
    }
    std::printf(
        "%s: command -> motion delay tau_p + tau_m %.1f ms (noise-free plant %.1f ms; truth "
        "tau_p + tau_d %.1f ms), motion lag T_m %.1f ms (noise-free %.1f; truth T_s %.1f ms); "
        "equivalent tau_p + tau_m + T_m %.1f ms (noise-free %.1f; truth %.1f ms); the fitted "
        "chain moves 0.3 deg %.0f ms before the plant (mean, levels >= 50 %%)\n",
        d.sign > 0 ? "up" : "down", delay * 1e3, (c.pilot_delay.value + c.motion_delay.value) * 1e3,
        opens * 1e3, d.motion_lag.value * 1e3, c.motion_lag.value * 1e3,
        valve.spool_time_constant * 1e3, equivalent * 1e3, clean_equivalent * 1e3,
        truth_equivalent * 1e3, lead_count ? 1e3 * lead_sum / lead_count : 0.0);
    // Not before the spool opens.
    EXPECT_GE(delay, opens - 0.010);
    // The equivalent delay is the truth's: ±10 ms, and the oil-spring mode's own share of it,
    // which the chain has no term for. Lowering (down) it is 2ζ/ω ≈ 2·0.045/15 rad/s ≈ 6 ms
    // (the noise-free 80 % step rings at 2.4 Hz, its overshoot decaying to 0.76 per period).
    // Lifting (up) it is larger since the valve sections have load check valves (issue 41): the
    // cap chamber's overshoot over its supply, which an open spool used to vent back into the
    // supply line, now stays, and the lift gets under way sooner than the chain alone says
    // (noise-free plant 225.5 ms against the truth chain's 250 ms; 234–250 ms before).
    EXPECT_NEAR(equivalent, truth_equivalent, d.sign > 0 ? 0.030 : 0.016);
    // Sensor noise does not move it: the same fit on the noise-free plant.
    EXPECT_NEAR(equivalent, clean_equivalent, 0.010);
  }
}

// The cylinder's distance from the end of stroke it runs to in direction `sign` (positive
// commands extend the boom cylinders) at boom angle `q` [m].
double FromStop(const Recovery& r, int sign, double q) {
  const generated::MachineFunctions& functions = *generated::FindMachine("excavator_25t");
  const model::Actuator& act = r.truth.hydraulics.actuators[r.actuator];
  std::vector<double> joints(r.truth.num_joints(), 0.0);  // the boom's cylinder spans chassis–boom
  joints[0] = q;
  const double length = functions.cylinder_length(r.actuator, joints.data());
  return sign > 0 ? act.retracted_length + act.stroke - length : length - act.retracted_length;
}

// The flow characteristic. The fitted O_j = DirectionFit::rates[j] is the steady joint rate at
// level j at the logs' centre angle and mean load; the chain's steady rate elsewhere is
// O_j·G(q)·L(p_L) (valve_chain_model.h). Most levels never pass the centre angle (their steps
// start 40 % of the stroke from the stop they run to), and the plant's rate rings about its
// steady value (the ~2.4 Hz oil-spring mode) and changes over the stroke with the cylinder's
// lever, so the plant's steady rate at level j is measured where the plant was: over a window of
// each noise-free log from 1 s after the motion onset (the transient has decayed to a ring a
// window of several periods averages out) to where the cylinder enters its last 5 % of stroke
// (the end cushion), referred to the knot's conditions through the fitted G and L,
//   plant O_j = |Δq over the window| / ∫ G(q(t))·L(p_L(t)) dt,
// with the plant's own noise-free angle and pressures in G and L. The fitted O_j must be
// within 5 % of that, the level's logs at both loads pooled (the truth curve × the flow law
// would not be exact: the compensator holds the drop across the spool only to within its
// ±2 bar band of the 15 bar margin, and a lowering boom is metered out against its load).
void FlowCharacteristicIsThePlants(const Recovery& r) {
  const ChainFitOptions defaults;
  for (const DirectionFit& d : r.fit.directions) {
    SCOPED_TRACE(d.sign > 0 ? "up" : "down");
    // Per level, both loads pooled (the fitted O_j is at the mean load): Σ|Δq|, Σ∫G·L dt.
    std::vector<std::pair<double, double>> pooled(d.levels.size(), {0.0, 0.0});
    for (const FileReport& f : d.files) {
      const std::size_t i = IndexOf(r.clean, f.file);
      ASSERT_NE(i, kNone) << f.file;
      const HydraulicLog& plant = r.clean[i];
      const std::size_t j =
          std::find_if(d.levels.begin(), d.levels.end(),
                       [&](double level) { return std::abs(level - f.level) < 1e-9; }) -
          d.levels.begin();
      ASSERT_LT(j, d.levels.size()) << f.file;
      const std::size_t on = StepOn(plant);
      std::size_t off = on;
      while (off < plant.size() && std::abs(plant.command[off]) > 0.02) ++off;
      const std::size_t onset = Crossing(plant.joint_angle, on, d.sign, 0.3 * kDeg);
      ASSERT_NE(onset, kNone) << f.file;
      std::size_t a = onset;
      while (a < off && plant.time[a] < plant.time[onset] + 0.6) ++a;
      const double cushion = 0.05 * r.truth.hydraulics.actuators[r.actuator].stroke;
      std::size_t b = a;
      while (b + 1 < off && FromStop(r, d.sign, plant.joint_angle[b + 1]) > cushion) ++b;
      if (b <= a || plant.time[b] - plant.time[a] < 0.8) continue;  // two periods of the ring
      double shape = 0;                                             // ∫ G·L dt
      auto gain_load = [&](std::size_t k) {
        double z = (plant.joint_angle[k] - d.angle_center) / d.angle_half_range;
        z = std::clamp(z, -1.0, 1.0);
        const double p_load = plant.pressure_a[k] - defaults.area_ratio * plant.pressure_b[k];
        const double inside =
            1.0 + d.load_coefficient.value * (p_load - d.load_reference) / (100 * kBar);
        return std::exp(d.gain_linear.value * z + d.gain_quadratic.value * z * z) *
               std::sqrt(std::max(0.05, inside));
      };
      for (std::size_t k = a; k < b; ++k) {
        shape += 0.5 * (gain_load(k) + gain_load(k + 1)) * (plant.time[k + 1] - plant.time[k]);
      }
      const double moved = std::abs(plant.joint_angle[b] - plant.joint_angle[a]);
      std::printf("%s %-18s window %5.2f-%5.2f s  %7.2f..%7.2f deg: plant %7.3f deg/s\n",
                  d.sign > 0 ? "up  " : "down", fs::path(f.file).filename().c_str(), plant.time[a],
                  plant.time[b], plant.joint_angle[a] / kDeg, plant.joint_angle[b] / kDeg,
                  moved / shape / kDeg);
      pooled[j].first += moved;
      pooled[j].second += shape;
    }
    for (std::size_t j = 0; j < d.levels.size(); ++j) {
      ASSERT_GT(pooled[j].second, 0.0) << d.levels[j] * 100 << " %: no window";
      const double plant_rate = pooled[j].first / pooled[j].second;
      const double fitted = d.rates[j].value;
      // The lowest level lies 1–3 % duty above the dead band (openings 6 % up, 1.8 % down, at
      // 0.7 and 0.4°/s): there the fit comes out up to 6 % low on the lowering boom (an open
      // finding, not understood yet); 8 % there, 5 % everywhere else.
      const double tolerance = j == 0 ? 0.08 : 0.05;
      std::printf("%s %3.0f %%: plant %7.3f deg/s, fitted %7.3f deg/s (%+.1f %%)\n",
                  d.sign > 0 ? "up  " : "down", d.levels[j] * 100, plant_rate / kDeg, fitted / kDeg,
                  100 * (fitted / plant_rate - 1));
      EXPECT_NEAR(fitted / plant_rate, 1.0, tolerance) << d.levels[j] * 100 << " %";
    }
  }
}

// The stalls the fit leaves out (step_events.h), against the noise-free plant: every log whose
// joint runs into its stop has stalled samples, no sample is stalled before the cylinder is at
// its end of stroke (1 % of the stroke, as the simulator judges it), and the pressure read as
// relief is the plant's limit: the load-sensing pump's maximum (the stall holds the driving
// chamber there, below the cylinder's relief valve).
void StallsAreTheStops(const Recovery& r) {
  const ChainFitOptions defaults;
  const double pump = r.truth.hydraulics.pump_pressure;
  const double stroke = r.truth.hydraulics.actuators[r.actuator].stroke;
  int stalling = 0;
  for (const DirectionFit& d : r.fit.directions) {
    SCOPED_TRACE(d.sign > 0 ? "up" : "down");
    for (const FileReport& f : d.files) {
      const std::size_t i = IndexOf(r.clean, f.file);
      ASSERT_NE(i, kNone) << f.file;
      const HydraulicLog& plant = r.clean[i];
      const std::size_t noisy = IndexOf(r.logs, f.file);
      ASSERT_NE(noisy, kNone) << f.file;
      // The fit's stalls, sample by sample (the fit reads them with these options).
      const LogEvents events = DetectStepEvents(r.logs[noisy], defaults.events);
      EXPECT_EQ(events.stalled_samples, f.stalled) << f.file;
      bool reaches = false;
      for (std::size_t k = 0; k < plant.size(); ++k) {
        const bool at_stop = FromStop(r, d.sign, plant.joint_angle[k]) < 0.01 * stroke;
        if (std::abs(plant.command[k]) > 0.02 && at_stop) reaches = true;
        if (events.stalled[k]) {
          EXPECT_TRUE(at_stop) << f.file << ": stalled at " << plant.time[k] << " s, cylinder "
                               << FromStop(r, d.sign, plant.joint_angle[k]) * 1e3
                               << " mm from its stop";
        }
      }
      if (reaches) {
        ++stalling;
        EXPECT_GT(f.stalled, 0u) << f.file;
        EXPECT_NEAR(f.relief_seen, pump, 0.05 * pump) << f.file;
      } else {
        EXPECT_EQ(f.stalled, 0u) << f.file << ": never reaches its stop";
      }
    }
  }
  // 60…100 % in both directions and both loads run into the stop.
  EXPECT_GE(stalling, 20);
}

// Into the plant (chain_report.h, AssignPlantFlow): the overlay's rated flow and per-direction
// opening shares must give back the plant's own flow law. The campaign's plant has 420 l/min at
// full spool, full opening extending and 0.85 of it retracting (truth.overlay.yaml): the rated
// flow is the extending one, and the retraction's share its 0.85. Before the shares, one rated
// flow served both directions and a retraction ran at the full opening (share 1.0).
void PlantFlowIsThePlants(const Recovery& r) {
  NamedChain named;
  named.chain = r.fit;
  AssignPlantFlow(named, r.truth, *generated::FindMachine("excavator_25t"), r.actuator);
  const double truth_lpm = TruthValve(r).rated_flow / (1e-3 / 60);
  std::printf("plant flow: rated %.1f l/min (truth %.1f); %s\n", named.rated_flow_lpm, truth_lpm,
              named.rated_flow_note.c_str());
  ASSERT_EQ(named.opening_scale.size(), r.fit.directions.size());
  // The identified rates are the plant's within 2.5 % (8 % at 40 % down, FlowCharacteristic…);
  // the rated flow and the share carry that error and the lever's change over the logs' range.
  EXPECT_NEAR(named.rated_flow_lpm / truth_lpm, 1.0, 0.05);
  for (std::size_t k = 0; k < r.fit.directions.size(); ++k) {
    const double truth_share = r.fit.directions[k].sign > 0 ? 1.0 : 0.85;
    EXPECT_NEAR(named.opening_scale[k], truth_share, 0.05) << "sign " << r.fit.directions[k].sign;
  }
}

// One test (ctest runs each in its own process, and the campaign is the cost: ~2 s to write,
// ~2 s noise-free, ~10 s for the two fits on one core).
TEST(PlantChainRecovery, RecoversThePlantsChainFromControlDeskLogs) {
  const Recovery r = Campaign();
  {
    SCOPED_TRACE("ReadsTheCampaignAndFitsBothDirections");
    ReadsTheCampaignAndFitsBothDirections(r);
  }
  {
    SCOPED_TRACE("PilotDelayIsTheTruth");
    PilotDelayIsTheTruth(r);
  }
  {
    SCOPED_TRACE("MotionDelayIsThePlantsAsTheChainSeesIt");
    MotionDelayIsThePlantsAsTheChainSeesIt(r);
  }
  {
    SCOPED_TRACE("FlowCharacteristicIsThePlants");
    FlowCharacteristicIsThePlants(r);
  }
  {
    SCOPED_TRACE("StallsAreTheStops");
    StallsAreTheStops(r);
  }
  {
    SCOPED_TRACE("PlantFlowIsThePlants");
    PlantFlowIsThePlants(r);
  }
}

}  // namespace
}  // namespace autoshovel::identification
