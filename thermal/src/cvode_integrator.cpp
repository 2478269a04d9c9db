#include "cvode_integrator.hpp"

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

namespace frictherm::thermal::detail {

CvodeIntegrator::CvodeIntegrator(std::string name, int lmm, const IntegratorOptions& options, LinearSolverKind lin)
    : SundialsIntegrator(std::move(name), options, lin), lmm_(lmm) {}

void CvodeIntegrator::release() {
  mem_.reset();  // CVodeFree before the solvers it references
  nls_.reset();
  ls_.reset();
  a_.reset();
}

void CvodeIntegrator::create(double t0) {
  SUNContext ctx = ctx_.get();
  mem_ = MemPtr(CVodeCreate(lmm_, ctx), MemDeleter{&CVodeFree});
  check_ptr(mem_.get(), "CVodeCreate", who_);
  void* mem = mem_.get();
  check(CVodeSetErrHandlerFn(mem, &ErrorSink::handler, &sink_), "CVodeSetErrHandlerFn");
  check(CVodeInit(mem, sys_->callbacks().rhs, t0, y_.get()), "CVodeInit");
  check(CVodeSVtolerances(mem, opt_.rtol, abstol_.get()), "CVodeSVtolerances");
  check(CVodeSetUserData(mem, sys_->callbacks().user_data), "CVodeSetUserData");
  check(CVodeSetMaxNumSteps(mem, opt_.max_steps), "CVodeSetMaxNumSteps");
  switch (lin_) {
    case LinearSolverKind::Klu:  // sparse direct, exact constant Jacobian J = −M⁻¹K_eff
      a_ = sys_->make_jacobian_matrix(ctx);
      ls_ = LinSolPtr(SUNLinSol_KLU(y_.get(), a_.get(), ctx));
      check_ptr(ls_.get(), "SUNLinSol_KLU", who_);
      // J has a symmetric pattern: AMD ordering (0) fills in less than the COLAMD default.
      check(SUNLinSol_KLUSetOrdering(ls_.get(), 0), "SUNLinSol_KLUSetOrdering");
      check(CVodeSetLinearSolver(mem, ls_.get(), a_.get()), "CVodeSetLinearSolver");
      check(CVodeSetJacFn(mem, sys_->callbacks().jac), "CVodeSetJacFn");
      break;
    case LinearSolverKind::Pcg:  // CG on the SPD form, exact J·v, the ODE's preconditioner
    case LinearSolverKind::Gmres:  // (GMRES when a consuming reaction makes the Newton matrix non-symmetric)
      ls_ = make_krylov_solver(*sys_, lin_, y_.get(), opt_.krylov_maxl, ctx, who_);
      check(CVodeSetLinearSolver(mem, ls_.get(), nullptr), "CVodeSetLinearSolver");
      check(CVodeSetJacTimes(mem, nullptr, sys_->callbacks().jtimes), "CVodeSetJacTimes");
      check(CVodeSetPreconditioner(mem, sys_->callbacks().psetup, sys_->callbacks().psolve),
            "CVodeSetPreconditioner");
      break;
    case LinearSolverKind::FixedPoint:  // functional iteration (non-stiff Adams)
      nls_ = NonlinSolPtr(SUNNonlinSol_FixedPoint(y_.get(), 0, ctx));
      check_ptr(nls_.get(), "SUNNonlinSol_FixedPoint", who_);
      check(CVodeSetNonlinearSolver(mem, nls_.get()), "CVodeSetNonlinearSolver");
      break;
    case LinearSolverKind::None:
      break;
  }
}

void CvodeIntegrator::reinit(double t0) {
  check(CVodeReInit(mem_.get(), t0, y_.get()), "CVodeReInit");
  check(CVodeSVtolerances(mem_.get(), opt_.rtol, abstol_.get()), "CVodeSVtolerances");  // abstol_ may be new
}

int CvodeIntegrator::evolve(double t1) {
  // 6.4.1: tstop stays set after tout == tstop and ReInit keeps it, so set it every window.
  check(CVodeSetStopTime(mem_.get(), t1), "CVodeSetStopTime");
  sunrealtype tret = 0.0;
  return CVode(mem_.get(), t1, y_.get(), &tret, CV_NORMAL);
}

IntegratorStats CvodeIntegrator::counters() const {
  IntegratorStats s;
  void* mem = mem_.get();
  if (mem == nullptr) return s;
  long nni = 0, ncfn = 0, nfe_ls = 0;
  CVodeGetNumSteps(mem, &s.steps);
  CVodeGetNumRhsEvals(mem, &s.rhs_evals);
  CVodeGetNumErrTestFails(mem, &s.error_test_failures);
  CVodeGetNonlinSolvStats(mem, &nni, &ncfn);
  s.nonlinear_iters = nni;
  s.convergence_failures = ncfn;
  if (lin_ == LinearSolverKind::Klu || krylov()) {
    CVodeGetNumJacEvals(mem, &s.jac_evals);
    CVodeGetNumLinIters(mem, &s.linear_iters);
    CVodeGetNumLinRhsEvals(mem, &nfe_ls);
    s.rhs_evals += nfe_ls;
  }
  if (sys_ != nullptr && sys_->jacobian_evaluations() >= 0) s.jac_evals = sys_->jacobian_evaluations();
  return s;
}

FlagNameFn CvodeIntegrator::flag_name_fn() const { return &CVodeGetReturnFlagName; }

}  // namespace frictherm::thermal::detail
