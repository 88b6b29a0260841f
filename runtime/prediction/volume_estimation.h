// Shoveling volume estimation, wheel-loader seed §6.1 (Fig. 9): the volume a single load takes is
// the current shoveled volume V1 plus the future volume V2 = V21 + V22.
//
// V1, Eq. (19):  V1 = Σ_{i∈Ω} (h_i − h'_i)·ε²   [m³]
//   Ω: the cells of the elevation map traversed by the bucket teeth, here the cells whose centre
//   lies within half the bucket width of the tip path's ground track (a straight strip per path
//   segment); h_i: the map height of cell i before the bucket reached it [m]; h'_i: the height of
//   the teeth when they pass over cell i [m] (interpolated along the segment; where several
//   segments pass over one cell the lowest tip counts, since that is where the cut is);
//   ε: the map resolution [m]. Cells where the teeth pass above the surface contribute nothing,
//   cells of unknown height (NaN) are skipped and counted.
//
// V2, our reading of §6.1 and §7.4.1 (Fig. 9, Fig. 21): from the instant the scoop is triggered the
// machine goes on travelling the predicted penetration depth d (the SVR of
// penetration_predictor.h) while
//   V21 — "Delay": for the hydraulic delay τ = transport delay + spool time constant of the
//         tilt valve (description `hydraulics.actuators[].valve`, with identified overlays), the
//         arm does not move and the teeth go on straight along the floor;
//   V22 — "Control": then the bucket curls at the rate its valve's rated flow gives through the
//         cylinder's lever arm (generated kinematics), and once curled the boom lifts; the machine
//         keeps moving until it has covered d.
// The machine's travel within d is by default a constant deceleration from the current speed v
// to rest over d: s(t) = v·t − v²·t²/(4d) for t ≤ 2d/v. A model that also predicts the travel
// at fixed times after the trigger (ScoopPlan::travel_at, penetration_predictor.h) replaces that
// shape: s(t) runs piecewise linear through (0, 0) and the predicted (t_k, s_k), then from the
// last knot at a constant deceleration from the last segment's speed to rest at d. Under a scoop
// that keeps pushing while it curls, how fast the machine loses speed depends on the pile: on a
// tall gravel cone it is 0.17 m behind the constant deceleration 2 s after the trigger, which
// puts the curling bucket where it never cuts (docs/scooping_control.md). The teeth follow
// Eq. (2) (planar two-link arm
// in the front frame) on that path; V21 and V22 are Eq. (19) over the past path extended by the
// two parts in turn, less what was already counted, so no cell is counted twice.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"

namespace autoshovel::prediction {

/// A height map in the world frame: cell (ix, iy) covers [origin.x + ix·ε, …) × [origin.y + iy·ε,
/// …); heights row-major (iy·nx + ix) [m], NaN where unknown. The plant's terrain and the semantic
/// elevation map both convert to it (a copy: the estimator never holds on to either).
struct HeightGrid {
  double resolution = 0.1;                           ///< ε [m]
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< world xy of cell (0, 0)'s corner [m]
  int nx = 0, ny = 0;
  std::vector<double> height;  ///< [m]

  bool InBounds(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < nx && iy < ny; }
  double at(int ix, int iy) const { return height[static_cast<std::size_t>(iy) * nx + ix]; }
  Eigen::Vector2d CellCenter(int ix, int iy) const {
    return origin + resolution * Eigen::Vector2d(ix + 0.5, iy + 0.5);
  }
  /// Height of the cell containing (x, y); NaN outside the grid or where unknown.
  double HeightAt(double x, double y) const;
};

struct SweptVolume {
  double volume = 0;      ///< Eq. (19) [m³]
  int cells = 0;          ///< |Ω|
  int unknown_cells = 0;  ///< cells of Ω with no height (not counted in `volume`)
};

/// Eq. (19) over the cells swept by the tip path `tip_path` (world points [m], in order of
/// travel) with a bucket of width `bucket_width` [m]. Throws std::invalid_argument for a width
/// ≤ 0 or a grid whose height vector does not match its size.
SweptVolume Eq19Volume(const HeightGrid& map, const std::vector<Eigen::Vector3d>& tip_path,
                       double bucket_width);

/// Bucket tip of a two-link loader arm in the base (front) frame, (x forward, z up) [m]: Eq. (2),
/// the arm pivot plus l1·(cos q1, sin q1) + l2·(cos(q1+q2), sin(q1+q2)).
Eigen::Vector2d TipInBase(const model::MachineDescription& machine, double q_boom, double q_bucket);

/// What the machine does after the scoop trigger, as V2 assumes it ("Just in & out" seed §6.2:
/// retract the bucket to an angle, then lift the boom).
struct ScoopPlan {
  double delay = 0;        ///< command to arm motion: transport delay + spool time constant [s]
  double bucket_rate = 0;  ///< bucket joint rate while curling [rad/s]
  double bucket_curl = 0;  ///< bucket joint travel of the curl [rad]
  double boom_rate = 0;    ///< boom joint rate while lifting [rad/s]
  double boom_lift = 0;    ///< boom joint travel of the lift [rad]
  /// Bucket joint rate at evenly spaced points of the curl, from q_bucket at the trigger (first)
  /// to q_bucket + bucket_curl (last) [rad/s]: the cylinder runs at the valve's flow over its
  /// area, and the joint rate follows the lever arm dL/dq along the stroke. On the XCMG-class
  /// arm the curl speeds up as the bucket racks back: from the attack pose the plant curls
  /// 0.82 rad in 2.63 s, this table predicts 2.70 s, the rate at the trigger alone 3.15 s
  /// (tests/prediction, PlanCurl). Empty: `bucket_rate` throughout.
  std::vector<double> bucket_rate_along_curl;
  /// Predicted travel [m] at `travel_times` [s after the trigger, increasing, > 0]. Both empty:
  /// the constant deceleration over d. A knot beyond d counts as d and one behind the knot
  /// before it as that one (a regression per knot need not be monotone).
  std::vector<double> travel_times;
  std::vector<double> travel_at;
  double time_step = 0.02;  ///< of the predicted path [s]
  double horizon = 8.0;     ///< the prediction stops here whatever happens [s]

  /// Empty when usable, else what is wrong (ceres Solver::Options::IsValid style).
  std::string Invalid() const;
};

/// The bucket's curl against time as V2 assumes it: still through the delay, then at the rate
/// along the stroke (ScoopPlan::bucket_rate_along_curl) until `bucket_curl` [rad].
struct CurlSchedule {
  std::vector<double> curl;  ///< joint travel at t = k·time_step, k = 0.. (to the horizon) [rad]
  double t_curled = 0;       ///< when the curl is complete (the horizon if never) [s]
};
CurlSchedule PlanCurl(const ScoopPlan& plan);

/// The plan for machine `machine` at joint positions `q` with the scoop commands `bucket_command`
/// and `boom_command` (valve fractions in (0, 1]): delays from the description's valves, joint
/// rates from the valves' rated flow over the cap area times the lever arm dL/dq (`functions`,
/// generated). Throws std::invalid_argument for an arm that is not a two-link loader arm.
ScoopPlan ScoopPlanFromMachine(const model::MachineDescription& machine,
                               const generated::MachineFunctions& functions,
                               const std::vector<double>& q, double bucket_command,
                               double boom_command, double bucket_curl, double boom_lift);

/// The machine at the trigger instant, as proprioception and localisation give it.
struct MachineAtTrigger {
  Eigen::Vector2d hinge_xy = Eigen::Vector2d::Zero();  ///< world [m]
  double heading = 0;                                  ///< [rad]
  double speed = 0;                                    ///< [m/s]
  std::vector<double> q;                               ///< boom, bucket joints [rad]
};

struct FutureVolume {
  double v21 = 0;  ///< delay part [m³]
  double v22 = 0;  ///< control part [m³]
  double total() const { return v21 + v22; }
  std::vector<Eigen::Vector3d> path;  ///< the predicted tip path, world [m]
  int delay_points = 0;               ///< the first `delay_points` of `path` belong to V21
};

/// V2 = V21 + V22 for a predicted penetration `penetration` [m] from the trigger instant, over
/// the map `map` (heights before the bucket came), the tip path so far `past_path` (counted in V1,
/// may be empty) and the scoop `plan`. Throws std::invalid_argument for an invalid plan, a NaN
/// or negative penetration or a machine state without two joints.
FutureVolume PredictFutureVolume(const model::MachineDescription& machine, const HeightGrid& map,
                                 const std::vector<Eigen::Vector3d>& past_path,
                                 const MachineAtTrigger& at_trigger, double penetration,
                                 const ScoopPlan& plan);

}  // namespace autoshovel::prediction
