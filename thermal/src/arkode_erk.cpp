#include "arkode_integrators.hpp"

#include <arkode/arkode_erkstep.h>

namespace frictherm::thermal::detail {

ArkodeErk::ArkodeErk(const IntegratorOptions& options) : SundialsIntegrator("arkode_erk", options, LinearSolverKind::None) {}

void ArkodeErk::create(double t0) {
  mem_ = MemPtr(ERKStepCreate(sys_->callbacks().rhs, t0, y_.get(), ctx_.get()), MemDeleter{&ERKStepFree});
  check_ptr(mem_.get(), "ERKStepCreate", who_);
  void* mem = mem_.get();
  check(ERKStepSetErrHandlerFn(mem, &ErrorSink::handler, &sink_), "ERKStepSetErrHandlerFn");
  check(ERKStepSVtolerances(mem, opt_.rtol, abstol_.get()), "ERKStepSVtolerances");
  check(ERKStepSetUserData(mem, sys_->callbacks().user_data), "ERKStepSetUserData");
  check(ERKStepSetMaxNumSteps(mem, opt_.max_steps), "ERKStepSetMaxNumSteps");
}

void ArkodeErk::reinit(double t0) {
  check(ERKStepReInit(mem_.get(), sys_->callbacks().rhs, t0, y_.get()), "ERKStepReInit");
  check(ERKStepSVtolerances(mem_.get(), opt_.rtol, abstol_.get()), "ERKStepSVtolerances");  // abstol_ may be new
}

int ArkodeErk::evolve(double t1) {
  check(ERKStepSetStopTime(mem_.get(), t1), "ERKStepSetStopTime");
  sunrealtype tret = 0.0;
  return ERKStepEvolve(mem_.get(), t1, y_.get(), &tret, ARK_NORMAL);
}

IntegratorStats ArkodeErk::counters() const {
  IntegratorStats s;
  void* mem = mem_.get();
  if (mem == nullptr) return s;
  ERKStepGetNumSteps(mem, &s.steps);
  ERKStepGetNumRhsEvals(mem, &s.rhs_evals);
  ERKStepGetNumErrTestFails(mem, &s.error_test_failures);
  if (sys_ != nullptr && sys_->jacobian_evaluations() >= 0) s.jac_evals = sys_->jacobian_evaluations();
  return s;
}

FlagNameFn ArkodeErk::flag_name_fn() const { return &ERKStepGetReturnFlagName; }

}  // namespace frictherm::thermal::detail
