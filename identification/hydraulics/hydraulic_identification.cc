#include "identification/hydraulics/hydraulic_identification.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

#include "runtime/core/diagnostics.h"
#include "runtime/core/strings.h"

namespace autoshovel::identification {

namespace {

constexpr int kNumParams = 4;           // d, τ_d, τ_s, Q_rated
constexpr std::size_t kMinSegment = 5;  // shorter runs between end stops are left out
constexpr double kMaxMotionLag = 0.1;   // τ_m bound [s]

double Value(double x) { return x; }
template <int N>
double Value(const ceres::Jet<double, N>& x) {
  return x.a;
}

[[noreturn]] void Fail(const HydraulicLog& log, std::size_t sample, const std::string& message) {
  const int row = log.row.empty() ? 0 : log.row[std::min(sample, log.row.size() - 1)];
  core::DiagnosticSink sink;
  sink.Add({log.file, row, 1}, "", message);
  sink.ThrowIfAny();
  throw std::logic_error("unreachable");
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

// The residuals of one file: angle rows (segment by segment), then spool rows.
// Parameter blocks: θ = [d, τ_d, τ_s, Q_rated]; the motion lag τ_m [s]; then the start angle
// of each segment [rad]. τ_m shifts the joint's response after the spool's: the few
// milliseconds the oil's compressibility and the arm's inertia add (valve_model.h). A logged
// spool tells it apart from τ_d; without one it is held at zero and τ_d absorbs it.
struct LogResidual {
  const PreparedFile* file;
  const ActuatorKinematics* kinematics;
  double angle_weight;  // 1/σ_q [1/rad]
  double spool_weight;  // 1/σ_s

  template <typename T>
  T LengthAt(const T& q) const {
    const double q0 = Value(q);
    return kinematics->Length(q0) + kinematics->Lever(q0) * (q - q0);
  }

  // q(L) through the generated inverse, its derivative from the implicit function theorem:
  // dq = dL / (dL/dq).
  template <typename T>
  T AngleAt(const T& length) const {
    const double l0 = Value(length);
    const double q0 = kinematics->Angle(l0);
    return q0 + (length - l0) / kinematics->Lever(q0);
  }

  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const T* theta = parameters[0];
    const T lag = parameters[1][0];
    const T* start = parameters[2];
    const HydraulicLog& log = *file->log;
    std::vector<T> shifted(log.size());
    for (std::size_t j = 0; j < log.size(); ++j) shifted[j] = log.time[j] - lag;
    const ValveResponse<T> response =
        SimulateValve(log.time, log.command, shifted, theta[0], theta[1], theta[2]);
    const double inv_extend = 1.0 / kinematics->area_extend();
    const double inv_retract = 1.0 / kinematics->area_retract();
    std::size_t row = 0;
    for (std::size_t k = 0; k < file->segments.size(); ++k) {
      const auto [begin, end] = file->segments[k];
      const T length0 = LengthAt(start[k]);
      for (std::size_t j = begin; j < end; ++j) {
        const T displacement =
            theta[3] * ((response.positive[j] - response.positive[begin]) * inv_extend +
                        (response.negative[j] - response.negative[begin]) * inv_retract);
        residual[row++] = (AngleAt(T(length0 + displacement)) - log.joint_angle[j]) * angle_weight;
      }
    }
    if (log.has_spool()) {
      const ValveResponse<T> valve =
          SimulateValve(log.time, log.command, theta[0], theta[1], theta[2]);
      for (std::size_t j = 0; j < log.size(); ++j) {
        residual[row++] = (valve.spool[j] - log.spool[j]) * spool_weight;
      }
    }
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
  const LogResidual functor{&file, &kinematics, 1.0, 1.0};
  std::vector<double> residual(file.rows());
  const double* blocks[] = {state.theta.data(), &state.lag, state.start[index].data()};
  functor(blocks, residual.data());
  std::size_t row = 0;
  double sum = 0;
  for (const auto& [begin, end] : file.segments) {
    for (std::size_t j = begin; j < end; ++j) {
      out.angle_fit[j] = log.joint_angle[j] + residual[row];
      sum += residual[row] * residual[row];
      ++row;
    }
  }
  out.angle_rms = std::sqrt(sum / std::max<std::size_t>(1, row));
  if (log.has_spool()) {
    out.spool_fit.resize(log.size());
    double spool_sum = 0;
    for (std::size_t j = 0; j < log.size(); ++j, ++row) {
      out.spool_fit[j] = log.spool[j] + residual[row];
      spool_sum += residual[row] * residual[row];
    }
    out.spool_rms = std::sqrt(spool_sum / log.size());
  }
  return out;
}

// The starting point: a scan over (τ_d, τ_s, d) with Q_rated and the offsets solved linearly in
// the cylinder-length domain (ΔL = Q_rated·F is linear in Q_rated for a given timing), each
// length residual weighted by 1/lever² to read as an angle.
FitState StartingPoint(const std::vector<PreparedFile>& files, const ActuatorKinematics& kinematics,
                       const HydraulicIdentificationOptions& options) {
  const double sigma_angle = 0.1 * std::numbers::pi / 180, sigma_spool = 0.01;
  const double inv_extend = 1.0 / kinematics.area_extend();
  const double inv_retract = 1.0 / kinematics.area_retract();
  double best_cost = std::numeric_limits<double>::infinity();
  FitState best;
  const double taus[] = {0.02, 0.04, 0.08, 0.16, 0.32};
  const double zones[] = {0.0, 0.04, 0.08, 0.12, 0.2, 0.3};
  std::vector<std::vector<double>> flow(files.size());
  // Lever-weighted means of the modelled flow integral and of the length over a segment.
  const auto weighted_means = [&](std::size_t f, std::size_t begin, std::size_t end) {
    double w = 0, mx = 0, my = 0;
    for (std::size_t j = begin; j < end; ++j) {
      const double wj = 1.0 / (files[f].lever[j] * files[f].lever[j]);
      w += wj, mx += wj * flow[f][j], my += wj * files[f].length[j];
    }
    return std::pair<double, double>{mx / w, my / w};
  };
  for (double delay = options.lower.transport_delay; delay <= options.upper.transport_delay;
       delay += options.delay_scan_step) {
    for (double tau : taus) {
      if (tau < options.lower.spool_time_constant || tau > options.upper.spool_time_constant) {
        continue;
      }
      for (double zone : zones) {
        if (zone < options.lower.dead_zone || zone > options.upper.dead_zone) continue;
        double sxy = 0, sxx = 0, syy = 0, spool_cost = 0;
        for (std::size_t f = 0; f < files.size(); ++f) {
          const HydraulicLog& log = *files[f].log;
          const ValveResponse<double> r = SimulateValve(log.time, log.command, zone, delay, tau);
          flow[f].resize(log.size());
          for (std::size_t j = 0; j < log.size(); ++j) {
            flow[f][j] = r.positive[j] * inv_extend + r.negative[j] * inv_retract;
          }
          for (const auto& [begin, end] : files[f].segments) {
            const auto [mx, my] = weighted_means(f, begin, end);
            for (std::size_t j = begin; j < end; ++j) {
              const double wj = 1.0 / (files[f].lever[j] * files[f].lever[j]);
              const double x = flow[f][j] - mx, y = files[f].length[j] - my;
              sxy += wj * x * y, sxx += wj * x * x, syy += wj * y * y;
            }
          }
          if (log.has_spool()) {
            for (std::size_t j = 0; j < log.size(); ++j) {
              spool_cost += (r.spool[j] - log.spool[j]) * (r.spool[j] - log.spool[j]);
            }
          }
        }
        const double q = std::clamp(sxx > 0 ? sxy / sxx : options.lower.rated_flow,
                                    options.lower.rated_flow, options.upper.rated_flow);
        const double cost = (syy - 2 * q * sxy + q * q * sxx) / (sigma_angle * sigma_angle) +
                            spool_cost / (sigma_spool * sigma_spool);
        if (cost < best_cost) {
          best_cost = cost;
          best.theta = {zone, delay, tau, q};
          // Offsets: L_j ≈ c + Q F_j per segment; the start angle is q(c + Q F_begin).
          best.start.assign(files.size(), {});
          for (std::size_t f = 0; f < files.size(); ++f) {
            for (const auto& [begin, end] : files[f].segments) {
              const auto [mx, my] = weighted_means(f, begin, end);
              best.start[f].push_back(kinematics.Angle(my - q * mx + q * flow[f][begin]));
            }
          }
        }
      }
    }
  }
  return best;
}

struct Weights {
  double angle = 1, spool = 1;  // 1/σ
};

// Builds the problem over `files` from `state` (updated in place).
struct Problem {
  ceres::Problem problem;
  std::vector<ceres::ResidualBlockId> blocks;
  std::vector<double*> parameter_blocks;
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
    if (files[f]->rows() == 0) continue;
    std::vector<double>& start = state.start[state_index[f]];
    auto* cost = new ceres::DynamicAutoDiffCostFunction<LogResidual, 8>(
        new LogResidual{files[f], &kinematics, weights.angle, weights.spool});
    cost->AddParameterBlock(kNumParams);
    cost->AddParameterBlock(1);
    std::vector<double*> blocks = {state.theta.data(), &state.lag};
    if (start.empty()) start.push_back(0.0);  // no angle rows: an unused offset keeps the layout
    cost->AddParameterBlock(static_cast<int>(start.size()));
    blocks.push_back(start.data());
    cost->SetNumResiduals(static_cast<int>(files[f]->rows()));
    out.blocks.push_back(out.problem.AddResidualBlock(cost, nullptr, blocks));
    out.parameter_blocks.push_back(start.data());
    if (files[f]->segments.empty()) out.problem.SetParameterBlockConstant(start.data());
  }
}

int Solve(Problem& p, const HydraulicIdentificationOptions& options) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-10;
  solver.num_threads = 2;
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
Weights Fit(const std::vector<const PreparedFile*>& files, const ActuatorKinematics& kinematics,
            FitState& state, const std::vector<std::size_t>& state_index,
            const HydraulicIdentificationOptions& options, bool fix_theta) {
  Weights weights{1.0 / (0.1 * std::numbers::pi / 180), 1.0 / 0.01};
  state.iterations = 0;
  for (int pass = 0; pass < 3; ++pass) {
    Problem p;
    BuildProblem(files, kinematics, weights, state, state_index, options, fix_theta, p);
    state.iterations += Solve(p, options);
    const Weights noise = ChannelNoise(files, kinematics, state, state_index);
    weights = {1.0 / noise.angle, 1.0 / noise.spool};
  }
  return weights;
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

// 1σ of θ from the Jacobian at the optimum (see the header).
std::array<double, kNumParams> StandardDeviations(const std::vector<const PreparedFile*>& files,
                                                  const ActuatorKinematics& kinematics,
                                                  FitState& state, const Weights& weights,
                                                  const HydraulicIdentificationOptions& options) {
  std::vector<std::size_t> index(files.size());
  for (std::size_t f = 0; f < files.size(); ++f) index[f] = f;
  Problem p;
  BuildProblem(files, kinematics, weights, state, index, options, false, p);
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = p.parameter_blocks;
  evaluate.residual_blocks = p.blocks;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  double cost = 0;
  p.problem.Evaluate(evaluate, &cost, &residuals, nullptr, &crs);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) jacobian(r, crs.cols[k]) = crs.values[k];
  }
  // Rows by channel, runs of consecutive samples for the autocorrelation.
  std::vector<std::pair<std::size_t, std::size_t>> angle_runs, spool_runs;
  std::size_t row = 0;
  for (const PreparedFile* file : files) {
    if (file->rows() == 0) continue;
    for (const auto& [begin, end] : file->segments) {
      angle_runs.emplace_back(row, row + end - begin);
      row += end - begin;
    }
    if (file->log->has_spool()) {
      spool_runs.emplace_back(row, row + file->log->size());
      row += file->log->size();
    }
  }
  const std::size_t m = residuals.size();
  const std::size_t n = static_cast<std::size_t>(crs.num_cols);
  double s2 = 0;
  for (double r : residuals) s2 += r * r;
  s2 /= std::max<std::size_t>(1, m > n ? m - n : 1);
  for (const auto* runs : {&angle_runs, &spool_runs}) {
    const double rho = Autocorrelation(residuals, *runs);
    const double scale = std::sqrt((1 - rho) / (1 + rho));
    for (const auto& [begin, end] : *runs) {
      jacobian.middleRows(begin, end - begin) *= scale;
    }
  }
  const Eigen::MatrixXd information = jacobian.transpose() * jacobian;
  const Eigen::MatrixXd covariance =
      s2 * information.completeOrthogonalDecomposition().pseudoInverse();
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
    double largest = 0;
    for (double u : log.command) largest = std::max(largest, std::abs(u));
    if (largest <= 0.01) {
      Fail(log, 0,
           "no excitation: the command stays within +/-1 % over all " + std::to_string(log.size()) +
               " rows (a step or chirp log is expected)");
    }
    const auto [low, high] = std::minmax_element(log.joint_angle.begin(), log.joint_angle.end());
    moves |= *high - *low > 0.2 * std::numbers::pi / 180;
  }
  if (!moves) {
    const auto [low, high] =
        std::minmax_element(logs[0].joint_angle.begin(), logs[0].joint_angle.end());
    Fail(logs[0], 0,
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

  FitState state = StartingPoint(prepared, kinematics, options);
  const Weights weights = Fit(all, kinematics, state, index, options, false);
  out.params = FromArray(state.theta.data());
  out.motion_lag = state.lag;
  out.iterations = state.iterations;
  out.angle_sigma = 1.0 / weights.angle;
  out.spool_sigma = out.has_spool ? 1.0 / weights.spool : 0.0;
  const std::array<double, kNumParams> sigma =
      StandardDeviations(all, kinematics, state, weights, options);
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
    std::vector<const PreparedFile*> train, test;
    std::vector<std::size_t> train_index, test_index;
    for (std::size_t f = 0; f < prepared.size(); ++f) {
      const bool out_of_fold = std::find(held_out.begin(), held_out.end(), f) != held_out.end();
      (out_of_fold ? test : train).push_back(&prepared[f]);
      (out_of_fold ? test_index : train_index).push_back(f);
    }
    FitState fold = state;  // started from the full fit: the same optimum, fewer iterations
    Fit(train, kinematics, fold, train_index, options, false);
    Fit(test, kinematics, fold, test_index, options, true);  // offsets only
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
