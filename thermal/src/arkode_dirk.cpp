#include "arkode_integrators.hpp"

#include <arkode/arkode_arkstep.h>
#include <sunlinsol/sunlinsol_klu.h>

namespace frictherm::thermal::detail {

ArkodeDirk::ArkodeDirk(const IntegratorOptions& options, LinearSolverKind lin)
    : SundialsIntegrator("arkode_dirk", options, lin) {}

void ArkodeDirk::release() {
  mem_.reset();  // ARKStepFree before the solvers it references
  ls_.reset();
  a_.reset();
}

void ArkodeDirk::create(double t0) {
  SUNContext ctx = ctx_.get();
  // fe = NULL, fi = conduction + sources: fully implicit.
  mem_ = MemPtr(ARKStepCreate(nullptr, sys_->callbacks().rhs, t0, y_.get(), ctx), MemDeleter{&ARKStepFree});
  check_ptr(mem_.get(), "ARKStepCreate", who_);
  void* mem = mem_.get();
  check(ARKStepSetErrHandlerFn(mem, &ErrorSink::handler, &sink_), "ARKStepSetErrHandlerFn");
  check(ARKStepSetTableNum(mem, ARKODE_ESDIRK324L2SA_4_2_3, ARKODE_ERK_NONE), "ARKStepSetTableNum");
  check(ARKStepSVtolerances(mem, opt_.rtol, abstol_.get()), "ARKStepSVtolerances");
  check(ARKStepSetUserData(mem, sys_->callbacks().user_data), "ARKStepSetUserData");
  check(ARKStepSetMaxNumSteps(mem, opt_.max_steps), "ARKStepSetMaxNumSteps");
  if (lin_ == LinearSolverKind::Klu) {
    a_ = sys_->make_jacobian_matrix(ctx);
    ls_ = LinSolPtr(SUNLinSol_KLU(y_.get(), a_.get(), ctx));
    check_ptr(ls_.get(), "SUNLinSol_KLU", who_);
    // J has a symmetric pattern: AMD ordering (0) fills in less than the COLAMD default.
    check(SUNLinSol_KLUSetOrdering(ls_.get(), 0), "SUNLinSol_KLUSetOrdering");
    check(ARKStepSetLinearSolver(mem, ls_.get(), a_.get()), "ARKStepSetLinearSolver");
    check(ARKStepSetJacFn(mem, sys_->callbacks().jac), "ARKStepSetJacFn");
  } else {
    ls_ = make_krylov_solver(*sys_, lin_, y_.get(), opt_.krylov_maxl, ctx, who_);
    check(ARKStepSetLinearSolver(mem, ls_.get(), nullptr), "ARKStepSetLinearSolver");
    check(ARKStepSetJacTimes(mem, nullptr, sys_->callbacks().jtimes), "ARKStepSetJacTimes");
    check(ARKStepSetPreconditioner(mem, sys_->callbacks().psetup, sys_->callbacks().psolve),
          "ARKStepSetPreconditioner");
  }
  // Without a reaction f_i is linear in y with a constant Jacobian: one Newton iteration per
  // stage. The Arrhenius term is nonlinear: full Newton then.
  if (!sys_->has_reaction()) check(ARKStepSetLinear(mem, 0), "ARKStepSetLinear");
}

void ArkodeDirk::reinit(double t0) {
  check(ARKStepReInit(mem_.get(), nullptr, sys_->callbacks().rhs, t0, y_.get()), "ARKStepReInit");
  check(ARKStepSVtolerances(mem_.get(), opt_.rtol, abstol_.get()), "ARKStepSVtolerances");  // abstol_ may be new
}

int ArkodeDirk::evolve(double t1) {
  check(ARKStepSetStopTime(mem_.get(), t1), "ARKStepSetStopTime");
  sunrealtype tret = 0.0;
  return ARKStepEvolve(mem_.get(), t1, y_.get(), &tret, ARK_NORMAL);
}

IntegratorStats ArkodeDirk::counters() const {
  IntegratorStats s;
  void* mem = mem_.get();
  if (mem == nullptr) return s;
  long nfe = 0, nfi = 0, nfe_ls = 0, nni = 0, ncfn = 0;
  ARKStepGetNumSteps(mem, &s.steps);
  ARKStepGetNumRhsEvals(mem, &nfe, &nfi);
  ARKStepGetNumErrTestFails(mem, &s.error_test_failures);
  ARKStepGetNonlinSolvStats(mem, &nni, &ncfn);
  ARKStepGetNumJacEvals(mem, &s.jac_evals);
  ARKStepGetNumLinIters(mem, &s.linear_iters);
  ARKStepGetNumLinRhsEvals(mem, &nfe_ls);
  s.rhs_evals = nfe + nfi + nfe_ls;
  s.nonlinear_iters = nni;
  s.convergence_failures = ncfn;
  if (sys_ != nullptr && sys_->jacobian_evaluations() >= 0) s.jac_evals = sys_->jacobian_evaluations();
  return s;
}

FlagNameFn ArkodeDirk::flag_name_fn() const { return &ARKStepGetReturnFlagName; }

}  // namespace frictherm::thermal::detail
