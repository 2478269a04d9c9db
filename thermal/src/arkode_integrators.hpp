// ARKODE 5.4.1 integrators: explicit ERKStep and diagonally implicit ARKStep. Internal header.
#pragma once

#include "sundials_integrator.hpp"

namespace frictherm::thermal::detail {

// Adaptive explicit Runge–Kutta (ERKStep default table, order 4). Its steps are limited by
// error control, which on diffusion ends up enforcing the explicit stability bound.
class ArkodeErk final : public SundialsIntegrator {
 public:
  explicit ArkodeErk(const IntegratorOptions& options);
  ~ArkodeErk() override { release(); }

 protected:
  void release() override { mem_.reset(); }
  void create(double t0) override;
  void reinit(double t0) override;
  int evolve(double t1) override;
  IntegratorStats counters() const override;
  FlagNameFn flag_name_fn() const override;
  const char* evolve_call() const override { return "ERKStepEvolve"; }

 private:
  MemPtr mem_;
};

// Adaptive L-stable ESDIRK (ARKODE_ESDIRK324L2SA_4_2_3, thermal-notes §2 test 3), with the
// implicit RHS declared linear and time-independent in its Jacobian (ARKStepSetLinear).
class ArkodeDirk final : public SundialsIntegrator {
 public:
  ArkodeDirk(const IntegratorOptions& options, LinearSolverKind lin);
  ~ArkodeDirk() override { release(); }

 protected:
  void release() override;
  void create(double t0) override;
  void reinit(double t0) override;
  int evolve(double t1) override;
  IntegratorStats counters() const override;
  FlagNameFn flag_name_fn() const override;
  const char* evolve_call() const override { return "ARKStepEvolve"; }

 private:
  MatrixPtr a_;
  LinSolPtr ls_;
  MemPtr mem_;  // declared last: freed first
};

}  // namespace frictherm::thermal::detail
