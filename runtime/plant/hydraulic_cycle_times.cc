#include "runtime/plant/hydraulic_cycle_times.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "runtime/model/interpreted_model.h"
#include "runtime/model/spec_sheet.h"
#include "runtime/plant/plant.h"

namespace autoshovel::plant {
namespace {

// Lowest point of the bucket profile above the ground at pose q [m].
double BucketClearance(const model::MachineDescription& m, const model::InterpretedModel& model,
                       const double* q) {
  std::vector<model::V2<double>> origins;
  std::vector<double> angles;
  model.LinkFrames(q, origins, angles);
  double lowest = 1e300;
  for (const Eigen::Vector2d& p : m.bucket.profile) {
    const model::V2<double> point = origins[1] + model::internal::Rotate(angles[1], p);
    lowest = std::min(lowest, m.arm_pivot.y() + point.z);
  }
  return lowest;
}

// Sign of the valve command that moves joint `joint` upwards (extension raises it: +1).
double UpwardCommand(const model::MachineDescription& m, const model::InterpretedModel& model,
                     const double* q, int joint) {
  const int actuator = m.ActuatorOfJoint(joint);
  return model.LeverArms(actuator, q)[joint] >= 0 ? 1.0 : -1.0;
}

// Holds `command` until `reached` or the time limit; returns the time taken or −1.
template <typename Reached>
double Stopwatch(Plant& plant, const core::ActuatorCommand& command, double tick, double limit,
                 Reached reached) {
  const double start = plant.time();
  if (!plant.SetCommand(command)) throw std::runtime_error("cycle times: command refused");
  while (plant.time() - start < limit) {
    plant.Advance(tick);
    if (reached(plant.state())) return plant.time() - start;
  }
  return -1.0;
}

// The bucket racked back fully at boom angle `boom`: its joint limit, or as far as a frame-mounted
// tilt cylinder reaches there (its window slides with the boom).
double RackedBack(const model::MachineDescription& m, double boom) {
  std::vector<double> q = {boom, m.links[1].joint_max};
  if (!model::CylinderMovesWithEarlierJoints(m, 1)) return q[1];
  const model::JointWindow w = model::ReachableJointWindow(m, 1, q.data());
  return w.empty ? q[1] : std::min(q[1], w.max);
}

// Dumped fully at boom angle `boom`, likewise.
double Dumped(const model::MachineDescription& m, double boom) {
  std::vector<double> q = {boom, m.links[1].joint_min};
  if (!model::CylinderMovesWithEarlierJoints(m, 1)) return q[1];
  const model::JointWindow w = model::ReachableJointWindow(m, 1, q.data());
  return w.empty ? q[1] : std::max(q[1], w.min);
}

}  // namespace

double GroundBoomAngle(const model::MachineDescription& m) {
  const model::InterpretedModel model(m);
  const model::Link& boom = m.links[0];
  std::vector<double> q(m.num_joints(), 0.0);
  const auto racked = [&] { q[1] = RackedBack(m, q[0]); };
  // Clearance rises with the boom over its lower range: scan up in 0.1° steps, then bisect.
  const double step = 0.1 * 3.14159265358979 / 180;
  double low = boom.joint_min;
  q[0] = low;
  racked();
  if (BucketClearance(m, model, q.data()) >= 0) return low;
  double high = low;
  while (high < boom.joint_max) {
    high = std::min(high + step, boom.joint_max);
    q[0] = high;
    racked();
    if (BucketClearance(m, model, q.data()) >= 0) break;
    low = high;
  }
  for (int i = 0; i < 40; ++i) {
    q[0] = (low + high) / 2;
    racked();
    (BucketClearance(m, model, q.data()) >= 0 ? high : low) = q[0];
  }
  return high;
}

HydraulicCycleTimes SimulateHydraulicCycleTimes(const model::MachineDescription& m,
                                                const generated::MachineFunctions& functions,
                                                const CycleTimeOptions& options) {
  if (m.kind != model::MachineKind::kWheelLoader || m.links.size() != 2) {
    throw std::invalid_argument("hydraulic cycle times are defined for wheel loaders");
  }
  const model::InterpretedModel model(m);
  const model::Link& boom = m.links[0];
  const model::Link& bucket = m.links[1];
  HydraulicCycleTimes times;
  const double ground = GroundBoomAngle(m);
  times.start_pose = {ground, RackedBack(m, ground)};
  // A frame-mounted tilt cylinder may dump the bucket short of its limit at the top.
  const double dumped = Dumped(m, boom.joint_max);

  // A floor far below the arm: the motions touch nothing.
  World world;
  GridGeometry geometry;
  geometry.resolution = 0.5;
  geometry.nx = geometry.ny = 60;
  geometry.origin = Eigen::Vector2d(-15, -15);
  world.terrain = Terrain(geometry, -50.0);
  world.materials = m.materials;
  MachineState initial;
  initial.q = times.start_pose;
  Plant plant(m, functions, world, initial);

  const int boom_valve = m.ActuatorOfJoint(0), tilt_valve = m.ActuatorOfJoint(1);
  core::ActuatorCommand command;
  command.valve.assign(m.hydraulics.actuators.size(), 0.0);
  const double tol = options.end_tolerance;

  command.valve[boom_valve] = UpwardCommand(m, model, times.start_pose.data(), 0);
  times.raise = Stopwatch(plant, command, options.tick, options.time_limit,
                          [&](const MachineState& s) { return s.q[0] >= boom.joint_max - tol; });
  times.boom_end = plant.state().q[0];

  command.valve[boom_valve] = 0.0;
  command.valve[tilt_valve] = -UpwardCommand(m, model, plant.state().q.data(), 1);
  times.dump = Stopwatch(plant, command, options.tick, options.time_limit,
                         [&](const MachineState& s) { return s.q[1] <= dumped + tol; });

  command.valve[tilt_valve] = 0.0;
  command.valve[boom_valve] = -UpwardCommand(m, model, plant.state().q.data(), 0);
  const double bottom = times.start_pose[0];
  // The plant stops the bucket only where its cylinder ends: watch how far it goes past its
  // dumped limit (a limit no stop holds), through the lowering.
  times.bucket_past_dump_limit = std::max(0.0, bucket.joint_min - plant.state().q[1]);
  times.lower =
      Stopwatch(plant, command, options.tick, options.time_limit, [&](const MachineState& s) {
        times.bucket_past_dump_limit =
            std::max(times.bucket_past_dump_limit, bucket.joint_min - s.q[1]);
        return s.q[0] <= bottom + tol;
      });
  return times;
}

}  // namespace autoshovel::plant
