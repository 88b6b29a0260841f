#include "runtime/plant/ode_integrator.h"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

namespace autoshovel::plant {

namespace {

int RhsCallback(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* system = static_cast<OdeSystem*>(user_data);
  system->Rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
  // A non-finite derivative is a recoverable failure: CVODE retries with a smaller step.
  const int n = system->size();
  const double* d = N_VGetArrayPointer(ydot);
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(d[i])) return 1;
  }
  return 0;
}

int QuadratureCallback(sunrealtype t, N_Vector y, N_Vector integrand, void* user_data) {
  auto* system = static_cast<OdeSystem*>(user_data);
  system->Quadrature(t, N_VGetArrayPointer(y), N_VGetArrayPointer(integrand));
  return 0;
}

int JacobianCallback(sunrealtype t, N_Vector y, N_Vector /*fy*/, SUNMatrix jacobian,
                     void* user_data, N_Vector, N_Vector, N_Vector) {
  auto* system = static_cast<OdeSystem*>(user_data);
  system->Jacobian(t, N_VGetArrayPointer(y), SUNDenseMatrix_Data(jacobian));
  return 0;
}

void Check(int flag, const char* what) {
  if (flag < 0) {
    std::ostringstream message;
    message << "CVODE: " << what << " failed with flag " << flag << " ("
            << CVodeGetReturnFlagName(flag) << ")";
    throw IntegrationError(message.str());
  }
}

}  // namespace

struct OdeIntegrator::Impl {
  SUNContext context = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  N_Vector quadrature = nullptr;  // null without quadratures
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;
  void* cvode = nullptr;
  int n = 0;
  double last_step = 0.0;
  // CVodeReInit zeroes CVODE's counters: totals of earlier segments are kept here.
  long steps_before = 0, rhs_before = 0, jacobians_before = 0;

  long Steps() const {
    long value = 0;
    CVodeGetNumSteps(cvode, &value);
    return value;
  }
  long RhsEvaluations() const {
    long value = 0;
    CVodeGetNumRhsEvals(cvode, &value);
    long linear_solver_rhs = 0;  // difference-quotient evaluations (none with our Jacobian)
    CVodeGetNumLinRhsEvals(cvode, &linear_solver_rhs);
    return value + linear_solver_rhs;
  }
  long JacobianEvaluations() const {
    long value = 0;
    CVodeGetNumJacEvals(cvode, &value);
    return value;
  }
};

OdeIntegrator::OdeIntegrator(OdeSystem& system, const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.n = system.size();
  Check(SUNContext_Create(nullptr, &s.context), "SUNContext_Create");
  s.y = N_VNew_Serial(s.n, s.context);
  s.abstol = N_VNew_Serial(s.n, s.context);
  double* atol = N_VGetArrayPointer(s.abstol);
  for (int i = 0; i < s.n; ++i) {
    atol[i] = options.absolute_tolerance.size() == 1 ? options.absolute_tolerance[0]
                                                     : options.absolute_tolerance.at(i);
  }
  N_VConst(0.0, s.y);
  s.cvode = CVodeCreate(CV_BDF, s.context);
  if (s.cvode == nullptr) throw IntegrationError("CVODE: CVodeCreate failed");
  Check(CVodeInit(s.cvode, RhsCallback, 0.0, s.y), "CVodeInit");
  Check(CVodeSVtolerances(s.cvode, options.relative_tolerance, s.abstol), "CVodeSVtolerances");
  Check(CVodeSetUserData(s.cvode, &system), "CVodeSetUserData");
  s.matrix = SUNDenseMatrix(s.n, s.n, s.context);
  s.solver = SUNLinSol_Dense(s.y, s.matrix, s.context);
  Check(CVodeSetLinearSolver(s.cvode, s.solver, s.matrix), "CVodeSetLinearSolver");
  Check(CVodeSetJacFn(s.cvode, JacobianCallback), "CVodeSetJacFn");
  Check(CVodeSetMaxNumSteps(s.cvode, options.max_steps_per_call), "CVodeSetMaxNumSteps");
  if (options.max_step > 0) Check(CVodeSetMaxStep(s.cvode, options.max_step), "CVodeSetMaxStep");
  const int nq = system.quadrature_size();
  if (nq > 0) {
    s.quadrature = N_VNew_Serial(nq, s.context);
    N_VConst(0.0, s.quadrature);
    Check(CVodeQuadInit(s.cvode, QuadratureCallback, s.quadrature), "CVodeQuadInit");
    // Not in the error test (the default, said here because the trajectory depends on it).
    Check(CVodeSetQuadErrCon(s.cvode, SUNFALSE), "CVodeSetQuadErrCon");
    quadratures_.assign(nq, 0.0);
  }
  // Errors become exceptions with CVODE's own flag; its default handler would print to stderr.
  Check(CVodeSetErrHandlerFn(
            s.cvode, [](int, const char*, const char*, char*, void*) {}, nullptr),
        "CVodeSetErrHandlerFn");
}

OdeIntegrator::~OdeIntegrator() {
  Impl& s = *impl_;
  CVodeFree(&s.cvode);
  SUNLinSolFree(s.solver);
  SUNMatDestroy(s.matrix);
  N_VDestroy(s.abstol);
  if (s.quadrature != nullptr) N_VDestroy(s.quadrature);
  N_VDestroy(s.y);
  SUNContext_Free(&s.context);
}

void OdeIntegrator::Reset(double t, const double* y) {
  Impl& s = *impl_;
  std::memcpy(N_VGetArrayPointer(s.y), y, sizeof(double) * s.n);
  s.steps_before += s.Steps();
  s.rhs_before += s.RhsEvaluations();
  s.jacobians_before += s.JacobianEvaluations();
  Check(CVodeReInit(s.cvode, t, s.y), "CVodeReInit");
  if (s.quadrature != nullptr) {
    // The integrals go on from where they stand.
    std::memcpy(N_VGetArrayPointer(s.quadrature), quadratures_.data(),
                sizeof(double) * quadratures_.size());
    Check(CVodeQuadReInit(s.cvode, s.quadrature), "CVodeQuadReInit");
  }
  if (s.last_step > 0) Check(CVodeSetInitStep(s.cvode, s.last_step), "CVodeSetInitStep");
  time_ = t;
  ++resets_;
}

void OdeIntegrator::AdvanceTo(double t_end, double* y) {
  Impl& s = *impl_;
  if (t_end <= time_) {
    std::memcpy(y, N_VGetArrayPointer(s.y), sizeof(double) * s.n);
    return;
  }
  Check(CVodeSetStopTime(s.cvode, t_end), "CVodeSetStopTime");
  sunrealtype t_reached = time_;
  Check(CVode(s.cvode, t_end, s.y, &t_reached, CV_NORMAL), "CVode");
  sunrealtype h = 0;
  CVodeGetLastStep(s.cvode, &h);
  if (h > 0) s.last_step = h;
  time_ = t_end;
  std::memcpy(y, N_VGetArrayPointer(s.y), sizeof(double) * s.n);
  if (s.quadrature != nullptr) {
    Check(CVodeGetQuad(s.cvode, &t_reached, s.quadrature), "CVodeGetQuad");
    std::memcpy(quadratures_.data(), N_VGetArrayPointer(s.quadrature),
                sizeof(double) * quadratures_.size());
  }
}

long OdeIntegrator::steps() const { return impl_->steps_before + impl_->Steps(); }
long OdeIntegrator::rhs_evaluations() const { return impl_->rhs_before + impl_->RhsEvaluations(); }
long OdeIntegrator::jacobian_evaluations() const {
  return impl_->jacobians_before + impl_->JacobianEvaluations();
}

}  // namespace autoshovel::plant
