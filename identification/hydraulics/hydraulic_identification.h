// Hydraulic delay identification: per actuator, the valve dead zone d, transport delay τ_d,
// spool time constant τ_s and rated flow Q_rated, by output-error fitting of the valve–actuator
// model (valve_model.h) to step and chirp logs of that actuator, all files jointly.
//
// Wheel-loader seed §1, §7.4: scooping must be triggered ahead of time because of the hydraulic
// delay (~0.6 s from command to arm motion); the control and prediction stages need its parts.
//
// The fit (Ceres, bounded Levenberg–Marquardt, automatic derivatives):
//   min Σ_files Σ_samples [(q̂ − q)/σ_q]² + [(x̂_s − x_s)/σ_s]²       (spool term if logged)
// over θ = (d, τ_d, τ_s, Q_rated) and, as nuisance parameters, the motion lag τ_m (the joint's
// response shifted after the spool's; with spool feedback only) and the joint angle at the start of
// each segment of each file (a segment is a run of samples between end-stop contacts; samples
// at an end stop, the cylinder within `end_stop_margin` of its stroke end or a chamber within
// `relief_margin` of relief, are left out of the angle term, the arm being held by the stop
// and not by the flow). A logged spool pins τ_d, τ_s and d independently of the gain.
// σ_q and σ_s are the residual RMS of a first fit (then refit): the channels weigh by their
// own noise.
// Start: a scan of τ_d (10 ms steps) × a few τ_s and d, with Q_rated and the segment offsets
// solved linearly in the cylinder-length domain at each point; output-error costs have local
// minima in τ_d (a chirp repeats itself) and this scan starts the solver in the right basin.
// On long logs (over 20000 rows in all) the scan looks at the most active 2000-row windows up
// to that many rows, so that the whole identification stays linear in the log length. The
// least-squares problem has one residual block per segment (θ, τ_m, its start angle) and per
// chunk of spool rows (θ), solved by a Schur complement over the start angles: linear in the
// rows however many segments a log has (hydraulic_identification.cc, docs).
// Confidence: covariance σ² (JᵀJ)⁻¹ at the optimum, the nuisance parameters included (so the
// reported σ is marginal over them), each channel's rows weighted down by its residuals'
// lag-1 autocorrelation ρ, n_eff = n (1 − ρ)/(1 + ρ): unmodelled dynamics make neighbouring
// residuals alike, and treating them as independent would give intervals far too narrow.
// Cross-validation: files are grouped by duty level (largest |command|, to the percent); for
// each level, fit on the others and predict it (only its segment offsets fitted). With three
// or more levels the spread of the fold estimates gives a jackknife σ_L² = (g−1)/g Σ(θ_i − θ̄)²,
// which sees what the noise does not: model errors that change with the duty level (on the
// plant, its compensators' 2 bar dead band moves the flow by a few % from level to level).
// The reported 1σ combines both.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/valve_model.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {

struct HydraulicIdentificationOptions {
  ValveParameters lower{0.0, 0.0, 0.005, 1e-5};  ///< bounds of the fit
  ValveParameters upper{0.5, 2.0, 1.0, 0.2};
  bool exclude_end_stops = true;
  double end_stop_margin = 0.01;  ///< of cylinder stroke at either end [m]
  double relief_margin = 10e5;    ///< below the relief setting [Pa]
  double delay_scan_step = 0.01;  ///< of the starting scan [s]
  bool cross_validate = true;
  int max_iterations = 200;
  /// Called with one short line per stage of the fit ("fit pass 2 of 3"); empty: silent.
  std::function<void(const std::string&)> progress;
};

/// The fit seen on one file.
struct FileFit {
  std::string file;
  double level = 0;                            ///< largest |command| [-1, 1]
  std::vector<double> time, angle, angle_fit;  ///< [s], [rad]
  std::vector<double> spool, spool_fit;        ///< [-1, 1]; empty without spool feedback
  std::vector<char> excluded;                  ///< 1: at an end stop, out of the angle term
  double angle_rms = 0;                        ///< over the samples used [rad]
  double spool_rms = 0;                        ///< [-]
};

/// One fold of the cross-validation.
struct CrossValidationFold {
  double level = 0;                ///< held-out duty level [-1, 1]
  std::vector<std::string> files;  ///< held out
  ValveParameters params;          ///< fitted on the other levels
  double angle_rms = 0;            ///< prediction error on the held-out files [rad]
  double angle_range = 0;          ///< motion range of the held-out files [rad]
  double spool_rms = 0;            ///< [-]; 0 without spool feedback
};

struct ActuatorIdentification {
  std::string actuator;  ///< its name in the description
  int actuator_index = -1;
  ValveParameters nominal;           ///< the description's values
  ValveParameters params;            ///< identified
  ValveParameters std_dev;           ///< 1σ: the two below combined, √(σ_J² + σ_L²)
  ValveParameters std_dev_jacobian;  ///< σ_J, from JᵀJ at the optimum (noise)
  ValveParameters std_dev_levels;    ///< σ_L, jackknife over the duty levels (0 without)
  std::vector<bool> at_bound;  ///< per parameter: the optimum lies on a bound (σ meaningless)
  bool has_spool = false;
  /// τ_m: the joint's lag behind the spool (oil compressibility, inertia), a nuisance parameter
  /// fitted only with spool feedback, else 0 [s].
  double motion_lag = 0;
  std::size_t samples = 0;   ///< all samples
  std::size_t excluded = 0;  ///< left out of the angle term at end stops
  double angle_sigma = 0;    ///< residual RMS [rad]
  double spool_sigma = 0;    ///< [-]
  int iterations = 0;
  /// Shape of the fit's least-squares problem: its residual blocks (one per segment of the
  /// angle term, one per chunk of the spool term) and the most parameters any one block
  /// depends on (nonzeros per Jacobian row). Bounded per block whatever the number of
  /// segments, which keeps the fit's time and memory linear in the log length.
  std::size_t residual_blocks = 0;
  int largest_block_parameters = 0;
  double seconds = 0;  ///< wall time of the fit, cross-validation apart
  std::vector<FileFit> files;
  std::vector<CrossValidationFold> cross_validation;
};

/// Fits one actuator to its logs. Throws core::InputError naming the file and row when the
/// logs cannot identify it (no command beyond ±1 %, no motion of the joint at all).
ActuatorIdentification IdentifyActuator(const model::MachineDescription& machine,
                                        const generated::MachineFunctions& functions, int actuator,
                                        const std::vector<HydraulicLog>& logs,
                                        const HydraulicIdentificationOptions& options = {});

/// The actuator a name designates: its own name or the joint it drives; -1 if none.
int FindActuator(const model::MachineDescription& machine, const std::string& name);

}  // namespace autoshovel::identification
