#include "identification/calibration/arm_calibration.h"

#include <ceres/ceres.h>

#include <Eigen/SVD>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace autoshovel::identification {

namespace {

// Eq. (3) for one pair of poses, with the analytic Jacobian of the generated kinematics.
class TipDisplacementCost : public ceres::CostFunction {
 public:
  TipDisplacementCost(const generated::MachineFunctions& machine, std::vector<double> angles_i,
                      std::vector<double> angles_j, const Eigen::Vector2d& measured)
      : machine_(machine),
        angles_i_(std::move(angles_i)),
        angles_j_(std::move(angles_j)),
        measured_(measured) {
    set_num_residuals(2);
    mutable_parameter_block_sizes()->push_back(machine.num_params);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int p = machine_.num_params, a = machine_.num_angles;
    double pose_i[4], pose_j[4];
    std::vector<double> d_angles(4 * a), d_params_i(4 * p), d_params_j(4 * p);
    machine_.forward_kinematics_jacobians(angles_i_.data(), parameters[0], pose_i, d_angles.data(),
                                          d_params_i.data());
    machine_.forward_kinematics_jacobians(angles_j_.data(), parameters[0], pose_j, d_angles.data(),
                                          d_params_j.data());
    // Pose rows: x, y, z, φ (row-major, 4 × p). The arm plane's x and z are rows 0 and 2.
    residuals[0] = measured_.x() - (pose_i[0] - pose_j[0]);
    residuals[1] = measured_.y() - (pose_i[2] - pose_j[2]);
    if (!std::isfinite(residuals[0]) || !std::isfinite(residuals[1])) return false;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      for (int k = 0; k < p; ++k) {
        jacobians[0][k] = -(d_params_i[0 * p + k] - d_params_j[0 * p + k]);
        jacobians[0][p + k] = -(d_params_i[2 * p + k] - d_params_j[2 * p + k]);
      }
    }
    return true;
  }

 private:
  const generated::MachineFunctions& machine_;
  std::vector<double> angles_i_, angles_j_;
  Eigen::Vector2d measured_;
};

// The same residual over Cartesian parameters c = [a_1 … a_n, b_1 … b_n] with
// (a_k, b_k) = l_k (cos α_k, sin α_k): Eq. (2) is linear in them, so this stage converges from
// any start (there is one minimum and no bound to stick to). Chain rule through
// l = |(a, b)|, α = atan2(b, a).
class CartesianCost : public ceres::CostFunction {
 public:
  CartesianCost(const TipDisplacementCost* polar, int num_links) : polar_(polar), n_(num_links) {
    set_num_residuals(2);
    mutable_parameter_block_sizes()->push_back(2 * num_links);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* c = parameters[0];
    std::vector<double> polar(2 * n_), jacobian_polar(2 * 2 * n_);
    for (int k = 0; k < n_; ++k) {
      polar[k] = std::hypot(c[k], c[n_ + k]);
      polar[n_ + k] = std::atan2(c[n_ + k], c[k]);
      if (!(polar[k] > 0)) return false;
    }
    const double* p[1] = {polar.data()};
    double* jp[1] = {jacobian_polar.data()};
    if (!polar_->Evaluate(p, residuals, jacobians ? jp : nullptr)) return false;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      const int m = 2 * n_;
      for (int r = 0; r < 2; ++r) {
        for (int k = 0; k < n_; ++k) {
          const double l = polar[k], ca = std::cos(polar[n_ + k]), sa = std::sin(polar[n_ + k]);
          const double dl = jacobian_polar[r * m + k], da = jacobian_polar[r * m + n_ + k];
          jacobians[0][r * m + k] = dl * ca - da * sa / l;       // ∂r/∂a_k
          jacobians[0][r * m + n_ + k] = dl * sa + da * ca / l;  // ∂r/∂b_k
        }
      }
    }
    return true;
  }

 private:
  const TipDisplacementCost* polar_;
  int n_;
};

}  // namespace

ArmCalibrationResult CalibrateArm(const generated::MachineFunctions& machine,
                                  const ArmCalibrationData& data, std::vector<double> initial) {
  const int p = machine.num_params, n = machine.num_links;
  ArmCalibrationResult result;
  if (initial.empty()) initial.assign(machine.nominal_params, machine.nominal_params + p);
  if (static_cast<int>(initial.size()) != p) {
    throw std::invalid_argument("CalibrateArm: " + std::to_string(p) +
                                " initial parameters expected, got " +
                                std::to_string(initial.size()));
  }
  for (int k = 0; k < n; ++k) {
    if (!(initial[k] > 0) || !(std::abs(initial[n + k]) < std::numbers::pi)) {
      throw std::invalid_argument(
          "CalibrateArm: initial values must satisfy l > 0 and -pi < alpha < pi");
    }
  }
  result.initial = initial;
  if (data.angles.size() < 3) {
    result.degenerate = "only " + std::to_string(data.angles.size()) +
                        " poses: at least 3 are needed (2 displacements, 4 residuals)";
    return result;
  }
  if (data.displacements.size() + 1 != data.angles.size()) {
    throw std::invalid_argument("CalibrateArm: " + std::to_string(data.angles.size()) +
                                " poses need " + std::to_string(data.angles.size() - 1) +
                                " displacements, got " + std::to_string(data.displacements.size()));
  }
  for (const auto& angles : data.angles) {
    if (static_cast<int>(angles.size()) != machine.num_angles) {
      throw std::invalid_argument("CalibrateArm: a pose has " + std::to_string(angles.size()) +
                                  " angles, machine '" + machine.name + "' needs " +
                                  std::to_string(machine.num_angles));
    }
    for (double v : angles) {
      if (!std::isfinite(v)) throw std::invalid_argument("CalibrateArm: non-finite angle");
    }
  }
  for (const auto& d : data.displacements) {
    if (!d.allFinite()) throw std::invalid_argument("CalibrateArm: non-finite displacement");
  }

  // Residuals at the start, to show what the calibration changed.
  for (std::size_t i = 0; i + 1 < data.angles.size(); ++i) {
    const TipDisplacementCost cost(machine, data.angles[i], data.angles[i + 1],
                                   data.displacements[i]);
    const double* blocks[] = {initial.data()};
    Eigen::Vector2d r(NAN, NAN);
    cost.Evaluate(blocks, r.data(), nullptr);
    result.initial_residuals.push_back(r);
  }
  // Stage 1, from the user's start: the convex problem in Cartesian parameters.
  std::vector<std::unique_ptr<TipDisplacementCost>> polar_costs;
  std::vector<double> cartesian(p);
  for (int k = 0; k < n; ++k) {
    cartesian[k] = initial[k] * std::cos(initial[n + k]);
    cartesian[n + k] = initial[k] * std::sin(initial[n + k]);
  }
  {
    ceres::Problem::Options keep;
    keep.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem convex(keep);
    std::vector<std::unique_ptr<CartesianCost>> costs;
    for (std::size_t i = 0; i + 1 < data.angles.size(); ++i) {
      polar_costs.push_back(std::make_unique<TipDisplacementCost>(
          machine, data.angles[i], data.angles[i + 1], data.displacements[i]));
      costs.push_back(std::make_unique<CartesianCost>(polar_costs.back().get(), n));
      convex.AddResidualBlock(costs.back().get(), nullptr, cartesian.data());
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 200;
    options.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &convex, &summary);
  }
  std::vector<double> params(p);
  for (int k = 0; k < n; ++k) {
    params[k] = std::max(std::hypot(cartesian[k], cartesian[n + k]), 1e-3);
    params[n + k] = std::atan2(cartesian[n + k], cartesian[k]);
  }
  // Stage 2: Eq. (4) as the seed states it, in (l, alpha) with the bounds, to |grad| <= 1e-10.
  ceres::Problem problem;
  for (std::size_t i = 0; i + 1 < data.angles.size(); ++i) {
    problem.AddResidualBlock(
        new TipDisplacementCost(machine, data.angles[i], data.angles[i + 1], data.displacements[i]),
        nullptr, params.data());
  }
  for (int k = 0; k < n; ++k) {
    problem.SetParameterLowerBound(params.data(), k, 1e-6);  // l_k > 0
    problem.SetParameterLowerBound(params.data(), n + k, -std::numbers::pi);
    problem.SetParameterUpperBound(params.data(), n + k, std::numbers::pi);
  }
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  options.gradient_tolerance = 1e-10;  // seed §3.1: ‖∇‖∞ ≤ 1e-10
  options.function_tolerance = 0.0;
  options.parameter_tolerance = 1e-15;
  options.max_num_iterations = 500;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size());
  result.cost = summary.final_cost;

  // Jacobian, gradient and conditioning at the solution.
  double cost = 0;
  std::vector<double> residuals, gradient, jacobian_values;
  ceres::CRSMatrix jacobian;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &residuals, &gradient, &jacobian);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(jacobian.num_rows, jacobian.num_cols);
  for (int r = 0; r < jacobian.num_rows; ++r) {
    for (int i = jacobian.rows[r]; i < jacobian.rows[r + 1]; ++i) {
      J(r, jacobian.cols[i]) = jacobian.values[i];
    }
  }
  // Projected gradient: components pushing against an active bound do not count.
  double max_norm = 0;
  for (int k = 0; k < p; ++k) {
    const double lo = k < n ? 1e-6 : -std::numbers::pi, hi = k < n ? 1e300 : std::numbers::pi;
    const double projected = std::clamp(params[k] - gradient[k], lo, hi) - params[k];
    max_norm = std::max(max_norm, std::abs(projected));
  }
  result.gradient_max_norm = max_norm;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J);
  const auto& s = svd.singularValues();
  result.condition_number = s(s.size() - 1) > 0 ? s(0) / s(s.size() - 1) : INFINITY;
  if (!(result.condition_number < 1e8)) {
    result.degenerate = "the poses do not determine every parameter (Jacobian condition number " +
                        std::to_string(result.condition_number) +
                        "): move each joint through a wider range, in at least 3 distinct poses";
    return result;
  }
  for (std::size_t i = 0; i + 1 < data.angles.size(); ++i) {
    result.residuals.emplace_back(residuals[2 * i], residuals[2 * i + 1]);
  }
  // Parameter standard deviations from (JᵀJ)⁻¹ σ², σ² = Σr²/(m − p).
  const int m = static_cast<int>(residuals.size());
  const double sigma2 = m > p ? 2 * cost / (m - p) : 0.0;
  const Eigen::MatrixXd covariance = (J.transpose() * J).inverse() * sigma2;
  for (int k = 0; k < p; ++k) result.std_dev.push_back(std::sqrt(std::max(covariance(k, k), 0.0)));
  result.params = params;
  result.ok = true;
  return result;
}

}  // namespace autoshovel::identification
