// The refined dig planner (excavator seed §4.2, Fig. 13): within one dig region from the coarse
// planner, choose the "best" dig that "meets geometric constraints (reachability and
// collisions)" and "locally optimizes a cost function (e.g. volume, energy, time)". It searches
// compact task parameters (DigAction: where the bucket starts, how deep, how long a drag), not
// bucket trajectories, and scores each candidate through a forward model that simulates the dig.
//
// Plan(region, map, model, keep_out) does, in order:
//   1. enumerate the candidate grid in the region (candidate_grid.h), entry heights from the map;
//      unknown (NaN) surface and points without material in the band are rejected;
//   2. reject, without calling the forward model, candidates that are unreachable (E, P or D of
//      the nominal tip path not solvable within the joint limits at a digging attitude) or whose
//      nominal tip path meets the undercarriage radius or a keep-out box (dig_geometry.h);
//   3. ask the forward model about the survivors, at most `max_evaluations` of them
//      (budgeted_search.h: all of them when they fit, else the most promising by the volume
//      their nominal path sweeps out of the map, swept_volume.h, then local refinement around
//      the best prediction), re-check the returned tip path for collisions, and score the usable
//      predictions with the cost (dig_cost.h); a prediction that is not executed, not finite or
//      negative, or that takes less than `min_volume`, is rejected (never selected);
//   4. return the lowest-cost candidate (ties: the first in grid order), or kNoFeasibleDig with a
//      reason that counts the rejections by kind.
// Every candidate is returned with its status, its reason and, when evaluated, its prediction
// and cost terms, for reports.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/control/excavator/height_grid.h"
#include "runtime/control/excavator/obstacle_box.h"
#include "runtime/model/description.h"
#include "runtime/planning/dig/candidate_grid.h"
#include "runtime/planning/dig/dig_action.h"
#include "runtime/planning/dig/dig_cost.h"
#include "runtime/planning/dig/dig_geometry.h"
#include "runtime/planning/dig/dig_region.h"

namespace autoshovel::planning {

struct RefinedDigConfig {
  DigGridConfig grid;
  DigGeometryConfig geometry;
  DigCostConfig cost;
  /// Width of the bucket [m] (> 0), for the swept-volume screening (swept_volume.h).
  double bucket_width = 1.3;
  /// A dig predicted to take less than this is not worth its cycle [m^3] (>= 0): when only such
  /// digs are left in a region the plan is kNoFeasibleDig, and the coarse planner's caller
  /// marks the region exhausted instead of scraping it for ever.
  double min_volume = 0.1;
  /// Forward-model calls per plan, at most (>= 1). With the default grid a region has up to a
  /// few hundred geometric survivors; 40 dig simulations keep a plan to seconds on the plant.
  int max_evaluations = 40;
  /// Of those, how many go to the most promising candidates by swept-volume screening before
  /// local refinement starts, when the survivors do not all fit (in [1, max_evaluations]).
  int coarse_evaluations = 16;
};

/// The defaults with the machine's figures: V_cap = bucket.rated_capacity (heaped), the bucket
/// width and the undercarriage radius from the track frame (UndercarriageRadius). Throws
/// std::invalid_argument when the description lacks them.
RefinedDigConfig DefaultRefinedDigConfig(const model::MachineDescription& machine);

/// Throws std::invalid_argument naming the field ("RefinedDigConfig.grid.depth_max: ...").
void Validate(const RefinedDigConfig& config);

enum class DigCandidateStatus {
  kScored,          ///< evaluated, usable, clear of collisions: has a cost
  kUnknownSurface,  ///< no surface known at the entry point
  kNoMaterial,      ///< nothing of the region's band to cut there
  kRepeatedCut,     ///< same cut as a shallower depth sample
  kUnreachable,     ///< E, P or D out of reach within the joint limits at a digging attitude
  kCollision,       ///< nominal tip path meets the undercarriage or a keep-out box
  kNotEvaluated,    ///< geometrically feasible, left out by the evaluation budget
  kNotExecuted,     ///< the forward model's prediction is not usable (not executed, NaN, < 0)
  kTooLittle,       ///< the prediction takes less than min_volume
  kPathCollision,   ///< the forward model's tip path meets the undercarriage or a keep-out box
};
std::string_view ToString(DigCandidateStatus status);

struct DigCandidate {
  std::array<int, 4> grid_index{};  ///< swing, radius, depth, drag sample
  DigAction action;
  DigCandidateStatus status = DigCandidateStatus::kNotEvaluated;
  std::string why;           ///< reason for any status but kScored and kNotEvaluated
  double swept_volume = 0;   ///< screening estimate V̂ [m^3] (geometric survivors only)
  bool evaluated = false;    ///< the forward model was called for it
  DigPrediction prediction;  ///< when evaluated
  DigCostTerms cost;         ///< when kScored; NaN terms otherwise
};

enum class DigPlanStatus { kPlanned, kNoFeasibleDig };

struct DigPlan {
  DigPlanStatus status = DigPlanStatus::kNoFeasibleDig;
  std::string why;  ///< for kNoFeasibleDig: the counts of each rejection
  int chosen = -1;  ///< index into `candidates`
  DigAction action;
  DigPrediction prediction;
  DigCostTerms cost;
  std::vector<DigCandidate> candidates;  ///< the whole grid, in grid order
  int geometric_survivors = 0;           ///< candidates that passed steps 1–2
  int evaluations = 0;                   ///< forward-model calls made
};

class RefinedDigPlanner {
 public:
  /// Copies both. Throws std::invalid_argument on an invalid config.
  RefinedDigPlanner(const control::ExcavatorKinematics& kinematics, const RefinedDigConfig& config);

  /// The best dig in `region` on `map_base` (terrain in the excavator base frame, NaN unknown),
  /// with `keep_out_base` (base frame: the truck, anything the bucket must not touch) as
  /// obstacles. Throws std::invalid_argument when the region is not a finite, non-empty polar
  /// box. A plan without a feasible dig is a status, not an exception.
  DigPlan Plan(const DigRegion& region, const control::HeightGrid& map_base, DigForwardModel& model,
               const std::vector<control::ObstacleBox>& keep_out_base = {}) const;

  /// Steps 1 and 2 only: every grid candidate, with the geometric survivors as kNotEvaluated.
  std::vector<DigCandidate> GeometricCandidates(
      const DigRegion& region, const control::HeightGrid& map_base,
      const std::vector<control::ObstacleBox>& keep_out_base = {}) const;

  const RefinedDigConfig& config() const { return config_; }

 private:
  RefinedDigConfig config_;
  DigReachability reachability_;
};

}  // namespace autoshovel::planning
