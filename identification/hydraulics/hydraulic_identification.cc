#include "identification/hydraulics/hydraulic_identification.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "runtime/core/diagnostics.h"
#include "runtime/core/strings.h"

namespace autoshovel::identification {

namespace {

constexpr int kNumParams = 4;           // d, τ_d, τ_s, Q_rated
constexpr std::size_t kMinSegment = 5;  // shorter runs between end stops are left out
constexpr double kMaxMotionLag = 0.1;   // τ_m bound [s]

using Progress = std::function<void(const std::string&)>;

void Report(const Progress& progress, const std::string& line) {
  if (progress) progress(line);
}

double Value(double x) { return x; }
template <int N>
double Value(const ceres::Jet<double, N>& x) {
  return x.a;
}

std::array<double, kNumParams> ToArray(const ValveParameters& p) {
  return {p.dead_zone, p.transport_delay, p.spool_time_constant, p.rated_flow};
}

ValveParameters FromArray(const double* a) { return {a[0], a[1], a[2], a[3]}; }

// One log made ready for the fit.
struct PreparedFile {
  const HydraulicLog* log = nullptr;
  double level = 0;
  std::vector<double> length;  ///< cylinder length from the measured angle [m]
  std::vector<double> lever;   ///< dL/dq at the measured angle [m/rad]
  std::vector<char> excluded;  ///< out of the angle term
  std::vector<std::pair<std::size_t, std::size_t>> segments;  ///< [begin, end) of used samples
  std::size_t angle_rows() const {
    std::size_t n = 0;
    for (const auto& [b, e] : segments) n += e - b;
    return n;
  }
  std::size_t rows() const { return angle_rows() + (log->has_spool() ? log->size() : 0); }
};

PreparedFile Prepare(const HydraulicLog& log, const ActuatorKinematics& kinematics,
                     const model::Actuator& actuator,
                     const HydraulicIdentificationOptions& options) {
  PreparedFile file;
  file.log = &log;
  const std::size_t n = log.size();
  file.length.resize(n);
  file.lever.resize(n);
  file.excluded.assign(n, 0);
  for (std::size_t j = 0; j < n; ++j) {
    file.level = std::max(file.level, std::abs(log.command[j]));
    file.length[j] = kinematics.Length(log.joint_angle[j]);
    file.lever[j] = kinematics.Lever(log.joint_angle[j]);
    if (!options.exclude_end_stops) continue;
    bool stop = file.length[j] - kinematics.length_min() < options.end_stop_margin ||
                kinematics.length_max() - file.length[j] < options.end_stop_margin;
    if (actuator.relief_pressure > 0) {
      const double limit = actuator.relief_pressure - options.relief_margin;
      stop |= !log.pressure_a.empty() && log.pressure_a[j] >= limit;
      stop |= !log.pressure_b.empty() && log.pressure_b[j] >= limit;
    }
    file.excluded[j] = stop ? 1 : 0;
  }
  for (std::size_t j = 0; j < n;) {
    if (file.excluded[j]) {
      ++j;
      continue;
    }
    std::size_t end = j;
    while (end < n && !file.excluded[end]) ++end;
    if (end - j >= kMinSegment) {
      file.segments.emplace_back(j, end);
    } else {
      for (std::size_t k = j; k < end; ++k) file.excluded[k] = 1;
    }
    j = end;
  }
  return file;
}

// The residuals, one block per segment of the angle term and one per chunk of the spool term.
// Parameter blocks: θ = [d, τ_d, τ_s, Q_rated]; the motion lag τ_m [s]; the segment's start
// angle [rad]. τ_m shifts the joint's response after the spool's: the few milliseconds the
// oil's compressibility and the arm's inertia add (valve_model.h). A logged spool tells it
// apart from τ_d; without one it is held at zero and τ_d absorbs it.
//
// Why blocks and not one per file: a file's segments (runs between end-stop contacts) each
// have their own start angle, so a single block over a file would make each of its rows
// depend on all of them: a dense Jacobian rows × (5 + segments), and automatic derivatives
// through the whole log once per 8 of its parameters. An hour of repeated steps into the
// stops has thousands of segments, and that went as rows × segments in time and memory (out of
// memory at a million rows). Per block, every row depends on at most 6 parameters (4 for the
// spool), so the Jacobian holds 6 numbers a row whatever the number of segments, and each
// evaluation simulates each row a bounded number of times: linear in the log.
//
// Each block simulates the valve from a warm-up before its first row, not from the start of
// the log (the blocks are evaluated independently, in parallel): the simulation starts at rest
// at the command of the row τ_d + τ_m + kWarmUpTimeConstants·τ_s (current values) before
// it; what remains of the true spool state there is e^{-12} ≈ 6·10⁻⁶ of it, far below the
// noise. Blocks near the start of a log begin at its first row and are exact.
constexpr double kWarmUpTimeConstants = 12;
constexpr std::size_t kSpoolChunk = 4096;  ///< rows per block of the spool term

// First row to simulate from for a block whose first instant is `at`: the last row at or
// before at − warm_up, or the first row.
std::size_t WarmUpRow(const std::vector<double>& time, double at, double warm_up) {
  const auto it = std::upper_bound(time.begin(), time.end(), at - warm_up);
  return it == time.begin() ? 0 : static_cast<std::size_t>(it - time.begin()) - 1;
}

// The angle term over one segment [begin, end) of a file.
struct SegmentResidual {
  const PreparedFile* file;
  const ActuatorKinematics* kinematics;
  std::size_t begin, end;
  double angle_weight;  // 1/σ_q [1/rad]

  template <typename T>
  T LengthAt(const T& q) const {
    const double q0 = Value(q);
    return kinematics->Length(q0) + kinematics->Lever(q0) * (q - q0);
  }

  // q(L) through the inverse kinematics, its derivative dq/dL = 1/(dL/dq) from the same table.
  template <typename T>
  T AngleAt(const T& length) const {
    const double l0 = Value(length);
    double slope = 0;  // dq/dL
    const double q0 = kinematics->Angle(l0, &slope);
    return q0 + (length - l0) * slope;
  }

  template <typename T>
  bool operator()(const T* theta, const T* lag, const T* start, T* residual) const {
    const HydraulicLog& log = *file->log;
    const double warm_up = Value(theta[1]) + Value(lag[0]) + kWarmUpTimeConstants * Value(theta[2]);
    const std::size_t first = WarmUpRow(log.time, log.time[begin], warm_up);
    const std::span<const double> time(log.time), command(log.command);
    const double inv_extend = 1.0 / kinematics->area_extend();
    const double inv_retract = 1.0 / kinematics->area_retract();
    const T length0 = LengthAt(start[0]);
    T positive0(0.0), negative0(0.0);
    ForEachValveSample(
        time.subspan(first), command.subspan(first), end - begin,
        [&](std::size_t j) { return T(log.time[begin + j]) - lag[0]; }, theta[0], theta[1],
        theta[2],
        [&](std::size_t j, const T&, const T& positive, const T& negative) {
          if (j == 0) positive0 = positive, negative0 = negative;
          const T displacement = theta[3] * ((positive - positive0) * inv_extend +
                                             (negative - negative0) * inv_retract);
          residual[j] =
              (AngleAt(T(length0 + displacement)) - log.joint_angle[begin + j]) * angle_weight;
        });
    return true;
  }
};

// The spool term over rows [begin, end) of a file.
struct SpoolResidual {
  const HydraulicLog* log;
  std::size_t begin, end;
  double spool_weight;  // 1/σ_s

  template <typename T>
  bool operator()(const T* theta, T* residual) const {
    const double warm_up = Value(theta[1]) + kWarmUpTimeConstants * Value(theta[2]);
    const std::size_t first = WarmUpRow(log->time, log->time[begin], warm_up);
    const std::span<const double> time(log->time), command(log->command);
    ForEachValveSample(
        time.subspan(first), command.subspan(first), end - begin,
        [&](std::size_t j) { return T(log->time[begin + j]); }, theta[0], theta[1], theta[2],
        [&](std::size_t j, const T& x, const T&, const T&) {
          residual[j] = (x - log->spool[begin + j]) * spool_weight;
        });
    return true;
  }
};

struct FitState {
  std::array<double, kNumParams> theta{};
  double lag = 0;                          ///< τ_m [s]
  std::vector<std::vector<double>> start;  ///< per file, per segment [rad]
  int iterations = 0;
};

// Fitted curves of one file (NaN at excluded samples).
FileFit Curves(const PreparedFile& file, const ActuatorKinematics& kinematics,
               const FitState& state, std::size_t index) {
  const HydraulicLog& log = *file.log;
  FileFit out;
  out.file = log.file;
  out.level = file.level;
  out.time = log.time;
  out.angle = log.joint_angle;
  out.spool = log.spool;
  out.excluded = file.excluded;
  out.angle_fit.assign(log.size(), std::nan(""));
  std::vector<double> residual;
  std::size_t rows = 0;
  double sum = 0;
  for (std::size_t k = 0; k < file.segments.size(); ++k) {
    const auto [begin, end] = file.segments[k];
    residual.resize(end - begin);
    const SegmentResidual segment{&file, &kinematics, begin, end, 1.0};
    segment(state.theta.data(), &state.lag, &state.start[index][k], residual.data());
    for (std::size_t j = begin; j < end; ++j) {
      out.angle_fit[j] = log.joint_angle[j] + residual[j - begin];
      sum += residual[j - begin] * residual[j - begin];
    }
    rows += end - begin;
  }
  out.angle_rms = std::sqrt(sum / std::max<std::size_t>(1, rows));
  if (log.has_spool()) {
    out.spool_fit.resize(log.size());
    double spool_sum = 0;
    const auto& theta = state.theta;
    ForEachValveSample(
        log.time, log.command, log.size(), [&](std::size_t j) { return log.time[j]; }, theta[0],
        theta[1], theta[2],
        [&](std::size_t j, double x, double, double) {
          out.spool_fit[j] = x;
          spool_sum += (x - log.spool[j]) * (x - log.spool[j]);
        });
    out.spool_rms = std::sqrt(spool_sum / log.size());
  }
  return out;
}

// Part of a file the starting scan looks at (scan_windows below).
struct ScanPart {
  const PreparedFile* file = nullptr;
  std::size_t scored_begin = 0;  ///< rows before this one only warm the spool up
};

// The modelled flow integral ∫ x_s dt / A at each sample of `file` for Q_rated = 1 [m].
void FlowIntegral(const PreparedFile& file, const ActuatorKinematics& kinematics, double zone,
                  double delay, double tau, ValveResponse<double>& response,
                  std::vector<double>& flow) {
  const HydraulicLog& log = *file.log;
  response = SimulateValve(log.time, log.command, zone, delay, tau);
  const double inv_extend = 1.0 / kinematics.area_extend();
  const double inv_retract = 1.0 / kinematics.area_retract();
  flow.resize(log.size());
  for (std::size_t j = 0; j < log.size(); ++j) {
    flow[j] = response.positive[j] * inv_extend + response.negative[j] * inv_retract;
  }
}

// Lever-weighted means of the modelled flow integral and of the length over a segment.
std::pair<double, double> WeightedMeans(const PreparedFile& file, const std::vector<double>& flow,
                                        std::size_t begin, std::size_t end) {
  double w = 0, mx = 0, my = 0;
  for (std::size_t j = begin; j < end; ++j) {
    const double wj = 1.0 / (file.lever[j] * file.lever[j]);
    w += wj, mx += wj * flow[j], my += wj * file.length[j];
  }
  return {mx / w, my / w};
}

// The start angle of each segment of each file for θ: L_j ≈ c + Q F_j per segment (c solved
// linearly), the start angle is q(c + Q F_begin).
template <typename Files>
std::vector<std::vector<double>> StartAngles(const Files& files,
                                             const ActuatorKinematics& kinematics,
                                             const std::array<double, kNumParams>& theta) {
  const auto [zone, delay, tau, q] = theta;
  ValveResponse<double> response;
  std::vector<double> flow;
  std::vector<std::vector<double>> start(files.size());
  for (std::size_t f = 0; f < files.size(); ++f) {
    FlowIntegral(files[f], kinematics, zone, delay, tau, response, flow);
    for (const auto& [begin, end] : files[f].segments) {
      const auto [mx, my] = WeightedMeans(files[f], flow, begin, end);
      start[f].push_back(kinematics.Angle(my - q * mx + q * flow[begin]));
    }
  }
  return start;
}

// The cost of the scan at one point (τ_d, τ_s, d), Q_rated solved linearly; returns it and
// Q_rated.
std::pair<double, double> ScanCost(const std::vector<ScanPart>& parts,
                                   const ActuatorKinematics& kinematics, double zone, double delay,
                                   double tau, const HydraulicIdentificationOptions& options,
                                   ValveResponse<double>& response, std::vector<double>& flow) {
  const double sigma_angle = 0.1 * std::numbers::pi / 180, sigma_spool = 0.01;
  double sxy = 0, sxx = 0, syy = 0, spool_cost = 0;
  for (const ScanPart& part : parts) {
    const PreparedFile& file = *part.file;
    const HydraulicLog& log = *file.log;
    FlowIntegral(file, kinematics, zone, delay, tau, response, flow);
    for (const auto& [begin, end] : file.segments) {
      const auto [mx, my] = WeightedMeans(file, flow, begin, end);
      for (std::size_t j = begin; j < end; ++j) {
        const double wj = 1.0 / (file.lever[j] * file.lever[j]);
        const double x = flow[j] - mx, y = file.length[j] - my;
        sxy += wj * x * y, sxx += wj * x * x, syy += wj * y * y;
      }
    }
    if (log.has_spool()) {
      for (std::size_t j = part.scored_begin; j < log.size(); ++j) {
        spool_cost += (response.spool[j] - log.spool[j]) * (response.spool[j] - log.spool[j]);
      }
    }
  }
  const double q = std::clamp(sxx > 0 ? sxy / sxx : options.lower.rated_flow,
                              options.lower.rated_flow, options.upper.rated_flow);
  const double cost = (syy - 2 * q * sxy + q * q * sxx) / (sigma_angle * sigma_angle) +
                      spool_cost / (sigma_spool * sigma_spool);
  return {cost, q};
}

// The scan's grid of spool time constants and dead zones (τ_d is scanned in steps).
constexpr double kScanTaus[] = {0.02, 0.04, 0.08, 0.16, 0.32};
constexpr double kScanZones[] = {0.0, 0.04, 0.08, 0.12, 0.2, 0.3};

// The starting point: a scan over (τ_d, τ_s, d) with Q_rated and the offsets solved linearly in
// the cylinder-length domain (ΔL = Q_rated·F is linear in Q_rated for a given timing), each
// length residual weighted by 1/lever² to read as an angle. The scan looks at `parts` (the
// files, or windows of long ones); the offsets are then solved on the whole `files`.
FitState StartingPoint(const std::vector<PreparedFile>& files, const std::vector<ScanPart>& parts,
                       const ActuatorKinematics& kinematics,
                       const HydraulicIdentificationOptions& options, const Progress& progress) {
  double best_cost = std::numeric_limits<double>::infinity();
  FitState best;
  ValveResponse<double> response;
  std::vector<double> flow;
  const int steps =
      static_cast<int>(std::floor((options.upper.transport_delay - options.lower.transport_delay) /
                                      options.delay_scan_step +
                                  1e-9)) +
      1;
  int reported = 0;  // quarters of the scan reported
  int step = 0;
  for (double delay = options.lower.transport_delay; delay <= options.upper.transport_delay;
       delay += options.delay_scan_step, ++step) {
    for (double tau : kScanTaus) {
      if (tau < options.lower.spool_time_constant || tau > options.upper.spool_time_constant) {
        continue;
      }
      for (double zone : kScanZones) {
        if (zone < options.lower.dead_zone || zone > options.upper.dead_zone) continue;
        const auto [cost, q] =
            ScanCost(parts, kinematics, zone, delay, tau, options, response, flow);
        if (cost < best_cost) {
          best_cost = cost;
          best.theta = {zone, delay, tau, q};
        }
      }
    }
    const int quarter = 4 * (step + 1) / std::max(steps, 1);
    if (progress && quarter > reported && quarter < 4) {
      reported = quarter;
      progress("starting scan " + std::to_string(25 * quarter) + " %");
    }
  }
  best.start = StartAngles(files, kinematics, best.theta);
  return best;
}

// Windows of long logs for the starting scan. Its cost is ~6000 simulations of what it looks
// at, so on a long log (hours at 100 Hz) it looks at a bounded number of rows: the windows with
// the most command activity (Σ|Δu|: steps and chirps, not the idle or steady stretches
// between), at least one per file. Each window is preceded by rows that only warm the spool up:
// the simulation starts at rest at that row's command, and after the longest delay plus five of
// the scan's largest spool time constants that start no longer shows. The scan only chooses
// the basin; the fit that follows uses every row.
constexpr std::size_t kScanBudget = 20000;  ///< rows scored by the scan, all files together
constexpr std::size_t kScanWindow = 2000;   ///< rows per window of a long log

struct ScanWindows {
  std::deque<HydraulicLog> logs;
  std::deque<PreparedFile> files;
  std::vector<ScanPart> parts;
};

// Rows [begin, end) of `file` as a file of its own, rows before `scored` out of the angle term.
void AddWindow(const PreparedFile& file, std::size_t begin, std::size_t scored, std::size_t end,
               ScanWindows& out) {
  const HydraulicLog& whole = *file.log;
  const auto slice = [&](const auto& v) {
    using V = std::decay_t<decltype(v)>;
    return v.empty() ? V{} : V(v.begin() + begin, v.begin() + end);
  };
  HydraulicLog& log = out.logs.emplace_back();
  log.file = whole.file;
  log.actuator = whole.actuator;
  log.row = slice(whole.row);
  log.time = slice(whole.time);
  log.command = slice(whole.command);
  log.joint_angle = slice(whole.joint_angle);
  log.spool = slice(whole.spool);
  PreparedFile& part = out.files.emplace_back();
  part.log = &log;
  part.level = file.level;
  part.length = slice(file.length);
  part.lever = slice(file.lever);
  part.excluded = slice(file.excluded);
  std::fill(part.excluded.begin(), part.excluded.begin() + (scored - begin), 1);
  for (const auto& [b, e] : file.segments) {
    const std::size_t from = std::max(b, scored), to = std::min(e, end);
    if (to >= from + kMinSegment) part.segments.emplace_back(from - begin, to - begin);
  }
  out.parts.push_back({&part, scored - begin});
}

std::unique_ptr<ScanWindows> ChooseScanWindows(const std::vector<PreparedFile>& files,
                                               const HydraulicIdentificationOptions& options) {
  auto out = std::make_unique<ScanWindows>();
  std::size_t total = 0;
  for (const PreparedFile& file : files) total += file.log->size();
  if (total <= kScanBudget) {
    for (const PreparedFile& file : files) out->parts.push_back({&file, 0});
    return out;
  }
  const double warm_up = options.upper.transport_delay + 5 * kScanTaus[std::size(kScanTaus) - 1];
  struct Candidate {
    double activity;
    std::size_t file, begin, scored, end;
  };
  std::vector<Candidate> candidates;
  for (std::size_t f = 0; f < files.size(); ++f) {
    const HydraulicLog& log = *files[f].log;
    std::vector<double> activity(log.size() + 1, 0.0);  // prefix sums of |Δu|
    for (std::size_t j = 1; j < log.size(); ++j) {
      activity[j + 1] = activity[j] + std::abs(log.command[j] - log.command[j - 1]);
    }
    for (std::size_t scored = 0; scored < log.size(); scored += kScanWindow) {
      const std::size_t end = std::min(scored + kScanWindow, log.size());
      const auto first =
          std::lower_bound(log.time.begin(), log.time.begin() + scored, log.time[scored] - warm_up);
      const std::size_t begin = static_cast<std::size_t>(first - log.time.begin());
      candidates.push_back({activity[end] - activity[begin], f, begin, scored, end});
    }
  }
  // Most active first; among equals, the earlier (a deterministic choice).
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.activity > b.activity; });
  std::vector<char> chosen(candidates.size(), 0), file_has(files.size(), 0);
  std::size_t rows = 0;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (file_has[candidates[c].file]) continue;
    file_has[candidates[c].file] = chosen[c] = 1;
    rows += candidates[c].end - candidates[c].scored;
  }
  for (std::size_t c = 0; c < candidates.size() && rows < kScanBudget; ++c) {
    if (chosen[c] || candidates[c].activity <= 0) continue;
    chosen[c] = 1;
    rows += candidates[c].end - candidates[c].scored;
  }
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    if (!chosen[c]) continue;
    const Candidate& w = candidates[c];
    AddWindow(files[w.file], w.begin, w.scored, w.end, *out);
  }
  return out;
}

struct Weights {
  double angle = 1, spool = 1;  // 1/σ
};

// The problem over `files` from `state` (updated in place).
struct Problem {
  ceres::Problem problem;
  std::vector<ceres::ResidualBlockId> blocks;
  std::vector<double*> parameter_blocks;  ///< θ, τ_m, then the start angles
  std::vector<double*> offsets;           ///< the start angles, one per angle block
  struct Rows {
    bool spool = false;      ///< the channel
    std::size_t count = 0;   ///< residuals
    bool continues = false;  ///< a spool chunk after the previous one of the same file
  };
  std::vector<Rows> rows;  ///< per block, in the order of `blocks`
  int largest_block_parameters = 0;
};

void BuildProblem(const std::vector<const PreparedFile*>& files,
                  const ActuatorKinematics& kinematics, const Weights& weights, FitState& state,
                  const std::vector<std::size_t>& state_index,
                  const HydraulicIdentificationOptions& options, bool fix_theta, Problem& out) {
  out.problem.AddParameterBlock(state.theta.data(), kNumParams);
  out.parameter_blocks.push_back(state.theta.data());
  const auto lower = ToArray(options.lower), upper = ToArray(options.upper);
  for (int i = 0; i < kNumParams; ++i) {
    out.problem.SetParameterLowerBound(state.theta.data(), i, lower[i]);
    out.problem.SetParameterUpperBound(state.theta.data(), i, upper[i]);
  }
  if (fix_theta) out.problem.SetParameterBlockConstant(state.theta.data());
  out.problem.AddParameterBlock(&state.lag, 1);
  out.parameter_blocks.push_back(&state.lag);
  out.problem.SetParameterLowerBound(&state.lag, 0, 0.0);
  out.problem.SetParameterUpperBound(&state.lag, 0, kMaxMotionLag);
  bool spool = false;
  for (const PreparedFile* file : files) spool |= file->log->has_spool();
  if (fix_theta || !spool) out.problem.SetParameterBlockConstant(&state.lag);
  for (std::size_t f = 0; f < files.size(); ++f) {
    const PreparedFile& file = *files[f];
    std::vector<double>& start = state.start[state_index[f]];
    for (std::size_t k = 0; k < file.segments.size(); ++k) {
      const auto [begin, end] = file.segments[k];
      auto* cost =
          new ceres::AutoDiffCostFunction<SegmentResidual, ceres::DYNAMIC, kNumParams, 1, 1>(
              new SegmentResidual{&file, &kinematics, begin, end, weights.angle},
              static_cast<int>(end - begin));
      out.blocks.push_back(
          out.problem.AddResidualBlock(cost, nullptr, state.theta.data(), &state.lag, &start[k]));
      out.parameter_blocks.push_back(&start[k]);
      out.offsets.push_back(&start[k]);
      out.rows.push_back({false, end - begin, false});
      out.largest_block_parameters = std::max(out.largest_block_parameters, kNumParams + 2);
    }
    if (!file.log->has_spool()) continue;
    for (std::size_t begin = 0; begin < file.log->size(); begin += kSpoolChunk) {
      const std::size_t end = std::min(begin + kSpoolChunk, file.log->size());
      auto* cost = new ceres::AutoDiffCostFunction<SpoolResidual, ceres::DYNAMIC, kNumParams>(
          new SpoolResidual{file.log, begin, end, weights.spool}, static_cast<int>(end - begin));
      out.blocks.push_back(out.problem.AddResidualBlock(cost, nullptr, state.theta.data()));
      out.rows.push_back({true, end - begin, begin > 0});
      out.largest_block_parameters = std::max(out.largest_block_parameters, kNumParams);
    }
  }
}

// `cost_resolution` > 0: stop once an iteration lowers the cost (½χ², the residuals being
// weighted by their noise) by less than that much. Near the optimum the cost has kinks (the
// spool's derivative jumps where a delayed switch crosses a sample), and Levenberg–Marquardt
// creeps along them for tens of iterations that move θ by a small fraction of its σ; on a long
// log each such iteration costs a pass over every row.
constexpr std::size_t kProgressRows = 100000;

int Solve(Problem& p, const HydraulicIdentificationOptions& options, double cost_resolution = 0) {
  ceres::Solver::Options solver;
  // Schur complement with the start angles eliminated first: each appears in one block only,
  // so its part of JᵀJ is diagonal and eliminating it costs a pass over that block's rows;
  // what is left is a dense 5×5 system in θ and τ_m. Time and memory: linear in the rows,
  // whatever the number of segments (DENSE_QR on the whole Jacobian went as rows × segments²).
  if (!p.offsets.empty()) {
    solver.linear_solver_type = ceres::DENSE_SCHUR;
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (double* offset : p.offsets) ordering->AddElementToGroup(offset, 0);
    ordering->AddElementToGroup(p.parameter_blocks[0], 1);
    ordering->AddElementToGroup(p.parameter_blocks[1], 1);
    solver.linear_solver_ordering = ordering;
  } else {
    solver.linear_solver_type = ceres::DENSE_QR;  // θ alone: rows × 4
  }
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-10;
  solver.num_threads = 2;
  if (cost_resolution > 0) {
    double cost = 0;
    p.problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
    solver.function_tolerance = std::max(1e-12, cost_resolution / std::max(cost, 1e-300));
  }
  // A pass over a long log (≥ 100k rows) takes seconds per iteration: say where it is.
  struct IterationReport : ceres::IterationCallback {
    const Progress* progress;
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
      char line[96];
      std::snprintf(line, sizeof line, "iteration %d, cost %.6g", s.iteration, s.cost);
      (*progress)(line);
      return ceres::SOLVER_CONTINUE;
    }
  } report;
  report.progress = &options.progress;
  std::size_t rows = 0;
  for (const Problem::Rows& r : p.rows) rows += r.count;
  if (options.progress && rows >= kProgressRows) solver.callbacks.push_back(&report);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &p.problem, &summary);
  return static_cast<int>(summary.iterations.size());
}

// Residual RMS of each channel at the current state (unweighted).
Weights ChannelNoise(const std::vector<const PreparedFile*>& files,
                     const ActuatorKinematics& kinematics, const FitState& state,
                     const std::vector<std::size_t>& state_index) {
  double angle_sum = 0, spool_sum = 0;
  std::size_t angle_n = 0, spool_n = 0;
  for (std::size_t f = 0; f < files.size(); ++f) {
    const FileFit fit = Curves(*files[f], kinematics, state, state_index[f]);
    const std::size_t rows = files[f]->angle_rows();
    angle_sum += fit.angle_rms * fit.angle_rms * rows, angle_n += rows;
    if (files[f]->log->has_spool()) {
      spool_sum += fit.spool_rms * fit.spool_rms * files[f]->log->size();
      spool_n += files[f]->log->size();
    }
  }
  Weights noise;
  // Floors: a noiseless simulated log must not make a weight infinite.
  noise.angle = std::max(std::sqrt(angle_sum / std::max<std::size_t>(1, angle_n)), 1e-6);
  noise.spool = std::max(std::sqrt(spool_sum / std::max<std::size_t>(1, spool_n)), 1e-5);
  return noise;
}

// Fit θ and the offsets on `files`: weighted by default noise, then by the residual RMS of each
// channel, twice. Returns the weights (1/σ) used last.
// `first_pass` > 0 resumes with `weights` (set by earlier passes on windows of the logs).
Weights Fit(const std::vector<const PreparedFile*>& files, const ActuatorKinematics& kinematics,
            FitState& state, const std::vector<std::size_t>& state_index,
            const HydraulicIdentificationOptions& options, bool fix_theta,
            const std::string& stage = "fit", int first_pass = 0, int last_pass = 2,
            Weights weights = {1.0 / (0.1 * std::numbers::pi / 180), 1.0 / 0.01},
            double cost_resolution = 0) {
  state.iterations = 0;
  for (int pass = first_pass; pass <= last_pass; ++pass) {
    Report(options.progress, stage + " pass " + std::to_string(pass + 1) + " of 3" +
                                 (last_pass < 2 ? " (on the scan's windows)" : ""));
    Problem p;
    BuildProblem(files, kinematics, weights, state, state_index, options, fix_theta, p);
    state.iterations += Solve(p, options, cost_resolution);
    const Weights noise = ChannelNoise(files, kinematics, state, state_index);
    weights = {1.0 / noise.angle, 1.0 / noise.spool};
  }
  return weights;
}

// Long logs: the first two passes (which only set the noise weights and bring θ near the
// optimum) on the scan's windows, a bounded number of rows; the last one on every row, from
// there. Each pass costs tens of evaluations of the whole problem: on every row, the three
// passes would make the fit several times slower than needed, for the same optimum.
// Cost decrease (½χ²) below which the last pass on a long log stops: Δχ² = 0.002 per
// iteration, θ moving by a few hundredths of its σ.
constexpr double kLongLogCostResolution = 1e-3;

Weights FitLongLogs(const std::vector<PreparedFile>& prepared, const ScanWindows& windows,
                    const ActuatorKinematics& kinematics, FitState& state,
                    const HydraulicIdentificationOptions& options) {
  std::vector<const PreparedFile*> parts, all;
  std::vector<std::size_t> part_index, index;
  for (const PreparedFile& file : windows.files) {
    part_index.push_back(parts.size());
    parts.push_back(&file);
  }
  for (const PreparedFile& file : prepared) {
    index.push_back(all.size());
    all.push_back(&file);
  }
  FitState on_windows = state;
  on_windows.start = StartAngles(windows.files, kinematics, state.theta);
  Weights weights = Fit(parts, kinematics, on_windows, part_index, options, false, "fit", 0, 1);
  const int iterations = on_windows.iterations;
  state.theta = on_windows.theta;
  state.lag = on_windows.lag;
  state.start = StartAngles(prepared, kinematics, state.theta);
  // The last pass weighs the channels by their residual RMS over every row it fits (one
  // simulation of the log), not over the windows: the most active windows miss much of what
  // the model does not explain elsewhere (end-stop contacts, idle stretches), and weights from
  // them moved the optimum by tens of σ on a cycle log with end stops (d 7.06 % instead of
  // the 7.74 % of three passes on every row; 7.97 % with these, the truth 8 %).
  const Weights noise = ChannelNoise(all, kinematics, state, index);
  weights = {1.0 / noise.angle, 1.0 / noise.spool};
  const Weights final_weights = Fit(all, kinematics, state, index, options, false, "fit", 2, 2,
                                    weights, kLongLogCostResolution);
  state.iterations += iterations;
  return final_weights;
}

// Lag-1 autocorrelation of consecutive residuals within runs [begin, end) of `r`.
double Autocorrelation(const std::vector<double>& r,
                       const std::vector<std::pair<std::size_t, std::size_t>>& runs) {
  double num = 0, den = 0;
  for (const auto& [begin, end] : runs) {
    for (std::size_t i = begin; i < end; ++i) {
      den += r[i] * r[i];
      if (i + 1 < end) num += r[i] * r[i + 1];
    }
  }
  return den > 0 ? std::clamp(num / den, 0.0, 0.99) : 0.0;
}

// 1σ of θ from the Jacobian at the optimum (see the header). The marginal covariance of θ is
// the inverse of the Schur complement of the start angles in JᵀJ: each start angle appears in
// one block only, so its part of JᵀJ is diagonal and JᵀJ is accumulated row by row from the
// sparse Jacobian (at most 6 numbers a row) in time linear in the rows and memory linear in
// the segments, never as a dense matrix. Also records the problem's shape in `out`.
std::array<double, kNumParams> StandardDeviations(const std::vector<const PreparedFile*>& files,
                                                  const ActuatorKinematics& kinematics,
                                                  FitState& state, const Weights& weights,
                                                  const HydraulicIdentificationOptions& options,
                                                  ActuatorIdentification& out) {
  std::vector<std::size_t> index(files.size());
  for (std::size_t f = 0; f < files.size(); ++f) index[f] = f;
  Problem p;
  BuildProblem(files, kinematics, weights, state, index, options, false, p);
  out.residual_blocks = p.blocks.size();
  out.largest_block_parameters = p.largest_block_parameters;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = p.parameter_blocks;
  evaluate.residual_blocks = p.blocks;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  double cost = 0;
  p.problem.Evaluate(evaluate, &cost, &residuals, nullptr, &crs);
  // Rows by channel, runs of consecutive samples for the autocorrelation (a file's spool
  // chunks make one run).
  std::vector<std::pair<std::size_t, std::size_t>> angle_runs, spool_runs;
  std::size_t row = 0;
  for (const Problem::Rows& rows : p.rows) {
    auto& runs = rows.spool ? spool_runs : angle_runs;
    if (rows.continues && !runs.empty() && runs.back().second == row) {
      runs.back().second += rows.count;
    } else {
      runs.emplace_back(row, row + rows.count);
    }
    row += rows.count;
  }
  const std::size_t m = residuals.size();
  const std::size_t n = static_cast<std::size_t>(crs.num_cols);
  double s2 = 0;
  for (double r : residuals) s2 += r * r;
  s2 /= std::max<std::size_t>(1, m > n ? m - n : 1);
  std::vector<double> weight(m, 1.0);  // per row: the squared autocorrelation scale
  for (const auto* runs : {&angle_runs, &spool_runs}) {
    const double rho = Autocorrelation(residuals, *runs);
    for (const auto& [begin, end] : *runs) {
      std::fill(weight.begin() + begin, weight.begin() + end, (1 - rho) / (1 + rho));
    }
  }
  // Columns: θ (and τ_m, when it is free), then one per start angle.
  const int offsets = static_cast<int>(p.offsets.size());
  const int global = crs.num_cols - offsets;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(global, global);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(global, offsets);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(offsets);
  Eigen::VectorXd g(global);
  for (int r = 0; r < crs.num_rows; ++r) {
    g.setZero();
    int offset = -1;
    double s = 0;
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) {
      if (crs.cols[k] < global) {
        g[crs.cols[k]] = crs.values[k];
      } else {
        offset = crs.cols[k] - global, s = crs.values[k];
      }
    }
    const double w = weight[r];
    a.noalias() += w * g * g.transpose();
    if (offset >= 0) {
      b.col(offset) += w * s * g;
      d[offset] += w * s * s;
    }
  }
  Eigen::MatrixXd schur = a;
  for (int k = 0; k < offsets; ++k) {
    if (d[k] > 0) schur.noalias() -= b.col(k) * b.col(k).transpose() / d[k];
  }
  const Eigen::MatrixXd covariance = s2 * schur.completeOrthogonalDecomposition().pseudoInverse();
  std::array<double, kNumParams> sigma{};
  for (int i = 0; i < kNumParams; ++i) sigma[i] = std::sqrt(std::max(covariance(i, i), 0.0));
  return sigma;
}

}  // namespace

int FindActuator(const model::MachineDescription& machine, const std::string& name) {
  const auto& actuators = machine.hydraulics.actuators;
  for (std::size_t a = 0; a < actuators.size(); ++a) {
    if (actuators[a].name == name) return static_cast<int>(a);
  }
  for (std::size_t a = 0; a < actuators.size(); ++a) {
    if (actuators[a].joint == name) return static_cast<int>(a);
  }
  return -1;
}

ActuatorIdentification IdentifyActuator(const model::MachineDescription& machine,
                                        const generated::MachineFunctions& functions, int actuator,
                                        const std::vector<HydraulicLog>& logs,
                                        const HydraulicIdentificationOptions& options) {
  const auto t_begin = std::chrono::steady_clock::now();
  if (logs.empty()) throw std::invalid_argument("IdentifyActuator: no logs");
  const Progress& progress = options.progress;
  const model::Actuator& act = machine.hydraulics.actuators.at(actuator);
  const ActuatorKinematics kinematics(machine, functions, actuator);

  ActuatorIdentification out;
  out.actuator = act.name;
  out.actuator_index = actuator;
  out.nominal = {act.valve.dead_zone, act.valve.transport_delay, act.valve.spool_time_constant,
                 act.valve.rated_flow};

  // Excitation: every file must command the valve; some file must move the joint.
  bool moves = false;
  for (const HydraulicLog& log : logs) {
    RequireExcitation(log);
    const auto [low, high] = std::minmax_element(log.joint_angle.begin(), log.joint_angle.end());
    moves |= *high - *low > 0.2 * std::numbers::pi / 180;
  }
  if (!moves) {
    const auto [low, high] =
        std::minmax_element(logs[0].joint_angle.begin(), logs[0].joint_angle.end());
    FailAtSample(
        logs[0], 0,
        "no excitation: the joint angle spans only " +
            core::FormatNumber(std::round((*high - *low) * 180 / std::numbers::pi * 1e3) / 1e3) +
            " deg (the valve never opened past its dead zone?); at least 0.2 deg is needed");
  }

  std::vector<PreparedFile> prepared;
  for (const HydraulicLog& log : logs) prepared.push_back(Prepare(log, kinematics, act, options));
  std::vector<const PreparedFile*> all;
  std::vector<std::size_t> index;
  for (std::size_t f = 0; f < prepared.size(); ++f) {
    all.push_back(&prepared[f]);
    index.push_back(f);
    out.samples += prepared[f].log->size();
    for (char e : prepared[f].excluded) out.excluded += e;
    out.has_spool |= prepared[f].log->has_spool();
  }

  Report(progress, "starting scan (" + std::to_string(out.samples) + " rows)");
  const std::unique_ptr<ScanWindows> windows = ChooseScanWindows(prepared, options);
  FitState state = StartingPoint(prepared, windows->parts, kinematics, options, progress);
  Weights weights;
  if (windows->files.empty()) {
    weights = Fit(all, kinematics, state, index, options, false);
  } else {
    weights = FitLongLogs(prepared, *windows, kinematics, state, options);
  }
  Report(progress, "uncertainty");
  out.params = FromArray(state.theta.data());
  out.motion_lag = state.lag;
  out.iterations = state.iterations;
  out.angle_sigma = 1.0 / weights.angle;
  out.spool_sigma = out.has_spool ? 1.0 / weights.spool : 0.0;
  const std::array<double, kNumParams> sigma =
      StandardDeviations(all, kinematics, state, weights, options, out);
  out.std_dev = out.std_dev_jacobian = FromArray(sigma.data());
  const auto lower = ToArray(options.lower), upper = ToArray(options.upper);
  for (int i = 0; i < kNumParams; ++i) {
    const double span = upper[i] - lower[i];
    out.at_bound.push_back(state.theta[i] - lower[i] < 1e-6 * span ||
                           upper[i] - state.theta[i] < 1e-6 * span);
  }
  for (std::size_t f = 0; f < prepared.size(); ++f) {
    out.files.push_back(Curves(prepared[f], kinematics, state, f));
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_begin).count();

  if (!options.cross_validate) return out;
  // Duty levels to the percent.
  std::map<long, std::vector<std::size_t>> levels;
  for (std::size_t f = 0; f < prepared.size(); ++f) {
    levels[std::lround(prepared[f].level * 100)].push_back(f);
  }
  if (levels.size() < 2) return out;
  for (const auto& [level, held_out] : levels) {
    const std::string stage = "cross-validation " +
                              std::to_string(out.cross_validation.size() + 1) + " of " +
                              std::to_string(levels.size());
    std::vector<const PreparedFile*> train, test;
    std::vector<std::size_t> train_index, test_index;
    for (std::size_t f = 0; f < prepared.size(); ++f) {
      const bool out_of_fold = std::find(held_out.begin(), held_out.end(), f) != held_out.end();
      (out_of_fold ? test : train).push_back(&prepared[f]);
      (out_of_fold ? test_index : train_index).push_back(f);
    }
    FitState fold = state;  // started from the full fit: the same optimum, fewer iterations
    Fit(train, kinematics, fold, train_index, options, false, stage + ", fit");
    Fit(test, kinematics, fold, test_index, options, true, stage + ", prediction");  // offsets
    CrossValidationFold result;
    result.level = level / 100.0;
    result.params = FromArray(fold.theta.data());
    double angle_sum = 0, spool_sum = 0;
    std::size_t angle_n = 0, spool_n = 0;
    for (std::size_t t = 0; t < test.size(); ++t) {
      const FileFit fit = Curves(*test[t], kinematics, fold, test_index[t]);
      result.files.push_back(fit.file);
      const std::size_t rows = test[t]->angle_rows();
      angle_sum += fit.angle_rms * fit.angle_rms * rows, angle_n += rows;
      const auto [low, high] = std::minmax_element(fit.angle.begin(), fit.angle.end());
      result.angle_range = std::max(result.angle_range, *high - *low);
      if (!fit.spool.empty()) {
        spool_sum += fit.spool_rms * fit.spool_rms * fit.spool.size();
        spool_n += fit.spool.size();
      }
    }
    result.angle_rms = std::sqrt(angle_sum / std::max<std::size_t>(1, angle_n));
    result.spool_rms = spool_n ? std::sqrt(spool_sum / spool_n) : 0.0;
    out.cross_validation.push_back(result);
  }
  const std::size_t g = out.cross_validation.size();
  if (g >= 3) {
    std::array<double, kNumParams> mean{}, spread{};
    for (const auto& fold : out.cross_validation) {
      const auto p = ToArray(fold.params);
      for (int i = 0; i < kNumParams; ++i) mean[i] += p[i] / g;
    }
    for (const auto& fold : out.cross_validation) {
      const auto p = ToArray(fold.params);
      for (int i = 0; i < kNumParams; ++i) spread[i] += (p[i] - mean[i]) * (p[i] - mean[i]);
    }
    std::array<double, kNumParams> jackknife{}, combined{};
    for (int i = 0; i < kNumParams; ++i) {
      jackknife[i] = std::sqrt((g - 1.0) / g * spread[i]);
      combined[i] = std::hypot(jackknife[i], sigma[i]);
    }
    out.std_dev_levels = FromArray(jackknife.data());
    out.std_dev = FromArray(combined.data());
  }
  return out;
}

}  // namespace autoshovel::identification
