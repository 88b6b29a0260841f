// The valve chain with a pilot stage and opening curves (docs/simulation.md "Valve chain"):
// u → delay τ_p + τ_d → pilot lag T_p → opening curve of the direction → spool lag → orifice.
// The pilot's delay and time constant are recovered from the plant's signals, the curves set
// the steady cylinder speeds in the ratio the orifice law predicts, a curve equal to the dead
// zone law changes nothing, and malformed curves are refused where they stand.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/core/diagnostics.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/valve_command.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string ExcavatorPath() {
  return model::ResolveMachineDescription("excavator_25t", testing::ModelsDir());
}

// excavator_25t with `valve_keys` (YAML lines at 6 spaces) for the boom's valve, as an overlay.
model::MachineDescription WithBoomValve(const std::string& file, const std::string& valve_keys) {
  const model::MachineDescription base = model::LoadMachineDescription(ExcavatorPath());
  model::LoadOptions options;
  options.overlays = {WriteTemp(file, "machine: excavator_25t\nbase_sha256: " + base.sha256 +
                                          "\nhydraulics:\n  actuators:\n"
                                          "    - name: boom_cylinders\n" +
                                          valve_keys)};
  return model::LoadMachineDescription(ExcavatorPath(), options);
}

MachineState MidPose(const model::MachineDescription& machine) {
  MachineState state;
  state.q.assign(machine.num_joints(), 0.0);
  for (std::size_t j = 0; j < machine.num_links(); ++j) {
    state.q[j] = 0.5 * (machine.links[j].joint_min + machine.links[j].joint_max);
  }
  return state;
}

struct Trace {
  std::vector<double> t, pilot_signal, pilot_state, spool, length, q;
};

// A step of the boom valve to `duty` at `step_time`, logged every `dt`.
Trace BoomStep(const model::MachineDescription& machine, double duty, double step_time,
               double duration, double dt) {
  const generated::MachineFunctions& functions = testing::Functions(machine.name);
  World world = EmptyYard(machine);
  Plant plant(machine, functions, world, MidPose(machine));
  const int boom = machine.ActuatorOfJoint(0);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  Trace trace;
  while (plant.time() < duration - 1e-9) {
    command.valve[boom] = plant.time() >= step_time - 1e-9 ? duty : 0.0;
    EXPECT_TRUE(plant.SetCommand(command));
    plant.Advance(dt);
    trace.t.push_back(plant.time());
    trace.pilot_signal.push_back(plant.PilotSignal(boom));
    trace.pilot_state.push_back(plant.PilotState(boom));
    trace.spool.push_back(plant.state().spool[0]);
    trace.length.push_back(functions.cylinder_length(boom, plant.state().q.data()));
    trace.q.push_back(plant.state().q[0]);
  }
  return trace;
}

// Fits x = target·(1 − exp(−(t − t0)/T)) by ln(1 − x/target) = −(t − t0)/T on the samples
// between 5 % and 90 % of the step; returns {t0, T}.
std::pair<double, double> FitLag(const std::vector<double>& t, const std::vector<double>& x,
                                 double target) {
  double sum_t = 0, sum_y = 0, sum_tt = 0, sum_ty = 0;
  int count = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double ratio = x[i] / target;
    if (ratio < 0.05 || ratio > 0.9) continue;
    const double y = std::log(1.0 - ratio);
    sum_t += t[i], sum_y += y, sum_tt += t[i] * t[i], sum_ty += t[i] * y;
    ++count;
  }
  EXPECT_GT(count, 10);
  const double slope = (count * sum_ty - sum_t * sum_y) / (count * sum_tt - sum_t * sum_t);
  const double intercept = (sum_y - slope * sum_t) / count;
  const double time_constant = -1.0 / slope;
  return {intercept * time_constant, time_constant};
}

TEST(ValveOpening, CurvesPerDirectionElseTheDeadZone) {
  model::Valve valve;
  valve.dead_zone = 0.1;
  EXPECT_EQ(ValveOpening(valve, 0.55), ApplyDeadZone(0.55, 0.1));
  EXPECT_EQ(ValveOpening(valve, -0.55), ApplyDeadZone(-0.55, 0.1));
  valve.opening_curve_extend = {{0.4, 0.0}, {0.6, 0.5}, {0.8, 0.9}};
  EXPECT_EQ(ValveOpening(valve, 0.3), 0.0);  // the dead band
  EXPECT_EQ(ValveOpening(valve, 0.4), 0.0);
  EXPECT_NEAR(ValveOpening(valve, 0.5), 0.25, 1e-15);
  EXPECT_NEAR(ValveOpening(valve, 0.7), 0.7, 1e-15);
  EXPECT_EQ(ValveOpening(valve, 1.0), 0.9);  // saturated above the last point
  EXPECT_EQ(ValveOpening(valve, -0.55), ApplyDeadZone(-0.55, 0.1));  // no retract curve
  valve.opening_curve_retract = {{0.2, 0.0}, {1.0, 0.8}};
  EXPECT_NEAR(ValveOpening(valve, -0.6), -0.4, 1e-15);
}

// π(t) = u (1 − exp(−(t − t_step − τ_p)/T_p)) exactly, and nothing before t_step + τ_p.
TEST(PilotSignal, IsTheDelayedExactFirstOrderLag) {
  PilotSignal pilot(0.07, 0.04);
  pilot.Command(1.0, 0.6);
  EXPECT_EQ(pilot.At(1.0699999), 0.0);
  EXPECT_EQ(pilot.At(1.07), 0.0);
  EXPECT_NEAR(pilot.At(1.07 + 0.04), 0.6 * (1 - std::exp(-1.0)), 1e-15);
  pilot.Command(1.2, 0.0);  // off: relaxes from where it was at 1.27
  pilot.Prune(1.25);
  const double at_off = 0.6 * (1 - std::exp(-0.2 / 0.04));
  EXPECT_NEAR(pilot.At(1.27), at_off, 1e-15);
  EXPECT_NEAR(pilot.At(1.31), at_off * std::exp(-1.0), 1e-15);
  pilot.Prune(1.3);
  EXPECT_NEAR(pilot.At(1.31), at_off * std::exp(-1.0), 1e-15);
}

// The pilot stage in the plant: the logged pilot signal starts exactly τ_p after the step and
// the CVODE pilot state (what the spool path sees) τ_p + τ_d after it, both with the time
// constant T_p: fitted to < 1 ms and < 2 %.
TEST(PlantValveChain, PilotDelayAndTimeConstantAreRecoveredFromThePlant) {
  const double tau_p = 0.07, time_constant = 0.04, tau_d = 0.12;
  const model::MachineDescription machine =
      WithBoomValve("pilot.yaml",
                    "      pilot_delay: 0.07\n      pilot_time_constant: 0.04\n"
                    "      transport_delay: 0.12\n");
  const double duty = 0.8, step_time = 0.2, dt = 0.002;
  const Trace trace = BoomStep(machine, duty, step_time, 0.8, dt);
  for (std::size_t i = 0; i < trace.t.size(); ++i) {
    // (the logged clock sums 2 ms ticks: the step's own instant carries their rounding)
    if (trace.t[i] <= step_time + tau_p + 1e-9) {
      ASSERT_NEAR(trace.pilot_signal[i], 0.0, 1e-12) << trace.t[i];
    }
    if (trace.t[i] <= step_time + tau_p + tau_d + 1e-9) {
      ASSERT_NEAR(trace.pilot_state[i], 0.0, 1e-12) << trace.t[i];
      ASSERT_NEAR(trace.spool[i], 0.0, 1e-9) << trace.t[i];
    }
  }
  const auto [t0_signal, tp_signal] = FitLag(trace.t, trace.pilot_signal, duty);
  EXPECT_NEAR(t0_signal, step_time + tau_p, 1e-3);
  EXPECT_NEAR(tp_signal, time_constant, 0.02 * time_constant);
  const auto [t0_state, tp_state] = FitLag(trace.t, trace.pilot_state, duty);
  EXPECT_NEAR(t0_state, step_time + tau_p + tau_d, 1e-3);
  EXPECT_NEAR(tp_state, time_constant, 0.02 * time_constant);
  // The motion path sees the logged signal τ_d later (to the integrator's tolerance).
  for (std::size_t i = 0; i + 60 < trace.t.size(); ++i) {
    ASSERT_NEAR(trace.pilot_state[i + 60], trace.pilot_signal[i], 2e-3) << trace.t[i];
  }
  EXPECT_GT(trace.q.back() - trace.q.front(), 0.005);  // and the boom rises
}

// Steady cylinder speed under pressure-compensated load sensing is Q/A with
// Q = K_v·x_s·√Δp_margin, x_s = the curve's opening: the speeds at two duties of a direction
// stand in the ratio of that direction's openings. (Boom down is an overrunning load, partly
// held by the meter-out edge, so its ratio is 2.5 % off the openings'; the extend one 0.7 %.)
TEST(PlantValveChain, OpeningCurveSetsTheSteadyCylinderSpeed) {
  const model::MachineDescription machine =
      WithBoomValve("curves.yaml",
                    "      dead_zone: 0\n      pilot_time_constant: 0.03\n"
                    "      opening_curve_extend: [[0.3, 0], [0.5, 0.3], [0.7, 0.6], [1.0, 0.9]]\n"
                    "      opening_curve_retract: [[0.35, 0], [0.6, 0.5], [1.0, 0.7]]\n");
  auto speed = [&](double duty) {
    const Trace trace = BoomStep(machine, duty, 0.1, 2.0, 0.01);
    // Mean speed over [1.2, 1.8] s: long after the chain has settled (τ ≈ 0.3 s in all).
    const std::size_t a = 119, b = 179;
    return (trace.length[b] - trace.length[a]) / (trace.t[b] - trace.t[a]);
  };
  const double v60 = speed(0.6), v90 = speed(0.9);
  const double v_retract_55 = speed(-0.55), v_retract_80 = speed(-0.8);
  const double open60 = 0.45, open90 = 0.8, open_retract_55 = 0.4, open_retract_80 = 0.6;
  RecordProperty("speed_ratio_90_60", std::to_string(v90 / v60));
  RecordProperty("speed_ratio_retract_80_55", std::to_string(v_retract_80 / v_retract_55));
  EXPECT_GT(v60, 0.0);
  EXPECT_LT(v_retract_55, 0.0);
  EXPECT_NEAR(v90 / v60, open90 / open60, 0.03 * open90 / open60);
  EXPECT_NEAR(v_retract_80 / v_retract_55, open_retract_80 / open_retract_55,
              0.03 * open_retract_80 / open_retract_55);
}

// A curve that is the dead-zone law itself, a pilot delay split off the transport delay: the
// same motion as the plain description (to rounding).
TEST(PlantValveChain, EquivalentChainGivesTheSameMotion) {
  const model::MachineDescription plain = model::LoadMachineDescription(ExcavatorPath());
  const model::Valve& valve = plain.hydraulics.actuators[plain.ActuatorOfJoint(0)].valve;
  char keys[256];
  std::snprintf(keys, sizeof keys,
                "      dead_zone: 0\n      pilot_delay: 0.05\n      transport_delay: %.17g\n"
                "      opening_curve_extend: [[%.17g, 0], [1, 1]]\n"
                "      opening_curve_retract: [[%.17g, 0], [1, 1]]\n",
                valve.transport_delay - 0.05, valve.dead_zone, valve.dead_zone);
  const model::MachineDescription curved = WithBoomValve("equivalent.yaml", keys);
  for (double duty : {0.6, -0.5}) {
    const Trace a = BoomStep(plain, duty, 0.1, 1.5, 0.01);
    const Trace b = BoomStep(curved, duty, 0.1, 1.5, 0.01);
    ASSERT_EQ(a.q.size(), b.q.size());
    EXPECT_GT(std::abs(a.q.back() - a.q.front()), 0.01);
    for (std::size_t i = 0; i < a.q.size(); ++i) {
      ASSERT_NEAR(a.q[i], b.q[i], 1e-6) << duty << " " << a.t[i];
      ASSERT_NEAR(a.spool[i], b.spool[i], 1e-6) << duty << " " << a.t[i];
    }
  }
}

// --- The description keys: malformed curves are refused at the bad point -------------------

// excavator_25t's description with `keys` added to the boom valve (after its
// rated_pressure_drop_bar line); returns the refusal, or "accepted". `line` gets the 1-based
// line of the first added key.
std::string RefusalOfValveKeys(const std::string& name, const std::string& keys, int* line) {
  std::ifstream in(ExcavatorPath());
  std::ostringstream text;
  std::string row;
  int number = 0;
  bool inserted = false;
  while (std::getline(in, row)) {
    text << row << "\n";
    ++number;
    if (!inserted && row.find("rated_pressure_drop_bar:") != std::string::npos) {
      *line = number + 1;
      text << keys;
      inserted = true;
    }
  }
  model::LoadOptions options;
  options.models_dir = testing::ModelsDir();
  try {
    model::LoadMachineDescription(WriteTemp(name, text.str()), options);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ValveKeys, MalformedOpeningCurvesAreRefusedWithTheirLocation) {
  const std::string key = "hydraulics.actuators[0].valve.";
  struct Case {
    const char* name;
    std::string keys;
    std::string expected;  // "LINE_OFFSET:COLUMN: key: message start", line offset from `line`
  };
  const std::string ext = "        opening_curve_extend: ";
  const int c = static_cast<int>(ext.size()) + 1;  // column of the list's '['
  const std::vector<Case> cases = {
      {"decreasing_duty.yaml", ext + "[[0.3, 0], [0.6, 0.5], [0.5, 0.6]]\n",
       "0:" + std::to_string(c + 23) + ": " + key +
           "opening_curve_extend[2]: duty must increase strictly"},
      {"decreasing_opening.yaml", ext + "[[0.3, 0], [0.6, 0.5], [0.8, 0.4]]\n",
       "0:" + std::to_string(c + 23) + ": " + key +
           "opening_curve_extend[2]: opening must not decrease"},
      {"out_of_range.yaml", ext + "[[0.3, 0], [1.2, 0.5]]\n",
       "0:" + std::to_string(c + 11) + ": " + key +
           "opening_curve_extend[1]: duty and opening are fractions in [0, 1], got [1.2, 0.5]"},
      {"one_point.yaml", ext + "[[0.3, 0]]\n",
       "0:" + std::to_string(c) + ": " + key +
           "opening_curve_extend: expected a list of at least 2"},
      {"open_at_start.yaml", ext + "[[0.3, 0.1], [0.9, 1]]\n",
       "0:" + std::to_string(c + 1) + ": " + key +
           "opening_curve_extend[0]: the first point's opening must be 0"},
      {"not_a_point.yaml", ext + "[[0.3, 0], [0.9, x]]\n",
       "0:" + std::to_string(c + 11) + ": " + key + "opening_curve_extend[1]: expected a point"},
      {"never_opens.yaml", ext + "[[0.3, 0], [0.9, 0]]\n",
       "0:" + std::to_string(c) + ": " + key + "opening_curve_extend: the valve never opens"},
      {"negative_pilot.yaml", "        pilot_time_constant: -0.01\n",
       "0:30: " + key + "pilot_time_constant: must be"},
  };
  for (const Case& test : cases) {
    int line = 0;
    const std::string what = RefusalOfValveKeys(test.name, test.keys, &line);
    const std::size_t colon = test.expected.find(':');
    const std::string where = std::string(test.name) + ":" +
                              std::to_string(line + std::stoi(test.expected.substr(0, colon))) +
                              test.expected.substr(colon);
    EXPECT_NE(what.find(where), std::string::npos) << "expected: " << where << "\ngot: " << what;
  }
  // Both curves make the dead zone meaningless: a non-zero one is refused at dead_zone.
  int line = 0;
  const std::string both =
      RefusalOfValveKeys("both_curves.yaml",
                         ext +
                             "[[0.3, 0], [1, 1]]\n        opening_curve_retract: [[0.3, 0], "
                             "[1, 1]]\n",
                         &line);
  EXPECT_NE(both.find(key + "dead_zone: dead_zone 0.1 has no effect when both"), std::string::npos)
      << both;
  // Well-formed keys load.
  EXPECT_EQ(RefusalOfValveKeys("good.yaml",
                               ext + "[[0.35, 0], [0.8, 0.9], [1, 0.95]]\n"
                                     "        pilot_delay: 0.07\n"
                                     "        pilot_time_constant: 0.04\n",
                               &line),
            "accepted");
}

// An overlay is read by the same rules; curves given over a description's non-zero dead zone
// in both directions are refused at the overlay's curve.
TEST(ValveKeys, OverlayCurvesFollowTheSameRules) {
  const model::MachineDescription base = model::LoadMachineDescription(ExcavatorPath());
  model::LoadOptions options;
  options.overlays = {WriteTemp("both.overlay.yaml",
                                "machine: excavator_25t\nhydraulics:\n  actuators:\n"
                                "    - name: boom_cylinders\n"
                                "      opening_curve_extend: [[0.3, 0], [1, 1]]\n"
                                "      opening_curve_retract: [[0.3, 0], [1, 1]]\n")};
  try {
    model::LoadMachineDescription(ExcavatorPath(), options);
    ADD_FAILURE() << "accepted";
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("both.overlay.yaml:6:30: hydraulics.actuators[0].opening_curve_retract: "
                        "dead_zone 0.1 has no effect"),
              std::string::npos)
        << what;
  }
  options.overlays = {WriteTemp("bad_point.overlay.yaml",
                                "machine: excavator_25t\nhydraulics:\n  actuators:\n"
                                "    - name: boom_cylinders\n"
                                "      opening_curve_retract: [[0.3, 0], [0.2, 1]]\n")};
  try {
    model::LoadMachineDescription(ExcavatorPath(), options);
    ADD_FAILURE() << "accepted";
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad_point.overlay.yaml:5:41: hydraulics.actuators[0]."
                        "opening_curve_retract[1]: duty must increase strictly"),
              std::string::npos)
        << what;
  }
  (void)base;
}

}  // namespace
}  // namespace autoshovel::plant
