// Shovel point selection (wheel-loader seed §5, Algorithm 2): candidate points along the front
// of each pile (the boundary cells that border ground, spaced `candidate_spacing` apart) times a
// set of entry angles; for each, a curvature-bounded forward path from the loader's pose
// (dubins_path.h) and five scores, weighted into one (Eq. 18), ranked.
//
//   Eq. (12)  T_c = Σ_{ij∈Ω} h_ij λ_i                        torque about the bucket centre line
//   Eq. (13)  s_t = 1 − (T_c/T_res)²  if |T_c| < T_res, else −∞
//   Eq. (14)  s_s = 1 if d_min > d_res;  d_min/d_res if d_min > 0;  else −∞
//   Eq. (15)  s_c = 1 if V_m ≥ max(V_l, V_r), else 0         three-section bucket model
//   Eq. (16)  s_e = (l_max − l_im)/(l_max − l_min)            over the pile's candidates
//   Eq. (17)  s_a = 1 − |κ_im|/κmax                           end-of-path curvature
//   Eq. (18)  F = k_t s_t + k_s s_s + k_c s_c + k_e s_e + k_a s_a
//
// Readings of what the seed leaves open (each explained where it is implemented, and in
// docs/shovel_point_selection.md):
// - Ω, the area the bucket covers, is the rectangle of the bucket's width from the entry point
//   `penetration_length` metres into the pile along the entry heading; the same rectangle,
//   split in three across, is the "future shoveling area" of Eq. (15). h_ij is the pile
//   cell's height above the fitted ground plane (ground cells contribute 0), and each cell
//   stands for its area ε², so T_c is a first moment of volume [m⁴] and V_* are volumes [m³],
//   independent of the map resolution.
// - Eq. (13) compares the signed T_c with T_res; a large negative (right-heavy) moment is as
//   dangerous as a positive one, so |T_c| is compared. T_res is not in Table 1: by default the
//   moment of a rated bucket load sitting wholly in one half of the bucket, V_rated · w / 4.
// - d_res and κmax are not in Table 1 either: d_res defaults to 1 m; κmax is the front axle's
//   curvature at full articulation (dubins_path.h), checked against the description.
// - κ_im of Eq. (17) is the mean |κ| over the last `entry_window` metres of the path: a Dubins
//   path's curvature jumps, and the articulation at entry lags the curvature by the articulation
//   rate limit, so one instant would make s_a a 0/1 flag of the last segment's type.
// - Algorithm 2 scores every candidate and keeps the maximum; here all candidates are kept,
//   ranked (the top 20 are drawn, seed Fig. 19). A candidate with s_t or s_s = −∞, or whose
//   path drives the chassis over the pile, is infeasible: F = −∞, ranked after the others.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"
#include "runtime/perception/grid_map.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/planning/dubins_path.h"

namespace autoshovel::planning {

inline constexpr double kMinusInfinity = -std::numeric_limits<double>::infinity();

/// The loader's planar geometry as the selection needs it (front frame, hinge origin).
struct LoaderGeometry {
  double hinge_to_front_axle = 0;  ///< l_f [m]
  double hinge_to_rear_axle = 0;   ///< l_r [m]
  double max_articulation = 0;     ///< γmax [rad]
  double track_width = 0;          ///< [m]
  double wheel_radius = 0;         ///< [m]
  double bucket_width = 0;         ///< w [m]
  double rated_capacity = 0;       ///< heaped bucket volume [m³]
  double tip_reach = 0;            ///< hinge → bucket tip, bucket on the floor, horizontal [m]
  double rear_overhang = 2.5;      ///< rear axle → counterweight [m] (machine_footprint.h)
  double body_margin = 0.3;        ///< added to the body outline on every side [m]

  /// κmax = sin γmax / (l_f cos γmax + l_r): the front axle's path curvature at full
  /// articulation (plant.cc steering kinematics with γ̇ = 0) [1/m].
  double MaxCurvature() const;
  /// The articulation γ that holds the front axle on a path of curvature κ (inverse of the
  /// relation above; |κ| ≤ κmax) [rad].
  double ArticulationFor(double curvature) const;
  /// Half the width of the body outline: the wider of bucket and tyres, plus the margin [m].
  double HalfWidth() const;
};

/// Geometry from a wheel-loader description, the tip reach with the bucket level on the floor
/// by the generated forward kinematics (Eq. 2). Throws std::invalid_argument for a machine that
/// is not a two-link wheel loader.
LoaderGeometry LoaderGeometryFrom(const model::MachineDescription& machine,
                                  const generated::MachineFunctions& functions);

struct ShovelPointConfig {
  // Seed Table 1: the weights of Eq. (18), tuned by CMA-ES on 482 expert scenarios.
  double k_t = 0.29;  ///< torque balance
  double k_s = 0.23;  ///< safety distance
  double k_c = 0.13;  ///< concavity
  double k_e = 0.25;  ///< efficiency
  double k_a = 0.10;  ///< entry angle
  // Safety thresholds of Algorithm 2 (not in Table 1; see the file comment).
  double torque_threshold = 0;   ///< T_res [m⁴]; ≤ 0: V_rated · w / 4 from the machine
  double safety_distance = 1.0;  ///< d_res [m]
  double max_curvature = 0;      ///< κmax [1/m]; ≤ 0: from the articulation limit
  // Candidates.
  double candidate_spacing = 1.0;  ///< along the pile front [m]
  /// Entry headings relative to the pile's inward normal at the point [rad] (Δ of Alg. 2).
  std::vector<double> entry_angle_offsets = {-0.5236, -0.2618, 0.0, 0.2618, 0.5236};
  double normal_radius = 1.5;  ///< cells within this of a point give its inward normal [m]
  // Scores.
  double penetration_length = 2.0;  ///< Ω's depth into the pile along the heading [m]
  /// Eq. (14)'s A is "the area covered by the loader during the process": the approach path and
  /// then the scoop, which drives the machine on along the entry heading after the bucket meets
  /// the pile. d_min also covers the body's sides and rear driven straight on this much [m]
  /// (ScoopSideClearance).
  double scoop_advance = 2.0;
  /// The scoop drives on only while the nearest obstacle to the middle of the front edge is
  /// farther than this [m]: the main job's look-ahead ends the crowd there (safety distance,
  /// planning margin, a map cell and a stopping allowance), so what lies beyond is met head on
  /// and never reached. 0: the scoop always drives the whole scoop_advance. The default is the
  /// main job's: 0.5 + 0.15 + 0.3 + 0.5 m.
  double crowd_stop_distance = 1.45;
  /// Eq. (15) counts a flat face as convex (V_m ≥ max{V_l, V_r}). On a perceived map a flat
  /// face's sections differ by the map's noise, and the binary score then flips on it: 0.13 of
  /// F (k_c) from one 7 Hz map to the next, which sent re-selection round a pile. A middle
  /// section within this fraction of the larger side counts as flat, hence convex [-].
  double concavity_tolerance = 0.05;
  double entry_window = 3.0;  ///< the end of the path whose mean |κ| is κ_im [m]
  // Paths.
  double path_spacing = 0.25;  ///< sampling of the planned path [m]
  /// The tyres may roll onto the pile's toe up to this height; higher pile cells under the
  /// chassis (hinge, axles, counterweight; the bucket excepted) make the path infeasible [m].
  double max_drive_over_height = 0.3;
  int pile = -1;  ///< index into the piles to select on; −1: every pile

  /// "" when valid, else what is wrong (the first problem found).
  std::string Validate() const;
};

/// The five scores of one candidate and the quantities behind them.
struct ScoreBreakdown {
  double s_t = 0, s_s = 0, s_c = 0, s_e = 0, s_a = 0;
  double torque = 0;                      ///< T_c, Eq. (12) [m⁴], left heavy positive
  double min_obstacle_distance = 0;       ///< d_min, Eq. (14): approach and scoop [m] (+inf: none)
  double approach_obstacle_distance = 0;  ///< d_min of the approach path alone [m]
  double volume_left = 0, volume_middle = 0;  ///< V_l, V_m, Eq. (15) [m³]
  double volume_right = 0;
  double path_length = 0;         ///< l_im, Eq. (16) [m]
  double entry_curvature = 0;     ///< κ_im, Eq. (17): mean |κ| over the entry window [1/m]
  double end_curvature = 0;       ///< κ at the path's last point [1/m] (for reference)
  double entry_articulation = 0;  ///< γ for κ_im [rad]
};

/// A point of the pile front and an entry heading: one (x_i, y_i, δ_m) of Algorithm 2.
struct CandidatePose {
  int pile = 0;                                  ///< index into the piles given
  int point = 0;                                 ///< index of the point along that pile's front
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< where the bucket tip meets the pile [m]
  double normal_heading = 0;                     ///< the pile's inward normal there [rad]
  double entry_offset = 0;                       ///< δ_m − normal heading [rad]
  double entry_heading = 0;                      ///< δ_m: the front frame's heading [rad]
};

struct ShovelCandidate {
  CandidatePose pose;
  Pose2 front_axle_goal;  ///< the path's end: front axle when the tip meets the pile
  DubinsPath path;        ///< of the front axle
  ScoreBreakdown scores;
  double score = kMinusInfinity;  ///< F, Eq. (18); −∞ when infeasible
  bool feasible = false;
  std::string infeasible;  ///< why not ("" when feasible)
};

enum class SelectionStatus { kSelected, kNoCandidates, kNoFeasibleCandidate, kInvalidInput };

struct ShovelPointResult {
  SelectionStatus status = SelectionStatus::kNoCandidates;
  std::string message;
  /// Every candidate, best first: feasible by F descending, then infeasible; ties keep the
  /// candidate order (pile, point, angle), so the ranking is deterministic.
  std::vector<ShovelCandidate> ranked;
  int feasible = 0;
  double max_curvature = 0;     ///< κmax used [1/m]
  double torque_threshold = 0;  ///< T_res used [m⁴]

  /// The selected candidate (x*, y*, δ*), or nullptr when none is feasible.
  const ShovelCandidate* best() const {
    return status == SelectionStatus::kSelected ? &ranked.front() : nullptr;
  }
};

/// Candidate points every `candidate_spacing` metres along each pile's front (boundary cells
/// bordering ground), each with the inward normal and every entry offset. Needs the "class"
/// layer.
std::vector<CandidatePose> GenerateCandidates(const perception::GridMap& map,
                                              const std::vector<perception::ExtractedPile>& piles,
                                              const ShovelPointConfig& config);

/// Algorithm 2. `map` holds "elevation" and "class" (perception::CellClass); `ground_plane`
/// (a, b, c) of z = a x + b y + c; `T_world_hinge` the loader's pose (hinge position, front
/// frame heading) now.
ShovelPointResult SelectShovelPoints(const perception::GridMap& map,
                                     const std::vector<perception::ExtractedPile>& piles,
                                     const Eigen::Vector3d& ground_plane,
                                     const Pose2& T_world_hinge, const LoaderGeometry& loader,
                                     const ShovelPointConfig& config = {});

// --- The scores one at a time (the equations, for tests and for the baseline) ---

/// Height of a cell above the ground plane if it is pile, 0 for any other known cell and for
/// unknown cells [m].
double PileHeightAboveGround(const perception::GridMap& map, const Eigen::Vector3d& ground_plane,
                             const perception::Index& index);

/// Eq. (12): T_c = Σ_{Ω} h_ij λ_i a_ij over Ω, the rectangle of `width` across and `length`
/// deep ahead of `entry` along `heading` (from half a cell behind it); a_ij is the area of the
/// cell inside Ω (cells count by their exact share, not by their centres) and λ_i the lateral
/// offset of that part's centroid from the bucket's centre line, left positive [m⁴].
double TorqueMoment(const perception::GridMap& map, const Eigen::Vector3d& ground_plane,
                    const Eigen::Vector2d& entry, double heading, double width, double length);
/// Eq. (13), with |T_c|.
double TorqueScore(double torque, double threshold);
/// Eq. (14).
double SafetyScore(double min_distance, double safety_distance);

struct SectionVolumes {
  double left = 0, middle = 0, right = 0;  ///< [m³]
};
/// The three-section bucket model of Eq. (15): the rectangle of TorqueMoment split into three
/// strips of width/3 across; volumes above the ground plane, each cell split between the
/// strips by area (exact polygon clipping), so that a level face gives three equal volumes
/// wherever the entry falls on the grid.
SectionVolumes ConcavityVolumes(const perception::GridMap& map, const Eigen::Vector3d& ground_plane,
                                const Eigen::Vector2d& entry, double heading, double width,
                                double length);
/// Eq. (15). Equal volumes (a flat face) count as convex (V_m ≥ max): the seed's "≥", here
/// V_m ≥ (1 − `tolerance`)·max{V_l, V_r}, a relative tolerance for the map's noise
/// (ShovelPointConfig::concavity_tolerance; 1e-9 leaves only rounding).
double ConcavityScore(const SectionVolumes& volumes, double tolerance = 1e-9);
/// Eq. (16); 1 when l_max = l_min (a single candidate, or all paths equally long).
double EfficiencyScore(double length, double min_length, double max_length);
/// Eq. (17).
double EntryAngleScore(double curvature, double max_curvature);
/// Eq. (18); −∞ if any score is −∞.
double WeightedScore(const ScoreBreakdown& scores, const ShovelPointConfig& config);

/// Mean |κ| over the last `window` metres of a sampled path (the whole path if shorter) [1/m].
double EntryCurvature(const std::vector<PathSample>& samples, double window);

/// Distance from every cell centre to the nearest obstacle cell centre (exact Euclidean
/// distance transform, Felzenszwalb & Huttenlocher 2012) [m]; +inf without obstacles.
Eigen::MatrixXf ObstacleDistanceField(const perception::GridMap& map);

/// d_min of Eq. (14) for a path: the least distance between the area the loader's body sweeps
/// along `samples` (front frame from the hinge to the tip, rear frame to the counterweight,
/// rear turned by the articulation that holds each sample's curvature) and the obstacle cells,
/// from `distance_field` (ObstacleDistanceField) [m]. Conservative by at most a cell. Exact
/// below `cap`; a clearance beyond it is returned as `cap` (the search stops refining there),
/// and the search ends at the first contact (the result then ≤ 0 but not the deepest).
double SweptObstacleDistance(const perception::GridMap& map, const Eigen::MatrixXf& distance_field,
                             const std::vector<PathSample>& samples, const LoaderGeometry& loader,
                             double cap = std::numeric_limits<double>::infinity());

/// The scoop's part of Eq. (14)'s A: the least distance from the obstacle cells to the loader
/// driving straight on from the contact pose (front axle at `front_axle_goal`) by `advance`
/// [m], sampled every `spacing`, the whole body (front frame to its front edge, rear frame)
/// at every step. The drive ends early at the first step whose front edge's middle lies nearer
/// than `crowd_stop_distance` to an obstacle: there the main job's look-ahead ends the crowd,
/// so what lies straight ahead of the bucket is never reached. Exact below `cap`, as
/// SweptObstacleDistance.
double ScoopSideClearance(const perception::GridMap& map, const Eigen::MatrixXf& distance_field,
                          const Pose2& front_axle_goal, const LoaderGeometry& loader,
                          double advance, double spacing, double crowd_stop_distance,
                          double cap = std::numeric_limits<double>::infinity());

const char* ToString(SelectionStatus status);

}  // namespace autoshovel::planning
