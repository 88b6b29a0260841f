// Issue 39, item 6: a boom that stalls under load while its working pressure is at the most the
// supply holds is a stall, not a stuck valve (app/safety_supervisor.h, docs/faults.md). The
// supervisor tells the two apart by the pressure of the chamber the valve feeds; the scoop cycle
// answers a stall by holding the joint and ending the scoop, keeping the load
// (control::ScoopCycle::JointStalledUnderLoad). Synthetic state sequences for the rule, then
// the plant: a machine whose pump cannot lift a full bucket of sand out of the pile, and a
// jammed boom spool on the nominal machine.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "runtime/app/safety_supervisor.h"
#include "runtime/control/scoop_cycle.h"
#include "tests/control/control_test_support.h"

namespace autoshovel::control {
namespace {

using app::JointCheck;
using app::JointRange;
using app::JointReading;
using app::JointState;
using app::SafetySupervisor;
using app::StallLimit;

constexpr const char* kMachine = "xcmg_968ev";
constexpr double kBar = 1e5;

// The XCMG's boom: a load-sensing pump of 250 bar whose compensators keep 15 bar: nothing above
// 235 bar reaches a cylinder (the relief valves open at 280 bar).
JointRange XcmgBoom() {
  const model::MachineDescription machine = plant::testing::LoadMachine(kMachine);
  return app::RangeOf(machine, 0);
}

TEST(StallLimit, IsTheLowerOfReliefAndTheLoadSensingPumpsLimit) {
  model::MachineDescription machine = plant::testing::LoadMachine(kMachine);
  const int boom = machine.ActuatorOfJoint(0);
  const StallLimit pump = app::StallLimitOf(machine, boom);
  EXPECT_NEAR(pump.pressure, (250 - 15) * kBar, 1.0);
  EXPECT_EQ(pump.what, "the load-sensing pump's limit");
  machine.hydraulics.pump_pressure = 350 * kBar;  // a pump that out-pushes the relief valves
  const StallLimit relief = app::StallLimitOf(machine, boom);
  EXPECT_NEAR(relief.pressure, 280 * kBar, 1.0);
  EXPECT_EQ(relief.what, "relief");
  EXPECT_TRUE(std::isnan(app::StallLimitOf(machine, 7).pressure));  // no such actuator
}

// One 20 Hz sequence: the boom commanded 0.49 open (the figure), not moving, its cap
// side at `working(t)` and the pump at `pump(t)`. Returns the checks from t = 0 to `until`.
using Pressure = double (*)(double t);
std::vector<JointCheck> Sequence(SafetySupervisor& s, double until, Pressure working,
                                 Pressure pump) {
  const JointRange range = XcmgBoom();
  std::vector<JointCheck> checks;
  for (int k = 0; k * 0.05 <= until + 1e-9; ++k) {
    const double t = k * 0.05;
    const JointReading reading{.valve = 0.49,
                               .q = -0.3,
                               .qd = 0.0,
                               .working_pressure = working(t),
                               .pump_pressure = pump(t)};
    checks.push_back(s.CheckJoint(0, "boom", t, reading, range));
  }
  return checks;
}

// What the plant's load-sensing pump does: standby (the margin over tank) while nothing feeds,
// its 250 bar maximum while the fed chamber is at the 235 bar limit.
double PumpAtItsLimit(double) { return 250 * kBar; }
double PumpIdling(double) { return 17 * kBar; }

TEST(SafetySupervisor, ABoomAtThePumpsLimitStallsUnderLoad) {
  SafetySupervisor s;
  // The pressure builds within 0.3 s to 240 bar and stays there (the load check valve holds it).
  const std::vector<JointCheck> checks = Sequence(
      s, 12.0, [](double t) { return (150 + std::min(t / 0.3, 1.0) * 90) * kBar; }, PumpAtItsLimit);
  int first = -1, stalls = 0;
  for (std::size_t k = 0; k < checks.size(); ++k) {
    if (checks[k].state == JointState::kStallsUnderLoad) {
      ++stalls;
      if (checks[k].first_report) {
        EXPECT_EQ(first, -1) << "reported once";
        first = static_cast<int>(k);
      }
    }
  }
  // Decided after the stuck time (2 s), as the stuck valve is, never before.
  ASSERT_EQ(first, 40) << checks[first < 0 ? 0 : first].message;
  EXPECT_EQ(checks[first].message.rfind(
                "boom stalls under load at the load-sensing pump's limit (240 bar, limit 235 "
                "bar): commanded 0.49 for 2.0 s",
                0),
            0u)
      << checks[first].message;
  for (int k = 0; k < first; ++k) EXPECT_EQ(checks[k].state, JointState::kAnswers) << k;
  // Still stalled 10 s on, the controller has not ended it: now a fault.
  EXPECT_EQ(checks[199].state, JointState::kStallsUnderLoad);
  EXPECT_EQ(checks[200].state, JointState::kDoesNotAnswer);
  EXPECT_NE(checks[200].message.find("not ended by the controller"), std::string::npos);
  EXPECT_EQ(stalls, 200 - 40);
}

TEST(SafetySupervisor, AStuckValveBuildsNoPressureAndIsAFault) {
  SafetySupervisor s;
  // A jammed spool: the cap side stays at what holds the arm, 95 bar; the pump idles.
  const std::vector<JointCheck> checks = Sequence(
      s, 2.0, [](double) { return 95 * kBar; }, PumpIdling);
  for (std::size_t k = 0; k + 1 < checks.size(); ++k) {
    EXPECT_EQ(checks[k].state, JointState::kAnswers) << k;
  }
  EXPECT_EQ(checks.back().state, JointState::kDoesNotAnswer);
  EXPECT_EQ(checks.back().message.rfind(
                "boom does not answer its valve: commanded 0.49 for 2.0 s, moving 0.0000 rad/s, "
                "working pressure 95 bar, pump 17 bar (stall limit 235 bar)",
                0),
            0u)
      << checks.back().message;
}

TEST(SafetySupervisor, AJammedSpoolUnderAnOutsideLoadIsAFaultThoughItsChamberIsHigh) {
  // The pile presses the bucket down on a boom whose spool is jammed shut: the trapped cap side
  // rises to 275 bar (the plant's reached 277 bar), but the pump idles: nothing pushes.
  SafetySupervisor s;
  const std::vector<JointCheck> checks = Sequence(
      s, 2.0, [](double) { return 275 * kBar; }, PumpIdling);
  EXPECT_EQ(checks.back().state, JointState::kDoesNotAnswer) << checks.back().message;
}

TEST(SafetySupervisor, APressureSpikeDoesNotMakeAStall) {
  // At the limit for 0.3 s (a stone) just before the 2 s are up, then back to holding pressure.
  SafetySupervisor s;
  const std::vector<JointCheck> checks = Sequence(
      s, 2.2, [](double t) { return (t > 1.775 && t < 2.075 ? 240.0 : 95.0) * kBar; },
      PumpAtItsLimit);
  // At 2.0 s the pressure is at the limit but has not held 0.5 s: undecided.
  EXPECT_EQ(checks[40].state, JointState::kAnswers);
  // At 2.1 s it is gone: a stuck valve.
  EXPECT_EQ(checks[42].state, JointState::kDoesNotAnswer) << checks[42].message;
  // Just below the margin (10 % under 235 bar = 211.5 bar) is not at the limit either.
  SafetySupervisor t;
  EXPECT_EQ(Sequence(
                t, 2.0, [](double) { return 210.0 * kBar; }, PumpAtItsLimit)
                .back()
                .state,
            JointState::kDoesNotAnswer);
  SafetySupervisor u;
  EXPECT_EQ(Sequence(
                u, 2.0, [](double) { return 212.0 * kBar; }, PumpAtItsLimit)
                .back()
                .state,
            JointState::kStallsUnderLoad);
  // A machine without a pressure transducer (NaN) cannot tell: a fault, as before.
  SafetySupervisor v;
  EXPECT_EQ(Sequence(
                v, 2.0, [](double) { return std::nan(""); }, PumpAtItsLimit)
                .back()
                .state,
            JointState::kDoesNotAnswer);
  SafetySupervisor w;
  EXPECT_EQ(Sequence(
                w, 2.0, [](double) { return 240.0 * kBar; }, [](double) { return std::nan(""); })
                .back()
                .state,
            JointState::kDoesNotAnswer);
}

TEST(SafetySupervisor, AStallThatEndsResets) {
  // Stalled, reported; the controller holds the boom (valve closed): answered. A later stall is
  // reported again.
  SafetySupervisor s;
  const JointRange range = XcmgBoom();
  const JointReading stalled{.valve = 0.8,
                             .q = -0.3,
                             .qd = 0.0,
                             .working_pressure = 240 * kBar,
                             .pump_pressure = 250 * kBar};
  JointCheck c;
  for (int k = 0; k <= 40; ++k) c = s.CheckJoint(0, "boom", k * 0.05, stalled, range);
  EXPECT_EQ(c.state, JointState::kStallsUnderLoad);
  EXPECT_TRUE(c.first_report);
  c = s.CheckJoint(0, "boom", 2.05, {.valve = 0.02, .q = -0.3, .working_pressure = 200 * kBar},
                   range);
  EXPECT_EQ(c.state, JointState::kAnswers);
  for (int k = 0; k <= 40; ++k) c = s.CheckJoint(0, "boom", 3 + k * 0.05, stalled, range);
  EXPECT_EQ(c.state, JointState::kStallsUnderLoad);
  EXPECT_TRUE(c.first_report);
}

// One predicted-trigger, auto-selected scoop in a 3 m river-sand cone (Stairway), the supervisor
// checking both joints at 20 Hz as the main job's executive does and passing stalls on.
struct SupervisedScoop {
  ScoopResult result;
  std::vector<std::string> stalls;   ///< the supervisor's first reports
  std::string fault;                 ///< kDoesNotAnswer's message, if any (the scoop stops there)
  double max_boom_cap_pressure = 0;  ///< [Pa]
  double boom_lifted = 0;            ///< largest boom angle over the attack pose [rad]
};

// `pressures_sensed` false: the supervisor gets no pressures (NaN), as before issue 39.
SupervisedScoop RunSupervisedSandScoop(double pump_pressure, bool jam_boom_in_the_scoop,
                                       bool ease_the_drive = true, bool pressures_sensed = true) {
  testing::ConeYard yard(kMachine, "river_sand", 3.0, 4.0);
  // Only the load-sensing supply reads the pump's maximum (plant.cc LoadSensing): the generated
  // code does not, so the same compiled machine runs with a weaker pump.
  if (pump_pressure > 0) yard.machine.hydraulics.pump_pressure = pump_pressure;
  const prediction::HeightGrid map = testing::ToHeightGrid(yard.world.terrain);
  plant::Plant loader(yard.machine, plant::testing::Functions(kMachine), yard.world, yard.start);
  testing::PlantMachine machine(loader);
  ScoopCycleOptions options;
  options.attack_pose = yard.attack_pose;
  options.policy = ScoopPolicy::kAutoSelection;
  if (!ease_the_drive) options.boom_stall_time = 0;  // ScoopCycleOptions: never
  static const prediction::PenetrationPredictor predictor = prediction::PenetrationPredictor::Load(
      std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/prediction/penetration_svr");
  PredictedVolumeTrigger trigger(options.target_fill * yard.machine.bucket.rated_capacity);
  ScoopCycle cycle(yard.machine, plant::testing::Functions(kMachine), map, *yard.material, trigger,
                   &predictor, options);
  SafetySupervisor supervisor;
  SupervisedScoop out;
  const bool trace = std::getenv("AUTOSHOVEL_STALL_TRACE") != nullptr;  // the time series
  cycle.Start(machine);
  long tick = 0;
  while (cycle.Tick(machine)) {
    machine.Advance(options.tick);
    if (jam_boom_in_the_scoop && std::string(cycle.phase_name()) == "scoop") {
      machine.SetStuckValve(yard.machine.ActuatorOfJoint(0));
    }
    const Proprioception s = machine.Sense();
    out.max_boom_cap_pressure = std::max(out.max_boom_cap_pressure, s.boom_pressure);
    if (trace && tick % 10 == 0) {
      std::printf(
          "[stall-trace] t %.2f %-8s boom valve %+.2f q %.3f qd %+.4f cap %.0f rod %.0f "
          "pump %.0f bar, speed %.2f, payload %.2f\n",
          s.time, cycle.phase_name(), machine.last_command().valve[yard.machine.ActuatorOfJoint(0)],
          s.q_boom, s.qd_boom, s.boom_pressure / kBar, s.boom_pressure_rod / kBar,
          s.pump_pressure / kBar, s.speed, machine.PayloadVolume());
    }
    out.boom_lifted = std::max(out.boom_lifted, s.q_boom - yard.attack_pose.boom);
    if (++tick % 5 != 0) continue;  // the supervisor's 20 Hz
    bool stop = false;
    for (int j = 0; j < 2 && !stop; ++j) {
      JointReading reading = app::ReadJoint(yard.machine, j, s, machine.last_command());
      if (!pressures_sensed) reading.working_pressure = reading.pump_pressure = std::nan("");
      const JointCheck check = supervisor.CheckJoint(j, j == 0 ? "boom" : "bucket", s.time, reading,
                                                     app::RangeOf(yard.machine, j));
      if (check.state == JointState::kDoesNotAnswer) {
        out.fault = check.message;
        stop = true;
      } else if (check.state == JointState::kStallsUnderLoad && check.first_report) {
        out.stalls.push_back(check.message);
        cycle.JointStalledUnderLoad(j, check.message);
      }
    }
    if (stop) break;  // the main job's safe stop
  }
  out.result = cycle.Finish(machine);
  const ScoopResult& r = out.result;
  std::printf(
      "[stall] pump %.0f bar%s: ok=%d %s strategy=%s actions=%d payload=%.3f m^3 (fill %.3f), "
      "boom cap up to %.0f bar, boom lifted %.3f rad; stalls %zu; fault '%s'\n",
      yard.machine.hydraulics.pump_pressure / kBar, jam_boom_in_the_scoop ? ", boom jammed" : "",
      r.ok, r.failure.c_str(), ToString(r.strategy), r.atomic_actions, r.payload, r.fill_rate,
      out.max_boom_cap_pressure / kBar, out.boom_lifted, out.stalls.size(), out.fault.c_str());
  for (const std::string& stall : r.stalls) std::printf("[stall]   %s\n", stall.c_str());
  return out;
}

// The nominal machine scoops sand with no stall and no fault: the rule does not fire on a
// machine that works.
TEST(StallUnderLoad, TheNominalMachineScoopsSandWithoutAStall) {
  const SupervisedScoop out = RunSupervisedSandScoop(0, false);
  EXPECT_TRUE(out.result.ok) << out.result.failure;
  EXPECT_TRUE(out.stalls.empty()) << out.stalls.front();
  EXPECT_TRUE(out.result.stalls.empty());
  EXPECT_EQ(out.fault, "");
  // The pile presses the boom's cap side above the pump's 235 bar limit (to 269 bar) while the
  // bucket curls in it: the chamber's pressure alone would call that a stall; the pump's, and
  // the joint's motion, do not.
  EXPECT_GT(out.max_boom_cap_pressure, 235 * kBar);
}

// An under-powered machine: a pump of 50 bar (its compensators pass 35 bar) where the XCMG's
// holds a full bucket of sand at 75-80 bar and the pile presses the boom to 180 bar. The bucket
// stalls curling in the pile and the boom stalls lifting the load, each commanded wide open,
// not moving, its working chamber and the pump at the pump's limit. Told from a stuck valve by
// that pressure, each stall is reported once, the joint held where it stalled and the scoop
// ended, and the cycle completes with what it scooped. The same machine watched without the
// pressures (as the supervisor was before: a stall cannot be told) is stopped as a fault.
TEST(StallUnderLoad, AnUnderPoweredMachineStallsAndTheCycleEndsWithItsLoad) {
  // AUTOSHOVEL_STALL_PUMP_BAR tries another pump, AUTOSHOVEL_STALL_NO_EASE turns the scoop's
  // drive easing off (exploration; the test asserts for 50 bar with the easing on).
  const char* pump = std::getenv("AUTOSHOVEL_STALL_PUMP_BAR");
  const double pump_pressure = (pump != nullptr ? std::atof(pump) : 50.0) * kBar;
  const bool ease = std::getenv("AUTOSHOVEL_STALL_NO_EASE") == nullptr;
  const SupervisedScoop out = RunSupervisedSandScoop(pump_pressure, false, ease);
  EXPECT_EQ(out.fault, "");
  ASSERT_FALSE(out.stalls.empty());
  bool boom = false;
  for (const std::string& stall : out.stalls) {
    EXPECT_NE(stall.find(" stalls under load at the load-sensing pump's limit ("),
              std::string::npos)
        << stall;
    EXPECT_NE(stall.find("limit 35 bar): commanded "), std::string::npos) << stall;
    boom = boom || stall.rfind("boom ", 0) == 0;
  }
  EXPECT_TRUE(boom) << "the boom stalls too";
  const ScoopResult& r = out.result;
  EXPECT_EQ(r.stalls.size(), out.stalls.size());  // each passed on to the scoop cycle
  EXPECT_TRUE(r.ok) << r.failure;
  const char* kPhases[] = {"approach", "crowd", "scoop", "level", "shake", "retreat"};
  ASSERT_EQ(r.phases.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(r.phases[i].name, kPhases[i]);
  // It kept what it had scooped (82 % of the rated heap) and backed out of the pile.
  EXPECT_GT(r.payload, 0.6 * r.target_volume);

  const SupervisedScoop blind = RunSupervisedSandScoop(pump_pressure, false, ease, false);
  EXPECT_TRUE(blind.stalls.empty());
  EXPECT_NE(blind.fault.find(" does not answer its valve: commanded "), std::string::npos)
      << blind.fault;
  EXPECT_FALSE(blind.result.ok);
}

// The nominal machine with its boom spool jammed at neutral from the scoop on: the boom is
// commanded to lift, does not move and builds no pressure: still a fault, the scoop stops.
TEST(StallUnderLoad, AJammedBoomSpoolIsStillAFault) {
  const SupervisedScoop out = RunSupervisedSandScoop(0, true);
  EXPECT_TRUE(out.stalls.empty());
  EXPECT_EQ(out.fault.rfind("boom does not answer its valve", 0), 0u) << out.fault;
  EXPECT_FALSE(out.result.ok);
}

}  // namespace
}  // namespace autoshovel::control
