// Direct collocation of the optimal scoop with Ipopt (scoop_ocp.h).
#include "runtime/optimal/scoop_ocp.h"

#include <ceres/jet.h>

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <type_traits>

namespace autoshovel::optimal {

namespace {

constexpr int kBlock = 2 * kNodeVariables + 1;  // a trapezoid: two nodes and T₂
using NodeJet = ceres::Jet<double, kNodeVariables>;
using BlockJet = ceres::Jet<double, kBlock>;

const char* StatusText(Ipopt::ApplicationReturnStatus status) {
  switch (status) {
    case Ipopt::Solve_Succeeded:
      return "solved";
    case Ipopt::Solved_To_Acceptable_Level:
      return "solved to the acceptable level";
    case Ipopt::Infeasible_Problem_Detected:
      return "infeasible (no scoop meets the bounds)";
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return "search direction too small";
    case Ipopt::Diverging_Iterates:
      return "diverging iterates";
    case Ipopt::User_Requested_Stop:
      return "stopped";
    case Ipopt::Feasible_Point_Found:
      return "feasible point found";
    case Ipopt::Maximum_Iterations_Exceeded:
      return "maximum iterations exceeded";
    case Ipopt::Restoration_Failed:
      return "restoration failed";
    case Ipopt::Error_In_Step_Computation:
      return "error in step computation";
    case Ipopt::Maximum_CpuTime_Exceeded:
      return "maximum CPU time exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
      return "not enough degrees of freedom";
    case Ipopt::Invalid_Problem_Definition:
      return "invalid problem definition";
    case Ipopt::Invalid_Option:
      return "invalid option";
    case Ipopt::Invalid_Number_Detected:
      return "invalid number (NaN or Inf) in the model";
    default:
      return "internal error";
  }
}

}  // namespace

namespace {

// Linear between the nodes, held at the ends.
template <std::size_t N>
std::array<double, N> Interpolate(const std::vector<double>& time,
                                  const std::vector<std::array<double, N>>& values, double t) {
  if (time.empty()) return {};
  if (t <= time.front()) return values.front();
  if (t >= time.back()) return values.back();
  const auto it = std::upper_bound(time.begin(), time.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - time.begin()) - 1;
  const double w = (t - time[k]) / std::max(time[k + 1] - time[k], 1e-12);
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = (1 - w) * values[k][i] + w * values[k + 1][i];
  return out;
}

}  // namespace

std::array<double, kStates> ScoopOcpSolution::StateAt(double t) const {
  return Interpolate(time_at, state, t);
}

std::array<double, kControls> ScoopOcpSolution::ControlAt(double t) const {
  return Interpolate(time_at, control, t);
}

struct ScoopOcp::WarmStart {
  std::vector<double> z, z_lower, z_upper, lambda;
};

// The NLP in scaled variables z (physical value = scale · z).
class ScoopOcp::Nlp : public Ipopt::TNLP {
 public:
  Nlp(const ScoopModel& model, const ScoopOcpOptions& options, const ScoopStart& start,
      double dead_time, const WarmStart* warm)
      : model_(model), o_(options), start_(start), dead_time_(dead_time), warm_(warm) {
    nodes_ = o_.delay_intervals + o_.intervals + 1;
    n_ = nodes_ * kNodeVariables + 1;
    defects_ = (nodes_ - 1) * kStates;
    m_ = defects_ + nodes_ * kNumPath + 1;
    state_scale_ = {1, 1, 1, 1, 1, 1, 1, 1e5};
    control_scale_[0] = 1e5;
    control_scale_[1] = control_scale_[2] = 1.0;
    path_scale_.fill(1.0);
    path_scale_[kTractionForward] = path_scale_[kTractionBackward] = 1e5;
    path_scale_[kDrivePower] = 1e5;
    for (int a = 0; a < kActuators; ++a) {
      path_scale_[kFlowExtend + a] = path_scale_[kFlowRetract + a] = 1e-3;
    }
    path_scale_[kPumpFlow] = 1e-3;
    for (int a = 0; a < kActuators; ++a) {
      path_scale_[kForceBelowMax + a] = path_scale_[kForceAboveMin + a] =
          std::max(std::abs(model_.force_min(a)), model_.force_max(a));
    }
  }

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g,
                    Ipopt::Index& nnz_h_lag, IndexStyleEnum& index_style) override {
    n = n_;
    m = m_;
    nnz_jac_g = defects_ * kBlock + nodes_ * kNumPath * kNodeVariables + kNodeVariables;
    nnz_h_lag = HessianEntries();
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* z_l, Ipopt::Number* z_u, Ipopt::Index m,
                       Ipopt::Number* g_l, Ipopt::Number* g_u) override {
    const double inf = 2e19;
    const double rack = std::isnan(o_.rack_angle) ? model_.joint_max(1) - 0.1 : o_.rack_angle;
    for (int k = 0; k < nodes_; ++k) {
      double lo[kNodeVariables], hi[kNodeVariables];
      lo[kS] = -0.5, hi[kS] = 15;
      lo[kV] = 0, hi[kV] = o_.max_speed;
      for (int j = 0; j < kJoints; ++j) {
        lo[kQ + j] = model_.joint_min(j), hi[kQ + j] = model_.joint_max(j);
        lo[kQd + j] = -2, hi[kQd + j] = 2;
      }
      lo[kVolume] = 0, hi[kVolume] = 1.5 * model_.heaped_capacity();
      lo[kEnergy] = 0, hi[kEnergy] = 1e7;
      lo[kStates] = -model_.max_traction_force(), hi[kStates] = model_.max_traction_force();
      for (int j = 0; j < kJoints; ++j) {
        lo[kStates + 1 + j] = -o_.max_joint_acceleration;
        hi[kStates + 1 + j] = o_.max_joint_acceleration;
      }
      if (k == 0) {
        lo[kS] = hi[kS] = 0;
        lo[kV] = hi[kV] = start_.speed;
        lo[kVolume] = hi[kVolume] = start_.volume;
        lo[kEnergy] = hi[kEnergy] = 0;
      }
      if (k <= o_.delay_intervals) {  // the arm held through the dead time
        for (int j = 0; j < kJoints; ++j) {
          lo[kQ + j] = hi[kQ + j] = start_.q[j];
          lo[kQd + j] = hi[kQd + j] = 0;
        }
      }
      if (k == nodes_ - 1) {
        lo[kV] = hi[kV] = 0;
        for (int j = 0; j < kJoints; ++j) lo[kQd + j] = hi[kQd + j] = 0;
        lo[kVolume] = std::max(lo[kVolume], o_.target_volume);
        lo[kQ + 1] = std::max(lo[kQ + 1], std::min(rack, model_.joint_max(1)));
        if (o_.objective == ScoopObjective::kMinimumTime && std::isfinite(o_.max_energy)) {
          hi[kEnergy] = o_.max_energy;
        }
      }
      for (int i = 0; i < kNodeVariables; ++i) {
        const double scale = Scale(i);
        z_l[k * kNodeVariables + i] = lo[i] / scale;
        z_u[k * kNodeVariables + i] = hi[i] / scale;
      }
    }
    z_l[n - 1] = std::max(o_.min_time - dead_time_, 0.2);
    z_u[n - 1] = std::max(o_.max_time - dead_time_, z_l[n - 1]);
    for (int r = 0; r < defects_; ++r) g_l[r] = g_u[r] = 0;
    for (int r = defects_; r < m; ++r) g_l[r] = 0, g_u[r] = inf;
    return true;
  }

  bool get_starting_point(Ipopt::Index n, bool init_z, Ipopt::Number* z, bool init_bounds,
                          Ipopt::Number* z_lower, Ipopt::Number* z_upper, Ipopt::Index m,
                          bool init_lambda, Ipopt::Number* lambda) override {
    if (warm_ != nullptr && static_cast<int>(warm_->z.size()) == n) {
      if (init_z) std::copy(warm_->z.begin(), warm_->z.end(), z);
      if (init_bounds) {
        std::copy(warm_->z_lower.begin(), warm_->z_lower.end(), z_lower);
        std::copy(warm_->z_upper.begin(), warm_->z_upper.end(), z_upper);
      }
      if (init_lambda) std::copy(warm_->lambda.begin(), warm_->lambda.end(), lambda);
      // The start is fixed by bounds: move the guess's first nodes onto it.
      if (init_z) PinStart(z);
      return true;
    }
    if (init_bounds || init_lambda) return false;  // cold: Ipopt's own multiplier guesses
    if (init_z) ColdGuess(z);
    (void)m;
    return true;
  }

  bool eval_f(Ipopt::Index n, const Ipopt::Number* z, bool, Ipopt::Number& f) override {
    const int last = (nodes_ - 1) * kNodeVariables;
    f = o_.objective == ScoopObjective::kMinimumEnergy ? z[last + kEnergy] : z[n - 1];
    for (int k = 0; k + 1 < nodes_; ++k) {
      for (int c = 0; c < kControls; ++c) {
        const double d =
            z[(k + 1) * kNodeVariables + kStates + c] - z[k * kNodeVariables + kStates + c];
        f += o_.control_smoothing * d * d;
      }
    }
    return true;
  }

  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* z, bool, Ipopt::Number* grad) override {
    std::fill(grad, grad + n, 0.0);
    const int last = (nodes_ - 1) * kNodeVariables;
    if (o_.objective == ScoopObjective::kMinimumEnergy) {
      grad[last + kEnergy] = 1;
    } else {
      grad[n - 1] = 1;
    }
    for (int k = 0; k + 1 < nodes_; ++k) {
      for (int c = 0; c < kControls; ++c) {
        const int a = k * kNodeVariables + kStates + c, b = a + kNodeVariables;
        const double d = z[b] - z[a];
        grad[b] += 2 * o_.control_smoothing * d;
        grad[a] -= 2 * o_.control_smoothing * d;
      }
    }
    return true;
  }

  bool eval_g(Ipopt::Index, const Ipopt::Number* z, bool, Ipopt::Index, Ipopt::Number* g) override {
    std::vector<std::array<double, kStates>> rates(nodes_);
    for (int k = 0; k < nodes_; ++k) {
      double node[kNodeVariables], path[kNumPath];
      Physical(z, k, node);
      model_.Evaluate(node, node + kStates, rates[k].data(), path);
      if (!AllFinite(rates[k].data(), kStates) || !AllFinite(path, kNumPath)) return false;
      for (int p = 0; p < kNumPath; ++p) g[defects_ + k * kNumPath + p] = path[p] / path_scale_[p];
    }
    for (int k = 0; k + 1 < nodes_; ++k) {
      const double h = Step(k, z[n_ - 1]);
      for (int i = 0; i < kStates; ++i) {
        const double a = z[k * kNodeVariables + i] * state_scale_[i];
        const double b = z[(k + 1) * kNodeVariables + i] * state_scale_[i];
        g[k * kStates + i] = (b - a - 0.5 * h * (rates[k][i] + rates[k + 1][i])) / state_scale_[i];
      }
    }
    g[m_ - 1] = ExitClearance<double>(z, nullptr);
    return std::isfinite(g[m_ - 1]);
  }

  bool eval_jac_g(Ipopt::Index, const Ipopt::Number* z, bool, Ipopt::Index, Ipopt::Index,
                  Ipopt::Index* i_row, Ipopt::Index* j_col, Ipopt::Number* values) override {
    int e = 0;
    if (values == nullptr) {
      for (int k = 0; k + 1 < nodes_; ++k) {
        for (int i = 0; i < kStates; ++i) {
          for (int c = 0; c < kBlock; ++c) {
            i_row[e] = k * kStates + i;
            j_col[e] = c < 2 * kNodeVariables ? k * kNodeVariables + c : n_ - 1;
            ++e;
          }
        }
      }
      for (int k = 0; k < nodes_; ++k) {
        for (int p = 0; p < kNumPath; ++p) {
          for (int c = 0; c < kNodeVariables; ++c) {
            i_row[e] = defects_ + k * kNumPath + p;
            j_col[e] = k * kNodeVariables + c;
            ++e;
          }
        }
      }
      for (int c = 0; c < kNodeVariables; ++c) {
        i_row[e] = m_ - 1;
        j_col[e] = (nodes_ - 1) * kNodeVariables + c;
        ++e;
      }
      return true;
    }
    // Trapezoids: both nodes and T₂ as Jet variables.
    for (int k = 0; k + 1 < nodes_; ++k) {
      double w[kBlock];
      for (int c = 0; c < kBlock; ++c) w[c] = z[BlockIndex(k, c)];
      BlockJet defects[kStates];
      BlockDefects(k, w, defects);
      for (int i = 0; i < kStates; ++i) {
        for (int c = 0; c < kBlock; ++c) values[e++] = defects[i].v[c];
      }
    }
    for (int k = 0; k < nodes_; ++k) {
      NodeJet node[kNodeVariables];
      for (int i = 0; i < kNodeVariables; ++i) {
        node[i] = NodeJet(z[k * kNodeVariables + i] * Scale(i), i);
        node[i].v *= Scale(i);
      }
      NodeJet rate[kStates], path[kNumPath];
      model_.Evaluate(node, node + kStates, rate, path);
      for (int p = 0; p < kNumPath; ++p) {
        for (int c = 0; c < kNodeVariables; ++c) values[e++] = path[p].v[c] / path_scale_[p];
      }
    }
    NodeJet exit_jacobian;
    ExitClearance<NodeJet>(z, &exit_jacobian);
    for (int c = 0; c < kNodeVariables; ++c) values[e++] = exit_jacobian.v[c];
    for (int i = 0; i < e; ++i) {
      if (!std::isfinite(values[i])) return false;
    }
    return true;
  }

  // The Lagrangian's Hessian, block by block: each trapezoid over its two nodes and T₂, each
  // node's path constraints, the exit constraint. Every block is the central difference of the
  // block's exact (Jet) gradient of Σ λ g: second derivatives through nested Jets would need
  // Jet-by-double arithmetic that ceres::Jet does not define for a Jet scalar. Symmetrised,
  // lower triangle; the objective's control smoothing enters exactly.
  bool eval_h(Ipopt::Index, const Ipopt::Number* z, bool, Ipopt::Number obj_factor, Ipopt::Index,
              const Ipopt::Number* lambda, bool, Ipopt::Index, Ipopt::Index* i_row,
              Ipopt::Index* j_col, Ipopt::Number* values) override {
    int e = 0;
    if (values == nullptr) {
      for (int k = 0; k + 1 < nodes_; ++k) {
        for (int r = 0; r < kBlock; ++r) {
          for (int c = 0; c <= r; ++c) {
            i_row[e] = BlockIndex(k, r), j_col[e] = BlockIndex(k, c);
            ++e;
          }
        }
      }
      for (int k = 0; k < nodes_; ++k) {
        for (int r = 0; r < kNodeVariables; ++r) {
          for (int c = 0; c <= r; ++c) {
            i_row[e] = k * kNodeVariables + r, j_col[e] = k * kNodeVariables + c;
            ++e;
          }
        }
      }
      for (int r = 0; r < kNodeVariables; ++r) {
        for (int c = 0; c <= r; ++c) {
          i_row[e] = (nodes_ - 1) * kNodeVariables + r,
          j_col[e] = (nodes_ - 1) * kNodeVariables + c;
          ++e;
        }
      }
      return true;
    }
    std::vector<double> w(kBlock), grad_plus(kBlock), grad_minus(kBlock);
    std::vector<double> hessian(kBlock * kBlock);
    for (int k = 0; k + 1 < nodes_; ++k) {
      for (int c = 0; c < kBlock; ++c) w[c] = z[BlockIndex(k, c)];
      const double* weights = lambda + k * kStates;
      for (int c = 0; c < kBlock; ++c) {
        const double step = 1e-6 * std::max(1.0, std::abs(w[c]));
        const double saved = w[c];
        w[c] = saved + step;
        BlockGradient(k, w.data(), weights, grad_plus.data());
        w[c] = saved - step;
        BlockGradient(k, w.data(), weights, grad_minus.data());
        w[c] = saved;
        for (int r = 0; r < kBlock; ++r) {
          hessian[r * kBlock + c] = (grad_plus[r] - grad_minus[r]) / (2 * step);
        }
      }
      for (int r = 0; r < kBlock; ++r) {
        for (int c = 0; c <= r; ++c) {
          double h = 0.5 * (hessian[r * kBlock + c] + hessian[c * kBlock + r]);
          // The objective's control smoothing, ρ Σ (u_{k+1} − u_k)², exactly.
          const bool control_r = r % kNodeVariables >= kStates && r < 2 * kNodeVariables;
          const bool control_c = c % kNodeVariables >= kStates && c < 2 * kNodeVariables;
          if (control_r && control_c && r % kNodeVariables == c % kNodeVariables) {
            h += obj_factor * 2 * o_.control_smoothing * (r == c ? 1.0 : -1.0);
          }
          values[e++] = h;
        }
      }
    }
    std::vector<double> node(kNodeVariables), node_plus(kNodeVariables), node_minus(kNodeVariables),
        node_hessian(kNodeVariables * kNodeVariables);
    auto node_block = [&](int k, auto gradient) {
      for (int c = 0; c < kNodeVariables; ++c) node[c] = z[k * kNodeVariables + c];
      for (int c = 0; c < kNodeVariables; ++c) {
        const double step = 1e-6 * std::max(1.0, std::abs(node[c]));
        const double saved = node[c];
        node[c] = saved + step;
        gradient(node.data(), node_plus.data());
        node[c] = saved - step;
        gradient(node.data(), node_minus.data());
        node[c] = saved;
        for (int r = 0; r < kNodeVariables; ++r) {
          node_hessian[r * kNodeVariables + c] = (node_plus[r] - node_minus[r]) / (2 * step);
        }
      }
      for (int r = 0; r < kNodeVariables; ++r) {
        for (int c = 0; c <= r; ++c) {
          values[e++] =
              0.5 * (node_hessian[r * kNodeVariables + c] + node_hessian[c * kNodeVariables + r]);
        }
      }
    };
    for (int k = 0; k < nodes_; ++k) {
      const double* weights = lambda + defects_ + k * kNumPath;
      node_block(k, [&](const double* v, double* g) { PathGradient(v, weights, g); });
    }
    const double exit_weight = lambda[m_ - 1];
    node_block(nodes_ - 1, [&](const double* v, double* g) { ExitGradient(v, exit_weight, g); });
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index n, const Ipopt::Number* z,
                         const Ipopt::Number* z_lower, const Ipopt::Number* z_upper, Ipopt::Index m,
                         const Ipopt::Number*, const Ipopt::Number* lambda, Ipopt::Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    result_z.assign(z, z + n);
    result_z_lower.assign(z_lower, z_lower + n);
    result_z_upper.assign(z_upper, z_upper + n);
    result_lambda.assign(lambda, lambda + m);
  }

  /// ‖∇f + Jᵀλ − z_L + z_U‖∞ at the stored result.
  double Stationarity() {
    if (result_z.empty()) return NAN;
    std::vector<double> grad(n_), values(NonZeros());
    std::vector<Ipopt::Index> rows(NonZeros()), cols(NonZeros());
    eval_grad_f(n_, result_z.data(), true, grad.data());
    eval_jac_g(n_, result_z.data(), true, m_, NonZeros(), rows.data(), cols.data(), nullptr);
    eval_jac_g(n_, result_z.data(), true, m_, NonZeros(), nullptr, nullptr, values.data());
    for (std::size_t e = 0; e < values.size(); ++e) {
      grad[cols[e]] += values[e] * result_lambda[rows[e]];
    }
    // Fixed variables (equal bounds: the start, the held arm, the end's rest) are parameters
    // to Ipopt (fixed_variable_treatment make_parameter): no multiplier, no condition.
    std::vector<double> lo(n_), hi(n_), g_lo(m_), g_hi(m_);
    get_bounds_info(n_, lo.data(), hi.data(), m_, g_lo.data(), g_hi.data());
    double worst = 0;
    for (int i = 0; i < n_; ++i) {
      if (lo[i] == hi[i]) continue;
      const double r = std::abs(grad[i] - result_z_lower[i] + result_z_upper[i]);
      worst = std::max(worst, r);
    }
    return worst;
  }

  /// The most violated constraint at the stored result, in words, and its scaled violation.
  std::string WorstConstraint(double* violation) {
    std::vector<double> g(m_), lo(m_), hi(m_), zl(n_), zu(n_);
    get_bounds_info(n_, zl.data(), zu.data(), m_, lo.data(), hi.data());
    eval_g(n_, result_z.data(), true, m_, g.data());
    int worst = -1;
    *violation = 0;
    for (int r = 0; r < m_; ++r) {
      const double v = std::max(lo[r] - g[r], g[r] - hi[r]);
      if (v > *violation) *violation = v, worst = r;
    }
    if (worst < 0) return "none";
    static const char* kStateNames[] = {"s",       "v",         "q_boom", "q_bucket",
                                        "qd_boom", "qd_bucket", "volume", "energy"};
    if (worst < defects_) {
      return std::string("defect of ") + kStateNames[worst % kStates] + " in interval " +
             std::to_string(worst / kStates);
    }
    if (worst < m_ - 1) {
      const int r = worst - defects_;
      return "path constraint " + std::to_string(r % kNumPath) + " at node " +
             std::to_string(r / kNumPath);
    }
    return "edge out of the pile at the end";
  }

  /// The solution in physical units.
  void Fill(ScoopOcpSolution& out) const {
    const std::vector<double>& z = result_z;
    double t = 0;
    for (int k = 0; k < nodes_; ++k) {
      double node[kNodeVariables];
      Physical(z.data(), k, node);
      out.time_at.push_back(t);
      std::array<double, kStates> x{};
      std::array<double, kControls> u{};
      std::copy(node, node + kStates, x.begin());
      std::copy(node + kStates, node + kNodeVariables, u.begin());
      out.state.push_back(x);
      out.control.push_back(u);
      if (k + 1 < nodes_) t += Step(k, z[n_ - 1]);
    }
    out.time = t;
    out.energy = out.state.back()[kEnergy];
    out.volume = out.state.back()[kVolume];
  }

  std::vector<double> result_z, result_z_lower, result_z_upper, result_lambda;

 private:
  int HessianEntries() const {
    return (nodes_ - 1) * kBlock * (kBlock + 1) / 2 +
           (nodes_ + 1) * kNodeVariables * (kNodeVariables + 1) / 2;
  }
  // Global index of a trapezoid's local variable c: its two nodes, then T₂.
  int BlockIndex(int k, int c) const {
    return c < 2 * kNodeVariables ? k * kNodeVariables + c : n_ - 1;
  }
  // A trapezoid's scaled defects as Jets over its scaled variables w (two nodes, then T₂).
  void BlockDefects(int k, const double* w, BlockJet* defects) const {
    BlockJet a[kNodeVariables], b[kNodeVariables];
    for (int i = 0; i < kNodeVariables; ++i) {
      a[i] = BlockJet(w[i] * Scale(i), i);
      a[i].v *= Scale(i);
      b[i] = BlockJet(w[kNodeVariables + i] * Scale(i), kNodeVariables + i);
      b[i].v *= Scale(i);
    }
    const BlockJet duration(w[kBlock - 1], kBlock - 1);
    BlockJet fa[kStates], fb[kStates], path[kNumPath];
    model_.Evaluate(a, a + kStates, fa, path);
    model_.Evaluate(b, b + kStates, fb, path);
    const BlockJet h = k < o_.delay_intervals ? BlockJet(dead_time_ / o_.delay_intervals)
                                              : duration / double(o_.intervals);
    for (int i = 0; i < kStates; ++i) {
      defects[i] = (b[i] - a[i] - 0.5 * h * (fa[i] + fb[i])) / state_scale_[i];
    }
  }
  // ∇ Σ_i λ_i defect_i over a trapezoid's scaled variables w (exact, by Jet).
  void BlockGradient(int k, const double* w, const double* weights, double* gradient) const {
    BlockJet defects[kStates];
    BlockDefects(k, w, defects);
    BlockJet sum(0.0);
    for (int i = 0; i < kStates; ++i) sum += weights[i] * defects[i];
    for (int c = 0; c < kBlock; ++c) gradient[c] = sum.v[c];
  }
  // ∇ Σ_p λ_p path_p / scale_p over a node's scaled variables.
  void PathGradient(const double* v, const double* weights, double* gradient) const {
    NodeJet node[kNodeVariables];
    for (int i = 0; i < kNodeVariables; ++i) {
      node[i] = NodeJet(v[i] * Scale(i), i);
      node[i].v *= Scale(i);
    }
    NodeJet rate[kStates], path[kNumPath];
    model_.Evaluate(node, node + kStates, rate, path);
    NodeJet sum(0.0);
    for (int p = 0; p < kNumPath; ++p) sum += weights[p] * path[p] / path_scale_[p];
    for (int c = 0; c < kNodeVariables; ++c) gradient[c] = sum.v[c];
  }
  // λ ∇(exit clearance) over the last node's scaled variables.
  void ExitGradient(const double* v, double weight, double* gradient) const {
    NodeJet node[kNodeVariables];
    for (int i = 0; i < kNodeVariables; ++i) {
      node[i] = NodeJet(v[i] * Scale(i), i);
      node[i].v *= Scale(i);
    }
    NodeJet tip_x, tip_z, angle;
    model_.Tip(node + kQ, node[kS], &tip_x, &tip_z, &angle);
    const NodeJet clearance = -model_.DepthBelowSurface(tip_x, tip_z);
    for (int c = 0; c < kNodeVariables; ++c) gradient[c] = weight * clearance.v[c];
  }
  int NonZeros() const {
    return defects_ * kBlock + nodes_ * kNumPath * kNodeVariables + kNodeVariables;
  }
  double Scale(int i) const { return i < kStates ? state_scale_[i] : control_scale_[i - kStates]; }
  void Physical(const double* z, int k, double* node) const {
    for (int i = 0; i < kNodeVariables; ++i) node[i] = z[k * kNodeVariables + i] * Scale(i);
  }
  double Step(int k, double duration) const {
    return k < o_.delay_intervals ? dead_time_ / o_.delay_intervals : duration / o_.intervals;
  }
  static bool AllFinite(const double* v, int n) {
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(v[i])) return false;
    }
    return true;
  }

  // −depth − clearance at the last node: the edge above the surface (≥ 0).
  template <typename T>
  double ExitClearance(const double* z, T* jacobian) const {
    const int base = (nodes_ - 1) * kNodeVariables;
    T node[kNodeVariables];
    for (int i = 0; i < kNodeVariables; ++i) {
      if constexpr (std::is_same_v<T, double>) {
        node[i] = z[base + i] * Scale(i);
      } else {
        node[i] = T(z[base + i] * Scale(i), i);
        node[i].v *= Scale(i);
      }
    }
    T tip_x, tip_z, angle;
    model_.Tip(node + kQ, node[kS], &tip_x, &tip_z, &angle);
    const T clearance = -model_.DepthBelowSurface(tip_x, tip_z) - o_.exit_clearance;
    if constexpr (std::is_same_v<T, double>) {
      return clearance;
    } else {
      *jacobian = clearance;
      return clearance.a;
    }
  }

  void PinStart(double* z) const {
    const double fixed[] = {0, start_.speed, start_.q[0], start_.q[1], 0, 0, start_.volume, 0};
    for (int k = 0; k <= o_.delay_intervals; ++k) {
      for (int i : std::array<int, 4>{kQ, kQ + 1, kQd, kQd + 1})
        z[k * kNodeVariables + i] = fixed[i] / Scale(i);
    }
    for (int i = 0; i < kStates; ++i) z[i] = fixed[i] / Scale(i);
  }

  // A cold start: the machine slowing evenly to rest, the arm moving evenly from the attack pose
  // to a racked, lifted end after the dead time, the volume growing to the target.
  void ColdGuess(double* z) const {
    const double duration = std::clamp(3.0, std::max(o_.min_time - dead_time_, 0.2),
                                       std::max(o_.max_time - dead_time_, 0.2));
    const double total = dead_time_ + duration;
    const double rack = std::isnan(o_.rack_angle) ? model_.joint_max(1) - 0.1 : o_.rack_angle;
    const double boom_end = std::min(start_.q[0] + 0.3, model_.joint_max(0) - 0.05);
    const double bucket_end = std::min(rack + 0.02, model_.joint_max(1) - 0.01);
    double t = 0, s = 0;
    for (int k = 0; k < nodes_; ++k) {
      const double v = start_.speed * (1 - t / total);
      const double w = k <= o_.delay_intervals ? 0.0 : (t - dead_time_) / duration;
      double node[kNodeVariables] = {};
      node[kS] = s;
      node[kV] = k == nodes_ - 1 ? 0.0 : v;
      node[kQ] = start_.q[0] + w * (boom_end - start_.q[0]);
      node[kQ + 1] = start_.q[1] + w * (bucket_end - start_.q[1]);
      const bool moving = k > o_.delay_intervals && k < nodes_ - 1;
      node[kQd] = moving ? (boom_end - start_.q[0]) / duration : 0.0;
      node[kQd + 1] = moving ? (bucket_end - start_.q[1]) / duration : 0.0;
      node[kVolume] = start_.volume + (t / total) * std::max(o_.target_volume - start_.volume, 0.0);
      node[kEnergy] = 2e5 * t / total;
      for (int i = 0; i < kNodeVariables; ++i) z[k * kNodeVariables + i] = node[i] / Scale(i);
      if (k + 1 < nodes_) {
        const double h = Step(k, duration);
        s += h * v;
        t += h;
      }
    }
    z[n_ - 1] = duration;
  }

  const ScoopModel& model_;
  ScoopOcpOptions o_;
  ScoopStart start_;
  double dead_time_;
  const WarmStart* warm_;
  int nodes_ = 0, n_ = 0, m_ = 0, defects_ = 0;
  std::array<double, kStates> state_scale_{};
  std::array<double, kControls> control_scale_{};
  std::array<double, kNumPath> path_scale_{};
};

ScoopOcp::ScoopOcp(const ScoopModel& model, const ScoopOcpOptions& options)
    : model_(&model), options_(options) {
  if (options.delay_intervals < 1 || options.intervals < 4) {
    throw std::invalid_argument("optimal scoop: need >= 1 delay and >= 4 scoop intervals");
  }
  if (!(options.max_time > options.min_time) || !(options.min_time > 0)) {
    throw std::invalid_argument("optimal scoop: need 0 < min_time < max_time");
  }
}

ScoopOcp::~ScoopOcp() = default;

double ScoopOcp::dead_time() const {
  return std::max(model_->valve_delay(0), model_->valve_delay(1));
}

ScoopOcpSolution ScoopOcp::Solve(const ScoopStart& start) {
  ScoopOcpSolution out;
  const bool warm = options_.warm_start && warm_ != nullptr;
  Ipopt::SmartPtr<Nlp> nlp =
      new Nlp(*model_, options_, start, dead_time(), warm ? warm_.get() : nullptr);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetIntegerValue("print_level", options_.print_level);
  app->Options()->SetStringValue("hessian_approximation",
                                 options_.exact_hessian ? "exact" : "limited-memory");
  app->Options()->SetNumericValue("tol", options_.tolerance);
  app->Options()->SetNumericValue("acceptable_tol", 1e-4);
  app->Options()->SetIntegerValue("max_iter", options_.max_iterations);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  app->Options()->SetStringValue("derivative_test", options_.derivative_test);
  app->Options()->SetNumericValue("derivative_test_tol", 1e-3);
  if (warm) {
    app->Options()->SetStringValue("warm_start_init_point", "yes");
    app->Options()->SetNumericValue("warm_start_bound_push", 1e-6);
    app->Options()->SetNumericValue("warm_start_mult_bound_push", 1e-6);
    app->Options()->SetNumericValue("mu_init", 1e-5);
  }
  out.warm_started = warm;
  if (app->Initialize() != Ipopt::Solve_Succeeded) {
    out.status = "Ipopt did not initialise";
    return out;
  }
  const auto begin = std::chrono::steady_clock::now();
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(nlp);
  out.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  out.status = StatusText(status);
  out.ok = status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
  if (Ipopt::SmartPtr<Ipopt::SolveStatistics> stats = app->Statistics(); Ipopt::IsValid(stats)) {
    out.iterations = stats->IterationCount();
    stats->Infeasibilities(out.dual_infeasibility, out.constraint_violation, out.complementarity,
                           out.kkt_error);
  }
  if (nlp->result_z.empty()) return out;
  nlp->Fill(out);
  out.stationarity = nlp->Stationarity();
  out.worst_constraint = nlp->WorstConstraint(&out.worst_violation);
  if (out.ok) {
    if (!warm_) warm_ = std::make_unique<WarmStart>();
    warm_->z = nlp->result_z;
    warm_->z_lower = nlp->result_z_lower;
    warm_->z_upper = nlp->result_z_upper;
    warm_->lambda = nlp->result_lambda;
  }
  return out;
}

}  // namespace autoshovel::optimal
