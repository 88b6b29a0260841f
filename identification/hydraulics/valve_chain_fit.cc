#include "identification/hydraulics/valve_chain_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "identification/hydraulics/valve_chain_model.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kDeg = kPi / 180;
constexpr double kBar = 1e5;
constexpr double kOnsetWindow = 2.0;     // validation window after motion onset [s]
constexpr double kOppositeSettle = 1.0;  // left out after a step of the other direction [s]
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPilotBefore = 0.1;  // pilot window around a command change [s]

using Progress = std::function<void(const std::string&)>;
void Report(const Progress& progress, const std::string& line) {
  if (progress) progress(line);
}

double RoundLevel(double level) { return std::round(std::abs(level) * 100) / 100; }

// One log made ready for one direction's fit.
struct DirectionLog {
  const HydraulicLog* log = nullptr;
  LogEvents events;
  double level = 0;              ///< largest |u| of this direction's steps, to the percent
  std::vector<double> load;      ///< p_L − p̄_L [Pa] (empty: no pressure)
  std::vector<double> load_raw;  ///< p_L [Pa]
  std::vector<char> used;        ///< 1: in the angle term
  std::vector<char> pilot_used;  ///< 1: in the pilot term (around the command's changes)
  std::vector<std::pair<std::size_t, std::size_t>> segments;
  std::vector<std::size_t> onsets;  ///< motion onsets of this direction's steps
  std::size_t used_count = 0;
  double weight = 1;       ///< per residual
  double pilot_delay = 0;  ///< τ_p of stage 1 (0 without a pilot channel) [s]
  int joint_sense = 1;     ///< StepEventOptions::joint_sense
  ChainSamples samples() const {
    ChainSamples s;
    s.time = log->time;
    s.command = log->command;
    s.angle = log->joint_angle;
    s.load = load;
    s.segments = segments;
    s.pilot_delay = pilot_delay;
    s.joint_sense = joint_sense;
    return s;
  }
};

std::vector<std::pair<std::size_t, std::size_t>> Runs(const std::vector<char>& used,
                                                      std::size_t min_length) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  for (std::size_t i = 0; i < used.size();) {
    if (!used[i]) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < used.size() && used[j]) ++j;
    if (j - i >= min_length) runs.emplace_back(i, j);
    i = j;
  }
  return runs;
}

// Output error over a whole log lets a small error in the joint rate of a long, slow log
// grow into degrees, which the fit then spends every parameter on. The angle is therefore
// integrated in chunks, each from its measured start (a multiple-shooting prediction error
// whose horizon is the one the chain is judged on): a chunk starts at each step of this
// direction and at its motion onset + `kChunk`, then every `kChunk`.
constexpr double kChunk = 2.0;  // [s]

std::vector<std::pair<std::size_t, std::size_t>> Chunks(
    const std::vector<std::pair<std::size_t, std::size_t>>& runs, const HydraulicLog& log,
    const LogEvents& events, int sign, const ChainFitOptions& options) {
  std::vector<char> boundary(log.size(), 0);
  for (const CommandStep& step : events.steps) {
    if ((step.level > 0 ? 1 : -1) != sign) continue;
    boundary[step.on] = 1;
    const std::size_t from = step.onset != static_cast<std::size_t>(-1) ? step.onset : step.on;
    double next = log.time[from] + kChunk;
    for (std::size_t k = from; k < log.size(); ++k) {
      if (log.time[k] >= next) {
        boundary[k] = 1;
        next = log.time[k] + kChunk;
      }
    }
  }
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
  for (const auto& [b, e] : runs) {
    std::size_t start = b;
    double next = log.time[b] + kChunk;
    for (std::size_t k = b + 1; k < e; ++k) {
      const bool cut = boundary[k] || (log.time[k] >= next && !boundary[k]);
      if (!cut) continue;
      if (k - start >= options.events.min_segment) {
        chunks.emplace_back(start, k);
        start = k;
      }
      next = log.time[k] + kChunk;
    }
    if (e - start >= options.events.min_segment) chunks.emplace_back(start, e);
  }
  return chunks;
}

DirectionLog PrepareDirection(const HydraulicLog& log, const LogEvents& events, int sign,
                              const ChainFitOptions& options) {
  DirectionLog d;
  d.log = &log;
  d.joint_sense = options.events.joint_sense;
  d.events = events;
  const std::size_t n = log.size();
  d.used.assign(n, 0);
  // Left out: stalls and overrides, the other direction's steps and the settling after them.
  std::vector<char> other(n, 0);
  for (const CommandStep& step : events.steps) {
    if ((step.level > 0 ? 1 : -1) == sign) {
      d.level = std::max(d.level, RoundLevel(step.level));
      if (step.onset != static_cast<std::size_t>(-1)) d.onsets.push_back(step.onset);
      continue;
    }
    const double until = log.time[std::min(step.off, n - 1)] + kOppositeSettle;
    for (std::size_t k = step.on; k < n && log.time[k] <= until; ++k) other[k] = 1;
  }
  for (std::size_t k = 0; k < n; ++k) d.used[k] = !events.excluded[k] && !other[k];
  // The pilot term looks at the rise after each step: from 0.1 s before it to where the
  // pilot has crossed half the step's held value. The delay and the first, fast rise are
  // there; after it the real EPPR rises on slowly (at 100 %: 17 bar in 20 ms, then 0.3 s to
  // 34 bar), overshoots and settles over seconds, which a first-order lag fitted over the
  // whole step would trade for a shorter delay and a longer lag. The slow part reaches the
  // motion stage through its own lag. Rising edges only: the valve
  // vents in 20 ms where it fills in 60-100 ms, and the delay a controller leads by is the
  // filling one.
  d.pilot_used.assign(n, 0);
  if (!log.pilot_pressure.empty()) {
    for (const CommandStep& step : events.steps) {
      if ((step.level > 0 ? 1 : -1) != sign) continue;
      std::vector<double> held;
      double rest = log.pilot_pressure[step.on];
      for (std::size_t k = step.on; k < step.off; ++k) {
        if (log.time[k] >= log.time[step.on] + 1.0) held.push_back(log.pilot_pressure[k]);
      }
      if (held.empty()) {
        for (std::size_t k = step.on; k < step.off; ++k) held.push_back(log.pilot_pressure[k]);
      }
      std::nth_element(held.begin(), held.begin() + held.size() / 2, held.end());
      const double target = rest + 0.5 * (held[held.size() / 2] - rest);
      std::size_t end_k = step.on;
      while (end_k < step.off && log.pilot_pressure[end_k] < target) ++end_k;
      end_k = std::min(step.off, end_k + 2);  // the crossing sample and the one after it
      for (std::size_t k = 0; k < end_k; ++k) {
        if (log.time[k] >= log.time[step.on] - kPilotBefore) d.pilot_used[k] = 1;
      }
    }
  }
  d.segments = Chunks(Runs(d.used, options.events.min_segment), log, events, sign, options);
  std::fill(d.used.begin(), d.used.end(), 0);
  for (const auto& [b, e] : d.segments) {
    for (std::size_t k = b; k < e; ++k) d.used[k] = 1;
    d.used_count += e - b;
  }
  if (!log.pressure_a.empty() && !log.pressure_b.empty()) {
    d.load_raw.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      d.load_raw[k] = log.pressure_a[k] - options.area_ratio * log.pressure_b[k];
    }
  }
  return d;
}

// ---------------------------------------------------------------------------------------------
// Stage 1: command → pilot.

struct PilotCost {
  const DirectionLog* file;
  int sign;
  double weight;
  template <typename T>
  bool operator()(const T* params, T* residuals) const {
    const HydraulicLog& log = *file->log;
    SimulatePilot<T>(log.time, log.command, sign, params, [&](std::size_t k, const T& p) {
      residuals[k] = file->pilot_used[k] ? weight * (p - log.pilot_pressure[k] / kBar) : T(0.0);
    });
    return true;
  }
};

struct PilotProblem {
  std::array<double, kPilotCount> params{};
  double cost = 0;
  int iterations = 0;
};

// The pilot's static map p = p_0 + a·max(0, |u| − u_0) from the logs themselves: p_0 the
// median at rest, and a, u_0 a straight line through each held step's median pilot (from 1 s
// after the step on, the EPPR's overshoot settled). With one level, u_0 = 0.
void SteadyPilotMap(const std::vector<const DirectionLog*>& files, int sign, double command_on,
                    PilotProblem& state) {
  std::vector<double> rest, level, steady;
  for (const DirectionLog* f : files) {
    const HydraulicLog& log = *f->log;
    for (std::size_t k = 0; k < log.size(); ++k) {
      if (std::abs(log.command[k]) <= command_on) rest.push_back(log.pilot_pressure[k] / kBar);
    }
    for (const CommandStep& step : f->events.steps) {
      if ((step.level > 0 ? 1 : -1) != sign) continue;
      std::vector<double> held;
      for (std::size_t k = step.on; k < step.off; ++k) {
        if (log.time[k] >= log.time[step.on] + 1.0) held.push_back(log.pilot_pressure[k] / kBar);
      }
      if (held.size() < 10) continue;
      std::nth_element(held.begin(), held.begin() + held.size() / 2, held.end());
      level.push_back(std::abs(step.level));
      steady.push_back(held[held.size() / 2]);
    }
  }
  double offset = 0;
  if (!rest.empty()) {
    std::nth_element(rest.begin(), rest.begin() + rest.size() / 2, rest.end());
    offset = rest[rest.size() / 2];
  }
  state.params[kPilotOffset] = offset;
  if (level.empty()) return;
  const double n = static_cast<double>(level.size());
  const double mx = std::accumulate(level.begin(), level.end(), 0.0) / n;
  const double my = std::accumulate(steady.begin(), steady.end(), 0.0) / n - offset;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < level.size(); ++i) {
    sxx += (level[i] - mx) * (level[i] - mx);
    sxy += (level[i] - mx) * (steady[i] - offset - my);
  }
  if (sxx > 1e-6 && sxy > 0) {
    state.params[kPilotGain] = sxy / sxx;
    state.params[kPilotThreshold] = std::clamp(mx - my / state.params[kPilotGain], -0.5, 0.95);
  } else {
    state.params[kPilotGain] = std::max(my / std::max(mx, 1e-3), 0.0);
    state.params[kPilotThreshold] = 0.0;
  }
}

// Fits the pilot stage on `files`; `free_delay_only` holds everything but τ_p.
void FitPilot(const std::vector<const DirectionLog*>& files, int sign, PilotProblem& state,
              bool free_delay_only, int max_iterations, Eigen::MatrixXd* jtj = nullptr) {
  ceres::Problem problem;
  for (const DirectionLog* f : files) {
    auto* cost = new ceres::AutoDiffCostFunction<PilotCost, ceres::DYNAMIC, kPilotCount>(
        new PilotCost{f, sign, f->weight}, static_cast<int>(f->log->size()));
    problem.AddResidualBlock(cost, nullptr, state.params.data());
  }
  double* p = state.params.data();
  const double lower[kPilotCount] = {0.0, 0.002, 0.0, -0.5, -50.0};
  const double upper[kPilotCount] = {0.5, 0.5, 2000.0, 0.95, 50.0};
  for (int i = 0; i < kPilotCount; ++i) {
    problem.SetParameterLowerBound(p, i, lower[i]);
    problem.SetParameterUpperBound(p, i, upper[i]);
  }
  // The static map (gain, threshold, offset) comes from the held steps (SteadyPilotMap): the
  // windows around the steps see mostly the EPPR's overshoot, which would inflate the gain.
  problem.SetManifold(
      p, new ceres::SubsetManifold(kPilotCount, free_delay_only ? std::vector<int>{1, 2, 3, 4}
                                                                : std::vector<int>{2, 3, 4}));
  ceres::Solver::Options solver;
  solver.max_num_iterations = max_iterations;
  solver.linear_solver_type = ceres::DENSE_QR;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  state.cost = summary.final_cost;
  state.iterations = static_cast<int>(summary.iterations.size());
  if (jtj) {
    ceres::CRSMatrix crs;
    problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &crs);
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(crs.num_cols, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) {
        for (int j = crs.rows[r]; j < crs.rows[r + 1]; ++j) {
          a(crs.cols[i], crs.cols[j]) += crs.values[i] * crs.values[j];
        }
      }
    }
    *jtj = a;
  }
}

// ---------------------------------------------------------------------------------------------
// Stage 2: pilot → motion.

struct MotionCost {
  const DirectionLog* file;
  int sign;
  const std::vector<double>* knots;
  AngleScale scale;
  int parameter_count;
  const std::vector<double>* starts;  ///< measured angle at each chunk's start
  template <typename T>
  bool operator()(T const* const* blocks, T* residuals) const {
    const ChainSamples samples = file->samples();
    std::size_t r = 0;
    const double w = file->weight;
    std::vector<T> start(starts->begin(), starts->end());
    SimulateMotion<T>(
        samples, sign, blocks[0], *knots, scale, start.data(),
        [&](std::size_t k, const T& q, const T&) { residuals[r++] = w * (q - samples.angle[k]); });
    return true;
  }
};

struct MotionState {
  std::vector<double> params;               // kMotionFixed + knots
  std::vector<std::vector<double>> starts;  // per file, per chunk: the measured angle
  double cost = 0;
};

struct MotionSetup {
  int sign = 1;
  std::vector<double> knots;
  AngleScale scale;
  bool pilot_fixed = false;  // T_p from stage 1
  bool has_pressure = false;
};

enum class MotionFree { kAll, kDelayOnly };

void FitMotion(const std::vector<const DirectionLog*>& files, const std::vector<int>& file_index,
               const MotionSetup& setup, MotionState& state, MotionFree free, int max_iterations,
               std::vector<char> knot_has_data = {}, ceres::CRSMatrix* jacobian = nullptr,
               std::vector<double>* residuals = nullptr) {
  ceres::Problem problem;
  const int size = static_cast<int>(state.params.size());
  double* p = state.params.data();
  problem.AddParameterBlock(p, size);
  bool any = false;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const DirectionLog* f = files[i];
    auto& starts = state.starts[static_cast<std::size_t>(file_index[i])];
    if (f->used_count == 0 || starts.empty()) continue;
    auto* cost = new ceres::DynamicAutoDiffCostFunction<MotionCost, 8>(
        new MotionCost{f, setup.sign, &setup.knots, setup.scale, size, &starts});
    cost->AddParameterBlock(size);
    cost->SetNumResiduals(static_cast<int>(f->used_count));
    problem.AddResidualBlock(cost, nullptr, p);
    any = true;
  }
  if (!any) return;
  const int knots = size - kMotionFixed;
  std::vector<double> lower(size), upper(size);
  lower[kMotionDelay] = 0.0, upper[kMotionDelay] = 1.5;
  lower[kMotionLag] = 0.005, upper[kMotionLag] = 2.0;
  lower[kPilotLag] = 0.002, upper[kPilotLag] = 0.5;
  lower[kDeadBand] = 0.0, upper[kDeadBand] = std::max(0.0, setup.knots.front() - 0.005);
  lower[kLoadCoefficient] = -3.0, upper[kLoadCoefficient] = 3.0;
  lower[kSupplyCapacity] = 0.0, upper[kSupplyCapacity] = 2.0;
  lower[kSupplyDelay] = 0.0, upper[kSupplyDelay] = 6.0;
  lower[kSupplyLag] = 0.02, upper[kSupplyLag] = 5.0;
  lower[kMotionLagSlope] = 0.0, upper[kMotionLagSlope] = 2.0;
  lower[kGainLinear] = lower[kGainQuadratic] = -4.0;
  upper[kGainLinear] = upper[kGainQuadratic] = 4.0;
  for (int j = 0; j < knots; ++j) lower[kMotionFixed + j] = 0.0, upper[kMotionFixed + j] = 20.0;
  for (int i = 0; i < size; ++i) {
    state.params[i] = std::clamp(state.params[i], lower[i], upper[i]);
    problem.SetParameterLowerBound(p, i, lower[i]);
    problem.SetParameterUpperBound(p, i, upper[i]);
  }
  std::vector<int> constant;
  if (free == MotionFree::kDelayOnly) {
    // The delay, and the flow value of the level itself (when given as the one knot with data):
    // the level's own steady rate must not be taken from the curve through the others, or the
    // delay would absorb the curve's error at that level.
    int own_knot = -1;
    if (std::count(knot_has_data.begin(), knot_has_data.end(), 1) == 1) {
      own_knot = static_cast<int>(std::find(knot_has_data.begin(), knot_has_data.end(), 1) -
                                  knot_has_data.begin());
    }
    for (int i = 0; i < size; ++i) {
      const bool own = own_knot >= 0 && i == kMotionFixed + own_knot;
      if (i != kMotionDelay && !own) constant.push_back(i);
    }
  } else {
    if (setup.pilot_fixed) constant.push_back(kPilotLag);
    if (!setup.has_pressure) constant.push_back(kLoadCoefficient);
    for (int j = 0; j < knots && j < static_cast<int>(knot_has_data.size()); ++j) {
      if (!knot_has_data[j]) constant.push_back(kMotionFixed + j);
    }
  }
  if (!constant.empty()) problem.SetManifold(p, new ceres::SubsetManifold(size, constant));
  ceres::Solver::Options solver;
  solver.max_num_iterations = max_iterations;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.num_threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  state.cost = summary.final_cost;
  if (jacobian) {
    double cost = 0;
    problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, residuals, nullptr, jacobian);
  }
}

// The angle term's cost for the current state, without solving.
double MotionCostOf(const std::vector<const DirectionLog*>& files, const MotionSetup& setup,
                    const MotionState& state) {
  double cost = 0;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const ChainSamples samples = files[i]->samples();
    const double w = files[i]->weight;
    SimulateMotion<double>(samples, setup.sign, state.params.data(), setup.knots, setup.scale,
                           state.starts[i].data(), [&](std::size_t k, double q, double) {
                             const double r = w * (q - samples.angle[k]);
                             cost += 0.5 * r * r;
                           });
  }
  return cost;
}

// Simulated angle and rate of one file (starts given).
void SimulateFile(const DirectionLog& file, const MotionSetup& setup,
                  const std::vector<double>& params, const std::vector<double>& starts,
                  std::vector<double>& angle, std::vector<double>& rate) {
  const std::size_t n = file.log->size();
  angle.assign(n, kNaN);
  rate.assign(n, kNaN);
  SimulateMotion<double>(file.samples(), setup.sign, params.data(), setup.knots, setup.scale,
                         starts.data(), [&](std::size_t k, double q, double v) {
                           angle[k] = q;
                           rate[k] = v;
                         });
}

std::vector<double> MeasuredStarts(const DirectionLog& file) {
  std::vector<double> starts;
  for (const auto& [b, e] : file.segments) starts.push_back(file.log->joint_angle[b]);
  return starts;
}

// RMS over the used samples and over 2 s after each motion onset.
std::pair<double, double> AngleErrors(const DirectionLog& file, const std::vector<double>& fit) {
  double all = 0, onset = 0;
  std::size_t n_all = 0, n_onset = 0;
  const auto& t = file.log->time;
  for (std::size_t k = 0; k < fit.size(); ++k) {
    if (!file.used[k] || std::isnan(fit[k])) continue;
    const double e = fit[k] - file.log->joint_angle[k];
    all += e * e, ++n_all;
    for (std::size_t o : file.onsets) {
      if (k >= o && t[k] - t[o] <= kOnsetWindow) {
        onset += e * e, ++n_onset;
        break;
      }
    }
  }
  return {n_all ? std::sqrt(all / n_all) : 0.0, n_onset ? std::sqrt(onset / n_onset) : 0.0};
}

// R² of the joint rate: the measured and the fitted angle differentiated alike (central
// differences over ±0.1 s within the used runs), so that the comparison is of the motion and
// not of the differentiator's noise.
double RateR2(const DirectionLog& file, const std::vector<double>& angle_fit) {
  const auto& t = file.log->time;
  const auto& q = file.log->joint_angle;
  std::vector<double> measured, fitted;
  for (const auto& [b, e] : file.segments) {
    std::size_t lo = b, hi = b;
    for (std::size_t k = b; k < e; ++k) {
      while (t[k] - t[lo] > 0.1) ++lo;
      while (hi + 1 < e && t[hi + 1] - t[k] <= 0.1) ++hi;
      if (hi == lo || std::isnan(angle_fit[hi]) || std::isnan(angle_fit[lo])) continue;
      const double dt = t[hi] - t[lo];
      measured.push_back((q[hi] - q[lo]) / dt);
      fitted.push_back((angle_fit[hi] - angle_fit[lo]) / dt);
    }
  }
  if (measured.size() < 3) return 0;
  const double mean = std::accumulate(measured.begin(), measured.end(), 0.0) / measured.size();
  double ss_res = 0, ss_tot = 0;
  for (std::size_t i = 0; i < measured.size(); ++i) {
    ss_res += (fitted[i] - measured[i]) * (fitted[i] - measured[i]);
    ss_tot += (measured[i] - mean) * (measured[i] - mean);
  }
  return ss_tot > 0 ? 1 - ss_res / ss_tot : 0.0;
}

// Knots: the duty levels of the given files; O's starting values from the measured rates.
struct Knots {
  std::vector<double> levels;
  std::vector<double> rates;  // median |q̇| with the command on, after the first second
};

Knots KnotsOf(const std::vector<const DirectionLog*>& files, const MotionSetup& setup) {
  std::map<double, std::vector<double>> by_level;
  for (const DirectionLog* f : files) {
    if (f->used_count == 0 || f->level <= 0) continue;
    auto& rates = by_level[f->level];
    for (const CommandStep& step : f->events.steps) {
      if ((step.level > 0 ? 1 : -1) != setup.sign) continue;
      const double settle = f->log->time[step.on] + 1.0;
      for (std::size_t k = step.on; k < step.off; ++k) {
        if (f->used[k] && f->log->time[k] >= settle) rates.push_back(std::abs(f->events.rate[k]));
      }
    }
  }
  Knots knots;
  for (auto& [level, rates] : by_level) {
    knots.levels.push_back(level);
    if (rates.empty()) {
      knots.rates.push_back(0);
      continue;
    }
    std::nth_element(rates.begin(), rates.begin() + rates.size() / 2, rates.end());
    knots.rates.push_back(rates[rates.size() / 2]);
  }
  return knots;
}

MotionState InitialMotion(const std::vector<const DirectionLog*>& files, const Knots& knots,
                          double pilot_lag) {
  MotionState state;
  state.params.assign(kMotionFixed + knots.levels.size(), 0.0);
  state.params[kMotionDelay] = 0.15;
  state.params[kMotionLag] = 0.15;
  state.params[kPilotLag] = pilot_lag;
  state.params[kDeadBand] = std::max(0.0, knots.levels.front() - 0.15);
  double previous = 0;
  for (std::size_t j = 0; j < knots.levels.size(); ++j) {
    const double rate = std::max(knots.rates[j], previous + 1e-4);
    state.params[kMotionFixed + j] = rate - previous;
    previous = rate;
  }
  // Below the fastest level's rate: at or above it the late stage has no gradient.
  state.params[kSupplyCapacity] = 0.6 * previous;
  state.params[kSupplyDelay] = 1.5;
  state.params[kSupplyLag] = 0.3;
  for (const DirectionLog* f : files) state.starts.push_back(MeasuredStarts(*f));
  return state;
}

// Scans τ_m with everything else at its start, then fits: output-error costs have local
// minima in the delay.
void ScanAndFit(const std::vector<const DirectionLog*>& files, const MotionSetup& setup,
                MotionState& state, int max_iterations) {
  double best = std::numeric_limits<double>::infinity(), best_delay = 0;
  // Off the sample grid: at a delay of a whole number of sample intervals the held mean's
  // derivative in τ vanishes from one side, and the solver would not move from there.
  for (double delay = 0.37 * 0.025; delay <= 0.6; delay += 0.025) {
    state.params[kMotionDelay] = delay;
    const double cost = MotionCostOf(files, setup, state);
    if (cost < best) best = cost, best_delay = delay;
  }
  state.params[kMotionDelay] = best_delay;
  std::vector<int> index(files.size());
  std::iota(index.begin(), index.end(), 0);
  FitMotion(files, index, setup, state, MotionFree::kAll, max_iterations);
}

Estimate MakeEstimate(double value, double lower, double upper, bool fixed) {
  Estimate e;
  e.value = value;
  e.low = e.high = value;
  e.fixed = fixed;
  const double span = upper - lower;
  e.at_bound = !fixed && (value <= lower + 1e-6 * span || value >= upper - 1e-6 * span);
  return e;
}

void SetInterval(Estimate& e, std::vector<double> samples) {
  if (samples.size() < 3) return;
  std::sort(samples.begin(), samples.end());
  auto at = [&](double q) {
    const double x = q * (samples.size() - 1);
    const std::size_t i = static_cast<std::size_t>(x);
    const double f = x - i;
    return i + 1 < samples.size() ? samples[i] * (1 - f) + samples[i + 1] * f : samples[i];
  };
  e.low = std::min(e.value, at(0.05));
  e.high = std::max(e.value, at(0.95));
}

std::string Percent(double level) {
  std::ostringstream s;
  s << std::lround(level * 100) << " %";
  return s.str();
}

// σ of each free parameter of the motion block from the Jacobian (marginal over the start
// angles) and the pairs whose correlation exceeds 0.95.
void JacobianSigmas(const ceres::CRSMatrix& crs, const std::vector<double>& residuals,
                    const std::vector<int>& free_index, std::vector<double>& sigma,
                    Eigen::MatrixXd& correlation) {
  const int cols = crs.num_cols;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(cols, cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) {
      for (int j = crs.rows[r]; j < crs.rows[r + 1]; ++j) {
        a(crs.cols[i], crs.cols[j]) += crs.values[i] * crs.values[j];
      }
    }
  }
  double s2 = 0;
  for (double r : residuals) s2 += r * r;
  s2 /= std::max<double>(1.0, static_cast<double>(residuals.size()) - cols);
  const Eigen::MatrixXd cov = a.completeOrthogonalDecomposition().pseudoInverse() * s2;
  const int k = static_cast<int>(free_index.size());
  sigma.assign(k, 0.0);
  correlation = Eigen::MatrixXd::Identity(k, k);
  for (int i = 0; i < k; ++i) sigma[i] = std::sqrt(std::max(0.0, cov(i, i)));
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      const double d = std::sqrt(cov(i, i) * cov(j, j));
      correlation(i, j) = d > 0 ? cov(i, j) / d : 0.0;
    }
  }
}

double HighestRate(const MotionState& state) {
  double sum = 0;
  for (std::size_t j = kMotionFixed; j < state.params.size(); ++j) sum += state.params[j];
  return sum;
}

const char* MotionName(int i) {
  switch (i) {
    case kMotionDelay:
      return "motion delay";
    case kMotionLag:
      return "motion lag";
    case kPilotLag:
      return "pilot lag";
    case kDeadBand:
      return "dead band";
    case kLoadCoefficient:
      return "load coefficient";
    case kGainLinear:
      return "angle gain c1";
    case kGainQuadratic:
      return "angle gain c2";
    case kSupplyCapacity:
      return "first supply capacity";
    case kMotionLagSlope:
      return "motion lag growth";
    case kSupplyDelay:
      return "late supply delay";
    case kSupplyLag:
      return "late supply lag";
    default:
      return "flow value";
  }
}

// ---------------------------------------------------------------------------------------------

DirectionFit FitDirection(const std::vector<DirectionLog>& all, int sign,
                          const ChainFitOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  DirectionFit fit;
  fit.sign = sign;
  std::vector<const DirectionLog*> files;
  for (const DirectionLog& d : all) {
    if (d.level > 0 && d.used_count > 0) files.push_back(&d);
  }
  const std::string direction = sign > 0 ? "positive" : "negative";
  fit.has_pilot = std::all_of(files.begin(), files.end(), [](const DirectionLog* f) {
    return !f->log->pilot_pressure.empty();
  });
  fit.has_pressure = std::all_of(files.begin(), files.end(),
                                 [](const DirectionLog* f) { return !f->load_raw.empty(); });

  // Stage 1.
  PilotProblem pilot;
  if (fit.has_pilot) {
    Report(options.progress, "valve chain (" + direction + "): command -> pilot");
    pilot.params = {0.07, 0.03, 35.0, 0.05, 0.0};
    SteadyPilotMap(files, sign, options.events.command_on, pilot);
    double best = std::numeric_limits<double>::infinity(), best_delay = 0.07;
    for (double delay = 0.0037; delay <= 0.3; delay += 0.01) {  // off the grid: ScanAndFit
      PilotProblem trial = pilot;
      trial.params[kPilotDelay] = delay;
      double cost = 0;
      for (const DirectionLog* f : files) {
        SimulatePilot<double>(f->log->time, f->log->command, sign, trial.params.data(),
                              [&](std::size_t k, double p) {
                                if (!f->pilot_used[k]) return;
                                const double r = f->weight * (p - f->log->pilot_pressure[k] / kBar);
                                cost += r * r;
                              });
      }
      if (cost < best) best = cost, best_delay = delay;
    }
    pilot.params[kPilotDelay] = best_delay;
    Eigen::MatrixXd jtj;
    FitPilot(files, sign, pilot, false, options.max_iterations, &jtj);
    std::size_t rows = 0;
    for (const DirectionLog* f : files) rows += f->log->size();
    const double s2 = 2 * pilot.cost / std::max<double>(1.0, double(rows) - double(kPilotCount));
    const Eigen::MatrixXd cov = jtj.completeOrthogonalDecomposition().pseudoInverse() * s2;
    const double lower[kPilotCount] = {0.0, 0.002, 0.0, -0.5, -50.0};
    const double upper[kPilotCount] = {0.5, 0.5, 2000.0, 0.95, 50.0};
    Estimate* out[kPilotCount] = {&fit.pilot_delay, &fit.pilot_time_constant, &fit.pilot_gain,
                                  &fit.pilot_threshold, &fit.pilot_offset};
    for (int i = 0; i < kPilotCount; ++i) {
      // The map (i ≥ 2) is read from the held steps, not fitted: shown as held.
      *out[i] = MakeEstimate(pilot.params[i], lower[i], upper[i], i >= 2);
      if (i < 2 && !out[i]->at_bound && cov.rows() == 2) out[i]->sigma = std::sqrt(cov(i, i));
    }
  } else {
    fit.pilot_delay.fixed = true;
    fit.pilot_delay.value = 0;
    fit.notes.push_back(
        "no pilot channel: the command -> pilot stage is not separated; its lag "
        "is fitted with the motion (pilot delay 0)");
  }

  // Stage 2.
  Report(options.progress, "valve chain (" + direction + "): pilot -> motion");
  MotionSetup setup;
  setup.sign = sign;
  setup.pilot_fixed = fit.has_pilot;
  setup.has_pressure = fit.has_pressure;
  double qmin = std::numeric_limits<double>::infinity(), qmax = -qmin;
  for (const DirectionLog* f : files) {
    for (std::size_t k = 0; k < f->log->size(); ++k) {
      if (!f->used[k]) continue;
      qmin = std::min(qmin, f->log->joint_angle[k]);
      qmax = std::max(qmax, f->log->joint_angle[k]);
    }
  }
  setup.scale.center = 0.5 * (qmin + qmax);
  setup.scale.half_range = std::max(0.5 * (qmax - qmin), 1 * kDeg);
  fit.angle_center = setup.scale.center;
  fit.angle_half_range = setup.scale.half_range;
  if (fit.has_pressure) {
    double sum = 0;
    std::size_t n = 0;
    for (const DirectionLog* f : files) {
      for (std::size_t k = 0; k < f->log->size(); ++k) {
        if (f->used[k] && sign * f->log->command[k] > options.events.command_on) {
          sum += f->load_raw[k], ++n;
        }
      }
    }
    fit.load_reference = n ? sum / n : 0.0;
  }
  // The load offsets are stored in the (const) logs' copies: recomputed here per direction.
  std::vector<DirectionLog> local;
  local.reserve(files.size());
  for (const DirectionLog* f : files) {
    local.push_back(*f);
    DirectionLog& d = local.back();
    d.pilot_delay = fit.has_pilot ? pilot.params[kPilotDelay] : 0.0;
    if (fit.has_pressure) {
      d.load.resize(d.load_raw.size());
      for (std::size_t k = 0; k < d.load_raw.size(); ++k) {
        d.load[k] = d.load_raw[k] - fit.load_reference;
      }
    } else {
      d.load.clear();
    }
  }
  files.clear();
  for (const DirectionLog& d : local) files.push_back(&d);
  const Knots knots = KnotsOf(files, setup);
  if (knots.levels.empty()) {
    FailAtSample(*all.front().log, 0,
                 "no " + direction + " command step moves the joint: nothing to identify");
  }
  setup.knots = knots.levels;
  fit.levels = knots.levels;
  const double pilot_lag = fit.has_pilot ? pilot.params[kPilotTimeConstant] : 0.05;
  MotionState state = InitialMotion(files, knots, pilot_lag);
  ScanAndFit(files, setup, state, options.max_iterations);

  // Jacobian σ and inseparable pairs.
  {
    ceres::CRSMatrix crs;
    std::vector<double> residuals;
    MotionState copy = state;
    std::vector<int> index(files.size());
    std::iota(index.begin(), index.end(), 0);
    FitMotion(files, index, setup, copy, MotionFree::kAll, 0, {}, &crs, &residuals);
    std::vector<int> free_index;
    for (int i = 0; i < static_cast<int>(state.params.size()); ++i) {
      if ((i == kPilotLag && setup.pilot_fixed) || (i == kLoadCoefficient && !setup.has_pressure)) {
        continue;
      }
      free_index.push_back(i);
    }
    std::vector<double> sigma;
    Eigen::MatrixXd correlation;
    if (crs.num_cols > 0) JacobianSigmas(crs, residuals, free_index, sigma, correlation);
    auto estimate = [&](int i, double lower, double upper) {
      const bool fixed = std::find(free_index.begin(), free_index.end(), i) == free_index.end();
      Estimate e = MakeEstimate(state.params[i], lower, upper, fixed);
      const auto at = std::find(free_index.begin(), free_index.end(), i) - free_index.begin();
      if (!fixed && !e.at_bound && at < static_cast<long>(sigma.size())) e.sigma = sigma[at];
      return e;
    };
    fit.motion_delay = estimate(kMotionDelay, 0.0, 1.5);
    fit.motion_lag = estimate(kMotionLag, 0.005, 2.0);
    if (!fit.has_pilot) fit.pilot_time_constant = estimate(kPilotLag, 0.002, 0.5);
    fit.dead_band = estimate(kDeadBand, 0.0, std::max(0.0, setup.knots.front() - 0.005));
    fit.load_coefficient = estimate(kLoadCoefficient, -3.0, 3.0);
    fit.gain_linear = estimate(kGainLinear, -4.0, 4.0);
    fit.gain_quadratic = estimate(kGainQuadratic, -4.0, 4.0);
    fit.supply_capacity = estimate(kSupplyCapacity, 0.0, 2.0);
    fit.motion_lag_slope = estimate(kMotionLagSlope, 0.0, 2.0);
    fit.supply_delay = estimate(kSupplyDelay, 0.0, 6.0);
    fit.supply_lag = estimate(kSupplyLag, 0.02, 5.0);
    if (fit.supply_capacity.value >= 0.99 * HighestRate(state)) {
      fit.notes.push_back(
          "no late supply seen (the first supply covers every level): its delay "
          "and lag say nothing");
    }
    double sum = 0;
    for (std::size_t j = 0; j < setup.knots.size(); ++j) {
      sum += state.params[kMotionFixed + j];
      Estimate e;
      e.value = e.low = e.high = sum;
      fit.rates.push_back(e);
    }
    for (int i = 0; i < static_cast<int>(free_index.size()); ++i) {
      for (int j = i + 1; j < static_cast<int>(free_index.size()); ++j) {
        if (correlation.rows() > j && std::abs(correlation(i, j)) > 0.95) {
          std::ostringstream s;
          s << MotionName(free_index[i]) << " and " << MotionName(free_index[j])
            << " cannot be separated by these logs (correlation " << correlation(i, j) << ")";
          fit.notes.push_back(s.str());
        }
      }
    }
    if (setup.knots.size() == 1) {
      fit.notes.push_back(
          "one duty level: the dead band and the flow value are not separated "
          "(log two or more levels)");
    }
    if (!fit.has_pressure) {
      fit.notes.push_back("no pressure channels: load dependence not identified (kappa held 0)");
    }
  }

  // Residuals per file.
  double ss = 0;
  std::size_t count = 0;
  double pilot_ss = 0;
  std::size_t pilot_count = 0;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const DirectionLog& f = *files[i];
    FileReport report;
    report.file = f.log->file;
    report.level = f.level;
    report.samples = f.log->size();
    report.used = f.used_count;
    report.stalled = f.events.stalled_samples;
    report.relief_seen = f.events.relief_seen;
    std::vector<double> angle, rate;
    SimulateFile(f, setup, state.params, state.starts[i], angle, rate);
    std::tie(report.angle_rms, report.angle_rms_onset) = AngleErrors(f, angle);
    report.rate_r2 = RateR2(f, angle);
    for (std::size_t k = 0; k < angle.size(); ++k) {
      if (f.used[k] && !std::isnan(angle[k])) {
        ss += (angle[k] - f.log->joint_angle[k]) * (angle[k] - f.log->joint_angle[k]);
        ++count;
      }
    }
    if (fit.has_pressure) {
      double sum = 0;
      std::size_t n = 0;
      for (std::size_t k = 0; k < f.log->size(); ++k) {
        if (f.used[k] && sign * f.log->command[k] > options.events.command_on) {
          sum += f.load_raw[k], ++n;
        }
      }
      report.mean_load = n ? sum / n : 0.0;
    }
    report.time = f.log->time;
    report.angle = f.log->joint_angle;
    report.angle_fit = angle;
    report.excluded.assign(f.log->size(), 0);
    for (std::size_t k = 0; k < f.log->size(); ++k) report.excluded[k] = !f.used[k];
    if (fit.has_pilot) {
      report.pilot.resize(f.log->size());
      report.pilot_fit.resize(f.log->size());
      double pss = 0;
      SimulatePilot<double>(f.log->time, f.log->command, sign, pilot.params.data(),
                            [&](std::size_t k, double p) {
                              report.pilot[k] = f.log->pilot_pressure[k] / kBar;
                              report.pilot_fit[k] = p;
                              pss += (p - report.pilot[k]) * (p - report.pilot[k]);
                            });
      report.pilot_rms = std::sqrt(pss / std::max<std::size_t>(1, f.log->size()));
      pilot_ss += pss, pilot_count += f.log->size();
    }
    fit.files.push_back(std::move(report));
  }
  fit.angle_sigma = count ? std::sqrt(ss / count) : 0.0;
  fit.pilot_sigma = pilot_count ? std::sqrt(pilot_ss / pilot_count) : 0.0;

  // Delay per duty level and per stage.
  std::map<double, std::vector<std::size_t>> by_level;
  for (std::size_t i = 0; i < files.size(); ++i) by_level[files[i]->level].push_back(i);
  for (const auto& [level, members] : by_level) {
    LevelDelay row;
    row.level = level;
    row.files = members.size();
    std::vector<const DirectionLog*> subset;
    std::vector<int> index;
    for (std::size_t i : members) subset.push_back(files[i]), index.push_back(static_cast<int>(i));
    double pilot_delay = 0;
    if (fit.has_pilot) {
      PilotProblem level_pilot = pilot;
      FitPilot(subset, sign, level_pilot, true, options.max_iterations);
      pilot_delay = level_pilot.params[kPilotDelay];
      row.pilot_delay = pilot_delay;
    } else {
      row.pilot_delay = kNaN;
    }
    MotionState level_state = state;
    std::vector<char> own(setup.knots.size(), 0);
    for (std::size_t j = 0; j < setup.knots.size(); ++j) own[j] = setup.knots[j] == level;
    FitMotion(subset, index, setup, level_state, MotionFree::kDelayOnly, options.max_iterations,
              own);
    row.motion_delay =
        (fit.has_pilot ? pilot.params[kPilotDelay] : 0.0) + level_state.params[kMotionDelay];
    std::vector<double> thresholds;
    for (const DirectionLog* f : subset) {
      for (const CommandStep& step : f->events.steps) {
        if ((step.level > 0 ? 1 : -1) == sign && step.onset != static_cast<std::size_t>(-1)) {
          thresholds.push_back(f->log->time[step.onset] - f->log->time[step.on]);
        }
      }
    }
    if (!thresholds.empty()) {
      std::nth_element(thresholds.begin(), thresholds.begin() + thresholds.size() / 2,
                       thresholds.end());
      row.threshold_motion = thresholds[thresholds.size() / 2];
    }
    fit.level_delays.push_back(row);
  }

  // Bootstrap over the logs.
  if (options.bootstrap > 0 && files.size() >= 2) {
    Report(options.progress, "valve chain (" + direction + "): bootstrap over " +
                                 std::to_string(options.bootstrap) + " resamples of the logs");
    std::mt19937_64 rng(options.seed + (sign > 0 ? 0 : 7919));
    std::uniform_int_distribution<std::size_t> pick(0, files.size() - 1);
    std::vector<std::vector<double>> motion_samples(state.params.size() + 1);
    std::vector<std::vector<double>> pilot_samples(kPilotCount);
    std::vector<std::vector<double>> rate_samples(setup.knots.size());
    for (int b = 0; b < options.bootstrap; ++b) {
      std::vector<const DirectionLog*> subset;
      std::vector<int> index;
      std::vector<char> has(setup.knots.size(), 0);
      for (std::size_t i = 0; i < files.size(); ++i) {
        const std::size_t j = pick(rng);
        subset.push_back(files[j]);
        index.push_back(static_cast<int>(subset.size() - 1));
        for (std::size_t kk = 0; kk < setup.knots.size(); ++kk) {
          if (std::abs(setup.knots[kk] - files[j]->level) < 1e-9) has[kk] = 1;
        }
      }
      if (fit.has_pilot) {
        PilotProblem resampled = pilot;
        FitPilot(subset, sign, resampled, false, options.max_iterations);
        for (int i = 0; i < kPilotCount; ++i) pilot_samples[i].push_back(resampled.params[i]);
      }
      MotionState resampled = state;
      resampled.starts.clear();
      for (const DirectionLog* f : subset) {
        const auto it = std::find(files.begin(), files.end(), f) - files.begin();
        resampled.starts.push_back(state.starts[static_cast<std::size_t>(it)]);
      }
      FitMotion(subset, index, setup, resampled, MotionFree::kAll, options.max_iterations, has);
      for (std::size_t i = 0; i < state.params.size(); ++i) {
        motion_samples[i].push_back(resampled.params[i]);
      }
      double sum = 0;
      for (std::size_t j = 0; j < setup.knots.size(); ++j) {
        sum += resampled.params[kMotionFixed + j];
        if (has[j]) rate_samples[j].push_back(sum);
      }
    }
    if (fit.has_pilot) {
      Estimate* out[kPilotCount] = {&fit.pilot_delay, &fit.pilot_time_constant, &fit.pilot_gain,
                                    &fit.pilot_threshold, &fit.pilot_offset};
      for (int i = 0; i < kPilotCount; ++i) SetInterval(*out[i], pilot_samples[i]);
    } else {
      SetInterval(fit.pilot_time_constant, motion_samples[kPilotLag]);
    }
    SetInterval(fit.motion_delay, motion_samples[kMotionDelay]);
    SetInterval(fit.motion_lag, motion_samples[kMotionLag]);
    SetInterval(fit.dead_band, motion_samples[kDeadBand]);
    if (fit.has_pressure) SetInterval(fit.load_coefficient, motion_samples[kLoadCoefficient]);
    SetInterval(fit.gain_linear, motion_samples[kGainLinear]);
    SetInterval(fit.gain_quadratic, motion_samples[kGainQuadratic]);
    SetInterval(fit.supply_capacity, motion_samples[kSupplyCapacity]);
    SetInterval(fit.motion_lag_slope, motion_samples[kMotionLagSlope]);
    SetInterval(fit.supply_delay, motion_samples[kSupplyDelay]);
    SetInterval(fit.supply_lag, motion_samples[kSupplyLag]);
    for (std::size_t j = 0; j < setup.knots.size(); ++j) SetInterval(fit.rates[j], rate_samples[j]);
  }

  // Validation.
  if (options.validate) {
    auto predict = [&](const std::vector<std::size_t>& train, const std::vector<std::size_t>& test,
                       const std::string& label) {
      std::vector<const DirectionLog*> subset;
      for (std::size_t i : train) subset.push_back(files[i]);
      MotionSetup sub = setup;
      const Knots sub_knots = KnotsOf(subset, setup);
      Prediction prediction;
      prediction.label = label;
      if (sub_knots.levels.empty()) return prediction;
      sub.knots = sub_knots.levels;
      MotionState sub_state = InitialMotion(subset, sub_knots, pilot_lag);
      for (int i = 0; i < kMotionFixed; ++i) sub_state.params[i] = state.params[i];
      sub_state.params[kDeadBand] =
          std::min(sub_state.params[kDeadBand], sub.knots.front() - 0.005);
      ScanAndFit(subset, sub, sub_state, options.max_iterations);
      for (std::size_t i : test) {
        const DirectionLog& f = *files[i];
        prediction.files.push_back(f.log->file);
        std::vector<double> angle, rate;
        SimulateFile(f, sub, sub_state.params, MeasuredStarts(f), angle, rate);
        const auto [all_rms, onset_rms] = AngleErrors(f, angle);
        prediction.angle_rms = std::max(prediction.angle_rms, all_rms);
        prediction.angle_rms_onset = std::max(prediction.angle_rms_onset, onset_rms);
      }
      return prediction;
    };
    if (by_level.size() >= 3) {
      Report(options.progress, "valve chain (" + direction + "): leave one duty level out");
      for (const auto& [level, members] : by_level) {
        std::vector<std::size_t> train;
        for (std::size_t i = 0; i < files.size(); ++i) {
          if (files[i]->level != level) train.push_back(i);
        }
        fit.leave_one_level_out.push_back(predict(train, members, Percent(level)));
      }
    }
    if (fit.has_pressure && files.size() >= 4) {
      Report(options.progress, "valve chain (" + direction + "): high load -> low load");
      // Split each level's logs at their median load; levels with one log go to training.
      std::vector<std::size_t> high, low;
      for (const auto& [level, members] : by_level) {
        std::vector<std::size_t> sorted = members;
        std::sort(sorted.begin(), sorted.end(), [&](std::size_t a, std::size_t b) {
          return fit.files[a].mean_load > fit.files[b].mean_load;
        });
        for (std::size_t r = 0; r < sorted.size(); ++r) {
          (r < (sorted.size() + 1) / 2 ? high : low).push_back(sorted[r]);
        }
      }
      if (!low.empty()) fit.load_transfer.push_back(predict(high, low, "high -> low load"));
    }
  }
  fit.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return fit;
}

}  // namespace

ChainIdentification IdentifyValveChain(const std::vector<HydraulicLog>& logs,
                                       const ChainFitOptions& options) {
  ChainIdentification result;
  std::vector<LogEvents> events;
  for (const HydraulicLog& log : logs) RequireExcitation(log);
  for (const HydraulicLog& log : logs) {
    events.push_back(DetectStepEvents(log, options.events));
    const auto mismatches = FindSignMismatches(log, events.back(), options.events);
    if (!mismatches.empty()) {
      const SignMismatch& m = mismatches.front();
      const CommandStep& step = events.back().steps[m.step];
      std::ostringstream s;
      s << "the joint moves against the command: a " << (m.level > 0 ? "+" : "")
        << std::lround(m.level * 100) << " % step " << (m.angle_change > 0 ? "raises" : "lowers")
        << " the angle by " << std::fixed << std::setprecision(1) << std::abs(m.angle_change) / kDeg
        << " deg, where the description's joint "
        << (options.events.joint_sense > 0 ? "rises" : "falls")
        << " for a positive command (one that extends the cylinder). Each direction must move "
           "the joint the description's way: negate the command column (e.g. command=-NAME, or "
           "command=UP - DOWN from the two direction channels) or the angle (joint_angle=-NAME)";
      FailAtSample(log, step.on, s.str());
    }
  }
  for (int sign : {1, -1}) {
    std::vector<DirectionLog> prepared;
    double total = 0;
    for (std::size_t i = 0; i < logs.size(); ++i) {
      DirectionLog d = PrepareDirection(logs[i], events[i], sign, options);
      if (d.level > 0 && d.used_count > 0) {
        total += static_cast<double>(d.used_count);
        prepared.push_back(std::move(d));
      }
    }
    if (prepared.empty()) continue;
    // Each log weighs the same whatever its length.
    const double mean = total / static_cast<double>(prepared.size());
    for (DirectionLog& d : prepared) {
      d.weight = std::sqrt(mean / static_cast<double>(std::max<std::size_t>(1, d.used_count)));
    }
    result.directions.push_back(FitDirection(prepared, sign, options));
  }
  if (result.directions.empty() && !logs.empty()) {
    FailAtSample(logs.front(), 0,
                 "no command step in these logs moves the joint: nothing to identify");
  }
  return result;
}

}  // namespace autoshovel::identification
