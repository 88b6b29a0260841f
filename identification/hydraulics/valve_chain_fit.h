// Identification of the valve chain (valve_chain_model.h) from step logs of one actuator, per
// command direction, in two stages:
//  1. command → pilot pressure (when the logs have a pilot channel): τ_p, T_p, the pilot map
//     a·max(0, |u| − u_0) + p_0, by output error on the pilot channel of every log;
//  2. pilot → motion: τ_m, T_m, the flow characteristic O (dead band + monotone values at the
//     duty levels), the angle gain G and the load coefficient κ, by output error on the joint
//     angle over the samples the data shows to be free (step_events.h), with one start angle
//     per segment. T_p comes from stage 1 when there is a pilot channel, else from stage 2.
// Both stages are bounded Levenberg–Marquardt fits (Ceres, automatic derivatives), each log
// weighted so that a long low-duty log does not outweigh the short high-duty ones.
//
// What is reported with every fit, per direction:
//  - the delay per duty level and per stage: τ_p and τ_m refitted on each level's logs alone,
//    every other parameter held;
//  - intervals from a bootstrap over the logs (resampled with replacement, refitted), the
//    Jacobian's σ beside them; parameters at a bound are flagged, not given a σ; pairs the data
//    cannot separate (|correlation| > 0.95 in the Jacobian) are named; the dead band is named
//    unidentified when the logs have one duty level;
//  - validation: leave-one-duty-level-out (fit on the other levels, predict the held-out
//    level's angle from its measured start: RMS over the 2 s after motion onset), high-load →
//    low-load prediction (logs split at the median load pressure), and the R² of the joint
//    rate on each log.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/step_events.h"

namespace autoshovel::identification {

struct ChainFitOptions {
  StepEventOptions events;
  double area_ratio = 0.5;  ///< α of p_L = p_A − α p_B (annulus / cap area)
  int bootstrap = 20;       ///< resamples; 0: none
  unsigned long long seed = 1;
  bool validate = true;  ///< leave-one-level-out and high → low load
  int max_iterations = 100;
  std::function<void(const std::string&)> progress;
};

/// A fitted value with what is known of its uncertainty.
struct Estimate {
  double value = 0;
  double sigma = 0;          ///< from the Jacobian (0 when at a bound or unavailable)
  double low = 0, high = 0;  ///< bootstrap 5–95 % (equal to value without bootstrap)
  bool at_bound = false;
  bool fixed = false;  ///< held, not fitted (e.g. κ without pressure channels)
};

struct LevelDelay {
  double level = 0;  ///< |duty| [-]
  std::size_t files = 0;
  double pilot_delay = 0;       ///< τ_p on this level's logs [s] (NaN without pilot)
  double motion_delay = 0;      ///< τ_p + τ_m on this level's logs [s]
  double threshold_motion = 0;  ///< median step → 0.3° moved [s] (a threshold reading)
};

struct FileReport {
  std::string file;
  double level = 0;
  std::size_t samples = 0, used = 0, stalled = 0;
  double relief_seen = 0;      ///< [Pa], 0: none
  double angle_rms = 0;        ///< fit, over the used samples [rad]
  double angle_rms_onset = 0;  ///< fit, over 2 s after motion onset [rad]
  double rate_r2 = 0;          ///< of the joint rate over the used samples
  double pilot_rms = 0;        ///< [bar], 0 without pilot
  double mean_load = 0;        ///< mean p_L over the used samples with the command on [Pa]
  std::vector<double> time, angle, angle_fit, pilot, pilot_fit;  ///< for figures [s, rad, bar]
  std::vector<char> excluded;
};

struct Prediction {
  std::string label;  ///< "60 %" or "high → low load"
  std::vector<std::string> files;
  double angle_rms_onset = 0;  ///< over 2 s after motion onset [rad], worst file
  double angle_rms = 0;        ///< over all used samples [rad], worst file
};

struct DirectionFit {
  int sign = 0;                ///< +1: positive commands, −1: negative
  std::vector<double> levels;  ///< the knots of O: duty levels [-]
  bool has_pilot = false, has_pressure = false;
  Estimate pilot_delay, pilot_time_constant, pilot_gain /*bar*/, pilot_threshold,
      pilot_offset /*bar*/;
  Estimate motion_delay, motion_lag, dead_band, load_coefficient, gain_linear, gain_quadratic;
  Estimate motion_lag_slope;  ///< T_m's growth at full opening [s] (valve_chain_model.h)
  /// The late supply (valve_chain_model.h): Q₁ [rad/s], τ_f, T_f [s].
  Estimate supply_capacity, supply_delay, supply_lag;
  std::vector<Estimate> rates;                    ///< O at the knots [rad/s]
  double load_reference = 0;                      ///< p̄_L [Pa]
  double angle_center = 0, angle_half_range = 1;  ///< of G [rad]
  std::vector<std::string> notes;                 ///< unidentified parameters, inseparable pairs
  std::vector<LevelDelay> level_delays;
  std::vector<FileReport> files;
  std::vector<Prediction> leave_one_level_out;
  std::vector<Prediction> load_transfer;
  double angle_sigma = 0, pilot_sigma = 0;  ///< residual RMS [rad], [bar]
  double seconds = 0;
};

struct ChainIdentification {
  std::vector<DirectionFit> directions;
};

/// Fits both directions present in the logs. Throws core::InputError naming the file and row
/// when a log's joint moves against its command (saying which column to negate), or when a
/// direction has no log in which the joint moves.
ChainIdentification IdentifyValveChain(const std::vector<HydraulicLog>& logs,
                                       const ChainFitOptions& options = {});

}  // namespace autoshovel::identification
