// Shared fixtures of the excavator control tests: the 25 t excavator with its generated code, a
// 20 t tipper beside it, a flat elevation map, and the closed loop used as "the machine": the
// joint models integrated at 100 Hz with the loading script evaluated at 10 Hz (seed §4.4).
#pragma once

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "generated/registry.h"
#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/control/excavator/excavator_simulator.h"
#include "runtime/control/excavator/height_grid.h"
#include "runtime/control/excavator/joint_model.h"
#include "runtime/control/excavator/linkage_clearance.h"
#include "runtime/control/excavator/linkage_envelope.h"
#include "runtime/control/excavator/loading_script.h"
#include "runtime/control/excavator/obstacle_lookahead.h"
#include "runtime/control/excavator/script_parameters.h"
#include "runtime/model/description.h"

namespace autoshovel::control::testing {

inline constexpr double kDeg = std::numbers::pi / 180.0;
inline constexpr double kMachineStep = 0.01;  ///< the machine's integration step, 100 Hz [s]

struct Excavator {
  model::MachineDescription machine;
  const generated::MachineFunctions* functions = nullptr;
  std::unique_ptr<ExcavatorKinematics> kinematics;
  std::unique_ptr<LinkageEnvelope> envelope;
  ExcavatorModelDerivation derivation;
};

/// The shipped 25 t excavator, loaded once.
inline const Excavator& Excavator25t() {
  static const Excavator* const excavator = [] {
    auto* e = new Excavator;
    const std::string models_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
    e->machine = model::LoadMachineDescription(
        model::ResolveMachineDescription("excavator_25t", models_dir));
    e->functions = generated::FindMachine("excavator_25t");
    if (e->functions == nullptr) throw std::runtime_error("no generated code for excavator_25t");
    e->kinematics = std::make_unique<ExcavatorKinematics>(e->machine, *e->functions);
    e->envelope =
        std::make_unique<LinkageEnvelope>(*e->kinematics, DefaultEnvelopeConfig(e->machine));
    e->derivation = DeriveJointModels(e->machine, *e->functions, DefaultReferencePose(),
                                      e->machine.bucket.rated_load);
    return e;
  }();
  return *excavator;
}

/// A 20 t tipper parked beside the excavator: the body's centre at `radius` from the swing axis
/// at azimuth `azimuth`, its long axis tangential, the cab on the side away from the dig
/// (`cab_side` +1: towards larger azimuths). Body 5.6 m × 2.5 m outside with its rim 2.8 m up,
/// cab 2.0 m × 2.5 m and 3.2 m high, 0.3 m in front of the body: rounded figures of 20 t
/// six-wheel tippers.
struct Truck {
  ObstacleBox body, cab;
  std::vector<ObstacleBox> boxes() const { return {body, cab}; }
};

inline Truck Truck20t(double azimuth, double radius, double cab_side = 1.0) {
  Truck t;
  const Eigen::Vector2d center = radius * Eigen::Vector2d(std::cos(azimuth), std::sin(azimuth));
  const Eigen::Vector2d along(-std::sin(azimuth), std::cos(azimuth));  // tangential
  t.body.center = center;
  t.body.yaw = std::atan2(along.y(), along.x());
  t.body.half_extents = Eigen::Vector2d(2.8, 1.25);
  t.body.z_max = 2.8;
  t.cab.center = center + cab_side * (2.8 + 0.3 + 1.0) * along;
  t.cab.yaw = t.body.yaw;
  t.cab.half_extents = Eigen::Vector2d(1.0, 1.25);
  t.cab.z_max = 3.2;
  return t;
}

/// The state when digging finished: the bucket curled just out of the ground in front.
inline ExcavatorState DigEnd(double swing = 0.0) {
  ExcavatorState s;
  s.q = JointVector(15 * kDeg, -105 * kDeg, -140 * kDeg, swing);
  return s;
}

/// The standard pass: dig 7 m ahead on flat ground, the truck at 90°, 6 m out, dump at the
/// body's centre on a 1.9 m high heap (below the rim).
inline LoadingGoal StandardGoal(const Truck& truck) {
  LoadingGoal goal;
  goal.p_base_dig = Eigen::Vector3d(7.0, 0.0, 0.0);
  goal.p_base_dump = Eigen::Vector3d(truck.body.center.x(), truck.body.center.y(), 1.9);
  goal.truck = truck.boxes();
  goal.ground_height = 0.0;
  return goal;
}

/// A flat 40 m × 40 m map at ground level around the excavator, `resolution` cells.
inline HeightGrid FlatMap(double resolution = 0.1) {
  const int n = static_cast<int>(std::lround(40.0 / resolution));
  return HeightGrid(Eigen::Vector2d(-20.0, -20.0), resolution, n, n, 0.0);
}

/// What one closed-loop run did, sampled at 100 Hz.
struct RunSample {
  double time = 0;
  ExcavatorState state;
  std::array<int, kNumExcavatorJoints> active_rule{};
  JointVector command = JointVector::Zero();
  bool stopped = false;
};

struct RunOptions {
  double max_time = 40.0;
  /// Look-ahead consulted after every script evaluation; its stop is applied at once.
  const ObstacleLookAhead* lookahead = nullptr;
  const HeightGrid* map = nullptr;
  /// Called at every 100 Hz sample (after the step); the test's own checks.
  std::function<void(const RunSample&)> observe;
  /// Runs on after the pass finishes or the machine stops, until every joint is at rest.
  bool settle_after_stop = true;
};

struct RunResult {
  bool finished = false;
  double finish_time = -1;  ///< script Finished [s]
  bool stopped = false;
  double stop_time = -1;  ///< when the look-ahead first reported [s]
  LookAheadResult first_report;
  LookAheadResult stop_prediction;  ///< CheckStop at the first report
  int lookahead_checks = 0;
  std::vector<RunSample> samples;
};

/// The machine is `machine_models` at 100 Hz from `start`; the script runs at 10 Hz on the
/// machine's state. With a look-ahead, a reported collision stops the machine at once (the stop
/// is issued at the same tick) and the script is no longer evaluated.
inline RunResult RunPass(LoadingScript script, const ExcavatorJointModels& machine_models,
                         const ExcavatorState& start, const ScriptSettings& settings,
                         const RunOptions& options = {}) {
  ExcavatorSimulator machine(machine_models, start, kMachineStep);
  RunResult result;
  const int steps_per_tick = static_cast<int>(std::lround(LoadingScript::kPeriod / kMachineStep));
  const long max_steps = std::lround(options.max_time / kMachineStep);
  JointVector command = start.q;
  std::array<int, kNumExcavatorJoints> active{};
  for (long step = 0; step < max_steps; ++step) {
    if (step % steps_per_tick == 0 && !result.stopped) {
      const ScriptOutput out = script.Step(machine.state().q);
      machine.Command(out.command);
      command = out.command.position;
      active = out.active_rule;
      if (options.lookahead != nullptr) {
        ++result.lookahead_checks;
        const LookAheadResult report =
            options.lookahead->Check(machine.state(), machine, &script, LoadingScript::kPeriod,
                                     *options.map, Eigen::Isometry3d::Identity());
        if (report.stop()) {
          result.stopped = true;
          result.stop_time = step * kMachineStep;
          result.first_report = report;
          result.stop_prediction = options.lookahead->CheckStop(
              machine.state(), machine, *options.map, Eigen::Isometry3d::Identity());
          machine.Command(ExcavatorCommand{JointVector::Zero(), true});
        }
      }
    }
    machine.Advance(kMachineStep);
    RunSample sample{(step + 1) * kMachineStep, machine.state(), active, command, result.stopped};
    if (options.observe) options.observe(sample);
    result.samples.push_back(sample);
    if (!result.finished && !result.stopped &&
        script.Finished(machine.state(), settings.arrival_tolerance, settings.settle_velocity)) {
      result.finished = true;
      result.finish_time = sample.time;
      if (!options.settle_after_stop) break;
    }
    if ((result.finished || result.stopped) && options.settle_after_stop &&
        machine.state().qd.cwiseAbs().maxCoeff() < 1e-6 &&
        sample.time > (result.stopped ? result.stop_time : result.finish_time) + 0.5) {
      break;
    }
  }
  return result;
}

/// Lowest signed distance [m] of the underside (all three links) to `boxes` over `samples`, with
/// MinClearance (ObstacleBox::SignedDistance in bulk, checked against it in
/// kinematics_envelope_test.cc) on samples of its own, independent of LinkageClearance's and of
/// the map's.
/// Every state is measured on 0.1 m samples, which over-estimate by at most 0.1/√2 m; the states
/// that can hold the minimum (within that of the lowest) are measured again on 0.03 m samples
/// (at most 0.021 m). Stops early once a coarse value is below `stop_below`.
inline double MinUndersideDistance(const std::vector<RunSample>& samples,
                                   const std::vector<ObstacleBox>& boxes,
                                   double stop_below = -1e9) {
  static const auto envelopes = [] {
    const Excavator& e = Excavator25t();
    EnvelopeConfig coarse = DefaultEnvelopeConfig(e.machine);
    coarse.max_spacing = 0.1;
    EnvelopeConfig fine = coarse;
    fine.max_spacing = 0.03;
    return std::make_pair(std::make_unique<LinkageEnvelope>(*e.kinematics, coarse),
                          std::make_unique<LinkageEnvelope>(*e.kinematics, fine));
  }();
  const double coarse_error = 0.1 / std::sqrt(2.0);
  std::vector<EnvelopePoint> points;
  auto distance = [&](const LinkageEnvelope& envelope, const JointVector& q) {
    envelope.Underside(q, Eigen::Isometry3d::Identity(), points);
    return MinClearance(points, boxes);
  };
  std::vector<double> coarse(samples.size(), 1e9);
  double lowest = 1e9;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    coarse[i] = distance(*envelopes.first, samples[i].state.q);
    lowest = std::min(lowest, coarse[i]);
    if (lowest < stop_below) return lowest;
  }
  double refined = lowest;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (coarse[i] < lowest + coarse_error) {
      refined = std::min(refined, distance(*envelopes.second, samples[i].state.q));
    }
  }
  return refined;
}

/// The joint models with the swing's speed and acceleration scaled by `factor`.
inline ExcavatorJointModels WithSwingFactor(ExcavatorJointModels models, double factor) {
  JointModelParams& swing = models[JointIndex(ExcavatorJoint::kSwing)];
  swing.max_velocity_up *= factor;
  swing.max_velocity_down *= factor;
  swing.max_acceleration *= factor;
  return models;
}

}  // namespace autoshovel::control::testing
