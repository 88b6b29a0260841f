// A stiff ODE integrator for the plant: CVODES (BDF, Newton iteration, dense direct linear
// solver) with a caller-supplied Jacobian. This header keeps SUNDIALS out of its includers.
//
// The plant integrates piecewise: between two discrete events (a valve command reaching its
// spool, a new contact state of the bucket, a new drive command) the inputs are constant and the
// right-hand side is smooth; at each event the caller changes its inputs and calls Reset, which
// re-initialises CVODE at the current state (order 1, fresh history) so that no step straddles
// a discontinuity. The last successful step size is kept as the initial step after a reset.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace autoshovel::plant {

/// The system integrated: ẏ = f(t, y) and its dense Jacobian ∂f/∂y.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int size() const = 0;
  virtual void Rhs(double t, const double* y, double* ydot) = 0;
  /// Column-major n × n (SUNDIALS' dense layout): jacobian[col * n + row] = ∂f_row/∂y_col.
  virtual void Jacobian(double t, const double* y, double* jacobian) = 0;
  /// Quadratures: integrals ∫ g(t, y) dt carried along with the solution (CVODES' quadrature
  /// feature). They enter neither the Newton iteration nor the step-size control, so adding them
  /// never changes the trajectory; they are as accurate as the BDF formula on the steps taken.
  virtual int quadrature_size() const { return 0; }
  virtual void Quadrature(double /*t*/, const double* /*y*/, double* /*integrand*/) {}
};

struct IntegratorOptions {
  double relative_tolerance = 1e-6;
  /// Absolute tolerance per state (size n), or one value for all when of size 1.
  std::vector<double> absolute_tolerance{1e-8};
  double max_step = 0.0;  ///< 0: unlimited
  long max_steps_per_call = 20000;
};

/// Thrown when CVODE fails (error test or convergence failures it could not recover from).
class IntegrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class OdeIntegrator {
 public:
  OdeIntegrator(OdeSystem& system, const IntegratorOptions& options);
  ~OdeIntegrator();
  OdeIntegrator(const OdeIntegrator&) = delete;
  OdeIntegrator& operator=(const OdeIntegrator&) = delete;

  /// Re-initialises at (t, y): a discrete event happened.
  void Reset(double t, const double* y);
  /// Integrates to exactly `t_end` (a stop time: CVODE never steps past it) and writes y(t_end).
  void AdvanceTo(double t_end, double* y);
  /// The quadratures at time(), accumulated since construction across resets (size
  /// OdeSystem::quadrature_size()).
  const std::vector<double>& quadratures() const { return quadratures_; }

  double time() const { return time_; }
  /// Statistics since construction: internal steps, right-hand side and Jacobian evaluations,
  /// resets.
  long steps() const;
  long rhs_evaluations() const;
  long jacobian_evaluations() const;
  long resets() const { return resets_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double time_ = 0.0;
  long resets_ = 0;
  std::vector<double> quadratures_;
};

}  // namespace autoshovel::plant
