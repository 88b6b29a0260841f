// Tuning the Eq. (18) weights k_t, k_s, k_c, k_e, k_a on expert demonstrations by CMA-ES
// (wheel-loader seed §5, Table 1).
//
// The five scores of a candidate do not depend on the weights, so Algorithm 2 runs once per
// demonstration (ScoreDemonstration) and each weight vector is then judged by an argmax over
// the stored scores: thousands of CMA-ES evaluations cost seconds.
//
// Objective: the mean distance between the point Eq. (18) selects and the expert's point, over
// the training demonstrations. It is piecewise constant in the weights, and CMA-ES stalls on
// its plateaus (a hidden Eq. (18) expert was not recovered that way: 9 % of the training picks
// stayed wrong), so CMA-ES ranks its samples by the softmax-expected distance
// (ExpectedDistance, temperature T in units of F) and the result is the sample with the best
// hard objective.
//
// Parameters: F's argmax is unchanged by scaling all weights, so the search runs over four
// log-ratios z_i = ln(k_i / k_a) (k_a's log fixed at 0) and the result is normalised to sum to
// 1, like Table 1's. A box of ±6 on each keeps every weight within e^±6 of k_a.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "identification/weights/demonstration_store.h"
#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::identification {

/// k_t, k_s, k_c, k_e, k_a in the order of Eq. (18).
using ShovelWeights = std::array<double, 5>;

ShovelWeights WeightsOf(const planning::ShovelPointConfig& config);

/// The weight-independent part of Algorithm 2 on one demonstration.
struct ScoredDemonstration {
  int id = 0;
  /// Feasible candidates in candidate order (pile, point, angle): their five scores and the
  /// distance from their entry point to the expert's [m].
  std::vector<std::array<double, 5>> scores;
  std::vector<double> distance_to_expert;
  double nearest = 0;  ///< the smallest distance any candidate reaches [m] (+inf: none)
};

ScoredDemonstration ScoreDemonstration(const Demonstration& demonstration,
                                       const planning::LoaderGeometry& loader,
                                       const planning::ShovelPointConfig& config);

/// The distance from the candidate Eq. (18) selects with `weights` to the expert's point
/// (+inf when the demonstration has no feasible candidate). Ties go to the first candidate.
double SelectedDistance(const ScoredDemonstration& scored, const ShovelWeights& weights);

/// The distance to the expert's point expected under a softmax choice, p_i ∝ exp(F_i / T):
/// SelectedDistance as T → 0, smooth in the weights for T > 0 (+inf without candidates).
double ExpectedDistance(const ScoredDemonstration& scored, const ShovelWeights& weights,
                        double temperature);

/// Agreement with the expert over a set of demonstrations.
struct Agreement {
  int demonstrations = 0;
  int without_candidates = 0;          ///< no feasible candidate: counted as disagreeing
  double mean_distance = 0;            ///< over those with candidates [m]
  double median_distance = 0;          ///< [m]
  double within_1m = 0;                ///< fraction of all demonstrations with distance ≤ 1 m
  double within_2m = 0;                ///< ≤ 2 m
  double best_possible_within_1m = 0;  ///< fraction where some candidate is within 1 m
};

Agreement MeasureAgreement(const std::vector<ScoredDemonstration>& set,
                           const ShovelWeights& weights);

struct WeightTuningOptions {
  int max_evaluations = 3000;
  double sigma0 = 0.7;  ///< initial step in the log-ratios
  /// T of the softmax surrogate [units of F]; F's scores span about 1, neighbouring
  /// candidates differ by a few hundredths.
  double temperature = 0.01;
  std::uint64_t seed = 1;
  /// Called after every CMA-ES generation: evaluations so far, best objective so far [m].
  std::function<void(int, double)> progress;
};

struct WeightTuningResult {
  ShovelWeights weights{};  ///< normalised to sum to 1
  double objective = 0;     ///< mean selected-to-expert distance on the training set [m]
  int evaluations = 0;
  std::string stop_reason;
};

/// CMA-ES from `initial` (normalised first). Throws std::invalid_argument for an empty set or
/// a non-positive initial weight.
WeightTuningResult TuneWeights(const std::vector<ScoredDemonstration>& training,
                               const ShovelWeights& initial, const WeightTuningOptions& options);

}  // namespace autoshovel::identification
