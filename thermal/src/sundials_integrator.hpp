// Shared window logic of the SUNDIALS-backed integrators (thermal-notes §1). Internal header.
//
// Each advance(problem, T, [progress,] t0, t1) is one window. The solver is
//  * rebuilt when the problem's M, K or boundaries changed and KLU holds their pattern, or the
//    state size (reacting nodes) or the reaction's presence changed,
//  * re-initialised in its kept memory with the new M, K when only their values changed (PCG,
//    fixed point, explicit: what a coupler's per-window re-assembly does; no CVodeCreate, no
//    new solvers or vectors),
//  * re-initialised (history cleared) when T (or the reaction progress) was changed outside,
//    t0 is not the previous t1,
//    or options.reinit_every_window is set,
//  * otherwise continued with its history (source changes between windows are then handled
//    by error control, which the notes found cheaper unless the jumps are large).
// The stop time is set before every window (6.4.1: tstop stays set after tout == tstop).
// Counters are accumulated before any re-init, since ReInit zeroes them.
#pragma once

#include "ode_system.hpp"
#include "sundials_support.hpp"

#include <cstdint>
#include <limits>
#include <string>

namespace frictherm::thermal::detail {

enum class LinearSolverKind { Klu, Pcg, FixedPoint, None };

// The Krylov solver for linear_solver "pcg": PCG, or SPGMR when sys.nonsymmetric().
LinSolPtr make_krylov_solver(const OdeSystem& sys, N_Vector y, int maxl, SUNContext ctx, const std::string& who);

// Parses options.linear_solver for the named integrator (see IntegratorOptions).
LinearSolverKind parse_linear_solver(const std::string& integrator, const std::string& value);

class SundialsIntegrator : public Integrator {
 public:
  SundialsIntegrator(std::string name, const IntegratorOptions& options, LinearSolverKind lin);
  std::string name() const override { return name_; }

 protected:
  void advance_impl(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0,
                    double t1) final;
  virtual void release() = 0;                  // free solver memory and solvers
  virtual void create(double t0) = 0;          // y_ holds the initial state
  virtual void reinit(double t0) = 0;          // y_ holds the new state
  virtual int evolve(double t1) = 0;           // set stop time, integrate into y_, return flag
  virtual IntegratorStats counters() const = 0;  // as reported by SUNDIALS since (re)init
  virtual FlagNameFn flag_name_fn() const = 0;
  virtual const char* evolve_call() const = 0;  // "CVode", "ARKStepEvolve" …

  void check(int flag, const char* call) const {
    check_flag(flag, call, name_, flag_name_fn(), sink_);
  }
  void on_reset_stats() override;

  std::string name_;
  IntegratorOptions opt_;
  LinearSolverKind lin_;
  ContextPtr ctx_;
  NVectorPtr y_, abstol_;
  OdeSystem sys_;
  ErrorSink sink_;

 private:
  void absorb_counters();  // base_ += counters() − offset_
  void refresh_stats();

  bool built_ = false;
  std::uint64_t revision_ = 0;
  double t_last_ = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd t_state_last_, progress_last_;
  IntegratorStats base_, offset_;
  double wall_ = 0.0;
  long reinits_ = 0;
};

}  // namespace frictherm::thermal::detail
