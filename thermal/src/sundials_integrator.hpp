// Window logic of the SUNDIALS-backed integrators (thermal-notes §1), serial and distributed
// alike (thermal_ode.hpp). Internal header.
//
// Each advance(problem, T, [progress,] t0, t1) is one window. The solver is
//  * rebuilt when the problem's M, K or boundaries changed and KLU holds their pattern, or the
//    state size (reacting nodes), the reaction's presence or the conservative Krylov wrapper
//    (its vector M^{1/2}·1) is concerned,
//  * re-initialised in its kept memory with the new M, K when only their values changed (PCG,
//    fixed point, explicit: what a coupler's per-window re-assembly does; no CVodeCreate, no
//    new solvers or vectors),
//  * re-initialised (history cleared) when T (or the reaction progress) was changed outside,
//    t0 is not the previous t1 (on any process),
//    or options.reinit_every_window is set,
//  * otherwise continued with its history (source changes between windows are then handled
//    by error control, which the notes found cheaper unless the jumps are large).
// The stop time is set before every window (6.4.1: tstop stays set after tout == tstop).
// Counters are accumulated before any re-init, since ReInit zeroes them.
#pragma once

#include "scheme.hpp"
#include "sundials_support.hpp"

#include <cstdint>
#include <limits>
#include <string>

namespace frictherm::thermal::detail {

// The Krylov solver: PCG ("pcg" on a symmetric Newton matrix) or SPGMR, made exact in Σ M T when
// the ODE conserves it (conservative_krylov.hpp).
LinSolPtr make_krylov_solver(const ThermalOde& ode, LinearSolverKind lin, N_Vector y, int maxl, SUNContext ctx,
                             const std::string& who);

class SundialsIntegrator : public Scheme {
 public:
  SundialsIntegrator(std::string name, const IntegratorOptions& options, LinearSolverKind lin);
  void advance(ThermalOde& ode, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0, double t1) final;

 protected:
  bool krylov() const { return lin_ == LinearSolverKind::Pcg || lin_ == LinearSolverKind::Gmres; }
  virtual void release() = 0;                  // free solver memory and solvers
  virtual void create(double t0) = 0;          // y_ holds the initial state
  virtual void reinit(double t0) = 0;          // y_ holds the new state
  virtual int evolve(double t1) = 0;           // set stop time, integrate into y_, return flag
  virtual IntegratorStats counters() const = 0;  // as reported by SUNDIALS since (re)init
  virtual FlagNameFn flag_name_fn() const = 0;
  virtual const char* evolve_call() const = 0;  // "CVode", "ARKStepEvolve" …

  void check(int flag, const char* call) const {
    check_flag(flag, call, who_, flag_name_fn(), sink_);
  }
  void on_reset_stats() override;

  IntegratorOptions opt_;
  LinearSolverKind lin_;
  ContextPtr ctx_;
  NVectorPtr y_, abstol_;
  ThermalOde* sys_ = nullptr;  // the ODE of the window in course
  std::string who_;
  ErrorSink sink_;

 private:
  void absorb_counters();  // base_ += counters() − offset_
  void refresh_stats();

  bool built_ = false, conservative_ = false;
  std::uint64_t revision_ = 0;
  double t_last_ = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd t_state_last_, progress_last_;
  IntegratorStats base_, offset_;
  double wall_ = 0.0;
  long reinits_ = 0;
};

}  // namespace frictherm::thermal::detail
