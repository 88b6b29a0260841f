// The closed-loop joint models (seed §4.4) and their simulator: values derived from the 25 t
// description, the motion they predict (latency, rate and acceleration limits, arrival without
// overshoot, braking), and the command latency of the simulator.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "excavator_test_support.h"

namespace autoshovel::control {
namespace {

using testing::Excavator25t;
using testing::kDeg;

TEST(JointModelDerivation, MatchesHandComputedValuesOfThe25tDescription) {
  const ExcavatorModelDerivation& d = Excavator25t().derivation;
  const JointModelParams& swing = d.models[JointIndex(ExcavatorJoint::kSwing)];
  // Swing motor: 250 L/min over 0.0025 m³/rad; relief 290 bar less 2 bar tank on the same
  // displacement; latency 0.20 s transport delay + 0.08 s spool lag.
  EXPECT_NEAR(swing.max_velocity_up, 250.0 / 60000.0 / 0.0025, 1e-9);
  EXPECT_NEAR(swing.max_velocity_down, swing.max_velocity_up, 1e-12);
  EXPECT_NEAR(swing.latency, 0.28, 1e-12);
  EXPECT_NEAR(swing.time_constant, 0.56, 1e-12);
  const double swing_inertia = d.joints[3].inertia;
  EXPECT_NEAR(swing.max_acceleration, 288e5 * 0.0025 / swing_inertia, 1e-9);
  // The arm and payload add to the upper structure's 60 000 kg m² by Σ m r²: with a 2 t payload
  // 7–8 m out that is several times as much again.
  EXPECT_GT(swing_inertia, 150000.0);
  EXPECT_LT(swing_inertia, 600000.0);
  // Boom: two 140/100 mm cylinders, 420 L/min; raising extends them (cap side fed).
  const JointModelDerivation& boom = d.joints[0];
  const double cap = 2 * std::numbers::pi / 4 * 0.14 * 0.14;
  const double annulus = 2 * std::numbers::pi / 4 * (0.14 * 0.14 - 0.10 * 0.10);
  EXPECT_GT(boom.lever, 0.0);
  EXPECT_NEAR(boom.params.max_velocity_up, 420.0 / 60000.0 / (cap * boom.lever), 1e-9);
  EXPECT_NEAR(boom.params.max_velocity_down, 420.0 / 60000.0 / (annulus * boom.lever), 1e-9);
  EXPECT_NEAR(boom.params.latency, 0.21, 1e-12);
  EXPECT_NEAR(boom.params.position_min, -40 * kDeg, 1e-9);
  EXPECT_NEAR(boom.params.position_max, 58 * kDeg, 1e-9);
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    const JointModelParams& p = d.models[j];
    std::printf(
        "[figure] joint model %-6s L %.2f s  v_up %.3f rad/s (%.1f°/s)  v_down %.3f rad/s "
        "(%.1f°/s)  a %.3f rad/s² (%.1f°/s²)  tau %.2f s  lever %.3f m/rad  inertia %.0f "
        "kg m²\n",
        d.joints[j].joint.c_str(), p.latency, p.max_velocity_up, p.max_velocity_up / kDeg,
        p.max_velocity_down, p.max_velocity_down / kDeg, p.max_acceleration,
        p.max_acceleration / kDeg, p.time_constant, d.joints[j].lever, d.joints[j].inertia);
    // Rates of a 25 t excavator's joints are tens of degrees per second; accelerations are
    // positive (drive torque beats gravity at the reference pose).
    EXPECT_GT(p.max_velocity_up, 5 * kDeg);
    EXPECT_LT(p.max_velocity_up, 150 * kDeg);
    EXPECT_GT(p.max_acceleration, 0.0);
  }
}

TEST(JointModelDerivation, RejectsALoaderAndNonFiniteInput) {
  const testing::Excavator& e = Excavator25t();
  model::MachineDescription loader = e.machine;
  loader.kind = model::MachineKind::kWheelLoader;
  EXPECT_THROW(DeriveJointModels(loader, *e.functions, DefaultReferencePose(), 0.0),
               std::invalid_argument);
  JointVector bad = DefaultReferencePose();
  bad[1] = std::nan("");
  EXPECT_THROW(DeriveJointModels(e.machine, *e.functions, bad, 0.0), std::invalid_argument);
  JointModelParams p = e.derivation.models[0];
  p.max_acceleration = 0;
  EXPECT_THROW(Validate(p, "boom"), std::invalid_argument);
}

/// Runs one joint from rest with a command at t = 0 and checks the limits along the way.
struct Trace {
  double start_moving = -1;
  double peak_speed = 0;
  double peak_acceleration = 0;
  double overshoot = 0;
  double final_position = 0;
};

Trace RunJoint(const JointModelParams& p, double from, double to, double duration, double dt) {
  Trace trace;
  JointMotion m{from, 0.0};
  const double direction = to > from ? 1.0 : -1.0;
  for (double t = 0; t < duration; t += dt) {
    const JointMotion next = t + 1e-12 >= p.latency ? StepJoint(p, m, to, false, dt) : m;
    if (trace.start_moving < 0 && next.position != from) trace.start_moving = t;
    trace.peak_speed = std::max(trace.peak_speed, std::abs(next.velocity));
    trace.peak_acceleration =
        std::max(trace.peak_acceleration, std::abs(next.velocity - m.velocity) / dt);
    trace.overshoot = std::max(trace.overshoot, direction * (next.position - to));
    m = next;
  }
  trace.final_position = m.position;
  return trace;
}

TEST(JointModel, MovesAfterItsLatencyWithinItsLimitsAndArrivesWithoutOvershoot) {
  const ExcavatorJointModels& models = Excavator25t().derivation.models;
  struct Move {
    ExcavatorJoint joint;
    double from, to;
  };
  for (const Move& move : {Move{ExcavatorJoint::kSwing, 0.0, 90 * kDeg},
                           Move{ExcavatorJoint::kSwing, 90 * kDeg, 10 * kDeg},
                           Move{ExcavatorJoint::kBoom, 10 * kDeg, 45 * kDeg},
                           Move{ExcavatorJoint::kBoom, 45 * kDeg, -5 * kDeg},
                           Move{ExcavatorJoint::kStick, -110 * kDeg, -60 * kDeg},
                           Move{ExcavatorJoint::kBucket, -140 * kDeg, 25 * kDeg}}) {
    const JointModelParams& p = models[JointIndex(move.joint)];
    SCOPED_TRACE(std::string(JointName(move.joint)) + " to " + std::to_string(move.to / kDeg));
    const double dt = 0.001;
    const Trace trace = RunJoint(p, move.from, move.to, 20.0, dt);
    EXPECT_NEAR(trace.start_moving, p.latency, 2 * dt);
    const double v_max = move.to > move.from ? p.max_velocity_up : p.max_velocity_down;
    EXPECT_LE(trace.peak_speed, v_max * (1 + 1e-9));
    EXPECT_LE(trace.peak_acceleration, p.max_acceleration * (1 + 1e-6));
    EXPECT_LT(trace.overshoot, 0.05 * kDeg);
    EXPECT_NEAR(trace.final_position, move.to, 0.01 * kDeg);
    // The time to within 1° from the profile worked out by hand. After the latency the joint
    // speeds up at a to v_max (or, for a short move, to the peak of a triangular profile). If
    // a·τ >= v the proportional law decelerates more gently than a allows: it cruises until
    // |e| = v·τ and then closes exponentially, |e| = v·τ·exp(−t/τ). Otherwise it follows the
    // braking parabola v² = 2a|e| and the motion is the rate- and acceleration-limited
    // rest-to-rest profile less the braking time of the last degree.
    const double distance = std::abs(move.to - move.from);
    const double a = p.max_acceleration, tau = p.time_constant, tolerance = 1 * kDeg;
    double expected = p.latency;
    if (a * tau >= v_max) {
      ASSERT_GT(distance, v_max * v_max / (2 * a) + v_max * tau);
      expected += v_max / a + (distance - v_max * v_max / (2 * a) - v_max * tau) / v_max +
                  tau * std::log(v_max * tau / tolerance);
    } else {
      const double peak = std::min(v_max, std::sqrt(a * distance));
      ASSERT_GT(peak, a * tau);
      expected += (distance > v_max * v_max / a ? distance / v_max + v_max / a
                                                : 2.0 * std::sqrt(distance / a)) -
                  std::sqrt(2.0 * tolerance / a);
    }
    const double reach = TimeToReach(p, move.from, move.to, tolerance, dt);
    EXPECT_NEAR(reach, expected, 0.05);
  }
}

TEST(JointModel, StopBrakesOverTheStoppingDistance) {
  ExcavatorJointModels models = Excavator25t().derivation.models;
  for (JointModelParams& p : models) {
    p.position_min = -100;
    p.position_max = 100;
  }
  for (ExcavatorJoint joint : kAllExcavatorJoints) {
    const int j = JointIndex(joint);
    const JointModelParams& p = models[j];
    // Drive the joint towards a far target until it cruises, then stop it.
    ExcavatorSimulator sim(models, ExcavatorState{}, 0.001);
    JointVector far = JointVector::Zero();
    far[j] = 50.0;
    sim.Command(ExcavatorCommand{far, false});
    sim.Advance(p.latency + 1.2 * p.max_velocity_up / p.max_acceleration);
    const double speed = sim.state().qd[j];
    EXPECT_NEAR(speed, p.max_velocity_up, 1e-6) << JointName(joint);
    const double at_stop = sim.state().q[j];
    sim.Command(ExcavatorCommand{JointVector::Zero(), true});
    sim.Advance(StoppingTime(p, speed) + 0.5);
    EXPECT_NEAR(sim.state().q[j] - at_stop, StoppingDistance(p, speed), 0.002 * speed + 1e-4)
        << JointName(joint);
    EXPECT_EQ(sim.state().qd[j], 0.0) << JointName(joint);
  }
}

TEST(ExcavatorSimulator, EachJointFollowsACommandAfterItsOwnLatency) {
  const ExcavatorJointModels& models = Excavator25t().derivation.models;
  ExcavatorState start;
  start.q = JointVector(10 * kDeg, -100 * kDeg, -100 * kDeg, 0.0);
  ExcavatorSimulator sim(models, start, 0.01);
  sim.Advance(0.05);
  sim.Command(ExcavatorCommand{JointVector(20 * kDeg, -90 * kDeg, -90 * kDeg, 10 * kDeg), false});
  // Just before each latency nothing has moved; just after, it has.
  for (ExcavatorJoint joint : kAllExcavatorJoints) {
    const int j = JointIndex(joint);
    ExcavatorSimulator before = sim, after = sim;
    before.Advance(models[j].latency - 0.011);
    after.Advance(models[j].latency + 0.021);
    EXPECT_EQ(before.state().q[j], start.q[j]) << JointName(joint);
    EXPECT_NE(after.state().q[j], start.q[j]) << JointName(joint);
  }
  // A resync replaces the state but keeps the command in flight.
  ExcavatorState moved = start;
  moved.q[3] = 5 * kDeg;
  sim.Resync(moved);
  sim.Advance(5.0);
  EXPECT_NEAR(sim.state().q[3], 10 * kDeg, 0.05 * kDeg);
  EXPECT_NEAR(sim.state().q[0], 20 * kDeg, 0.05 * kDeg);
}

TEST(ExcavatorSimulator, TheTrajectoryDoesNotDependOnTheIntegrationGrid) {
  // Commands take effect exactly one latency after they are issued, wherever the integration
  // steps fall, and the joints are sub-stepped: 3, 10 and 20 ms steps agree to 0.15° (a 10 ms
  // error in when the bucket starts would be 1.3° at its 2.3 rad/s).
  const ExcavatorJointModels& models = Excavator25t().derivation.models;
  ExcavatorState start;
  start.q = JointVector(15 * kDeg, -105 * kDeg, -140 * kDeg, 0.0);
  std::vector<ExcavatorSimulator> sims;
  for (double step : {0.003, 0.01, 0.02}) sims.emplace_back(models, start, step);
  const JointVector targets[] = {JointVector(50 * kDeg, -85 * kDeg, -140 * kDeg, 90 * kDeg),
                                 JointVector(50 * kDeg, -95 * kDeg, 25 * kDeg, 90 * kDeg),
                                 JointVector(26 * kDeg, -85 * kDeg, -20 * kDeg, 0.0)};
  for (int tick = 0; tick < 100; ++tick) {
    for (ExcavatorSimulator& sim : sims) {
      if (tick % 30 == 0) sim.Command(ExcavatorCommand{targets[tick / 30 % 3], false});
      sim.Advance(0.1);
    }
    for (std::size_t k = 1; k < sims.size(); ++k) {
      EXPECT_LT((sims[k].state().q - sims[0].state().q).cwiseAbs().maxCoeff(), 0.15 * kDeg)
          << "tick " << tick;
    }
  }
}

TEST(ExcavatorSimulator, RefusesNonFiniteCommandsAndStates) {
  const ExcavatorJointModels& models = Excavator25t().derivation.models;
  ExcavatorSimulator sim(models, ExcavatorState{}, 0.01);
  JointVector bad = JointVector::Zero();
  bad[2] = std::nan("");
  EXPECT_THROW(sim.Command(ExcavatorCommand{bad, false}), std::invalid_argument);
  // A stop carries no positions and is always accepted.
  EXPECT_NO_THROW(sim.Command(ExcavatorCommand{bad, true}));
  ExcavatorState nan_state;
  nan_state.qd[1] = std::nan("");
  EXPECT_THROW(sim.Resync(nan_state), std::invalid_argument);
  EXPECT_THROW(ExcavatorSimulator(models, nan_state), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::control
