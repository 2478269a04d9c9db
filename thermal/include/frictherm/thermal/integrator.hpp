// Swappable time integrators for thermal::Problem (design §3).
#pragma once

#include "frictherm/thermal/problem.hpp"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::thermal {

// Cumulative over the integrator's life (SUNDIALS counters are summed across re-inits).
struct IntegratorStats {
  long steps = 0;
  long rhs_evals = 0;             // includes RHS calls made by the linear-solver interface
  long jac_evals = 0;
  long nonlinear_iters = 0;
  long linear_iters = 0;
  long error_test_failures = 0;
  long convergence_failures = 0;  // nonlinear-solver convergence failures
  long reinits = 0;               // solver (re)initialisations: first window, T or problem changed
  double wall_seconds = 0.0;      // time spent inside advance()

  IntegratorStats& operator+=(const IntegratorStats& o);
  IntegratorStats& operator-=(const IntegratorStats& o);
};

struct IntegratorOptions {
  double rtol = 1e-6;   // relative tolerance (SUNDIALS integrators)
  double atol = 1e-6;   // absolute tolerance [K]
  double progress_atol = 1e-6;  // absolute tolerance on the reaction progress λ (dimensionless)
  long max_steps = 10000;  // per advance() call (CVODE mxstep; ARKODE mxsteps)
  // Linear solver for implicit methods: "klu" (sparse direct, exact Jacobian −M⁻¹K) or "pcg"
  // (preconditioned CG on the symmetric form y = M^{1/2}T, Jacobi preconditioner,
  // thermal-notes §1). cvode_adams also accepts "fixed_point" (its default: no linear solver).
  // With a consuming reaction the Newton matrix is not symmetric (the T–λ coupling), so "pcg"
  // then runs GMRES (SPGMR) with the same exact J·v and a 2×2 block-Jacobi preconditioner.
  // Empty means the integrator's default (klu for cvode_bdf and arkode_dirk).
  std::string linear_solver;
  int krylov_maxl = 100;   // PCG maximum iterations (SUNDIALS default 5 is too small)
  // forward_euler stability handling: "substep" (take equal sub-steps h ≤ fe_safety·dt_limit;
  // with a reaction, adaptive sub-steps h ≤ fe_safety·2/(λ_cond + max_i(k_i + a_i)), where
  // k_i is the rate constant and a_i the self-heating rate Q_i(1−λ_i)k'(T_i)/M_i),
  // "refuse" (throw StabilityError if the step would exceed fe_safety·dt_limit) or
  // "unguarded" (no check; exists only to demonstrate the instability).
  std::string fe_stability_policy = "substep";
  double fe_safety = 0.9;      // fraction of the stability limit used, in (0, 1]
  double fe_max_dt = 0.0;      // optional cap on the FE step [s]; 0 = none
  // "gershgorin" (guaranteed bound, exact for 3/5/7-point FD) or "power" (power iteration,
  // sharper for Q1 stiffness, capped by the Gershgorin bound).
  std::string fe_limit_estimate = "gershgorin";
  // Re-initialise SUNDIALS at every window even when the state continues (thermal-notes §1:
  // worth it only for large source jumps).
  bool reinit_every_window = false;
};

// A SUNDIALS call failed. flag is the SUNDIALS return value, flag_name its symbolic name.
class SolverError : public std::runtime_error {
 public:
  SolverError(const std::string& what, int flag, std::string flag_name)
      : std::runtime_error(what), flag_(flag), flag_name_(std::move(flag_name)) {}
  int flag() const { return flag_; }
  const std::string& flag_name() const { return flag_name_; }

 private:
  int flag_;
  std::string flag_name_;
};

// forward_euler refused a step beyond its stability limit (policy "refuse"), or an unguarded
// run produced non-finite temperatures.
class StabilityError : public std::runtime_error {
 public:
  StabilityError(const std::string& what, double dt, double dt_limit)
      : std::runtime_error(what), dt_(dt), dt_limit_(dt_limit) {}
  double dt() const { return dt_; }
  double dt_limit() const { return dt_limit_; }

 private:
  double dt_, dt_limit_;
};

class Integrator {
 public:
  Integrator() = default;
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;
  virtual ~Integrator() = default;

  // Integrates problem from t0 to t1 (t1 ≥ t0), updating T in place. Dirichlet values are
  // written into T first. The problem's source is evaluated at absolute time t.
  // Throws std::invalid_argument for bad input, SolverError / StabilityError on failure
  // (T is then left unchanged). A zero-order reaction (consume = false) is evaluated at
  // λ = 0; a consuming reaction needs the overload with the progress (else invalid_argument).
  void advance(const Problem& problem, Eigen::VectorXd& T, double t0, double t1);
  // Same with the reaction progress λ (size() entries in [0, 1]), updated in place when the
  // reaction consumes (clamped to [0, 1] on return; the clamp is at the solver-tolerance
  // level) and held fixed for a zero-order reaction. λ of Dirichlet nodes and nodes with
  // Q_i = 0 never changes. Without a reaction, progress is checked and left unchanged.
  void advance(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd& progress, double t0,
               double t1);
  virtual std::string name() const = 0;

  const IntegratorStats& stats() const { return stats_; }
  void reset_stats() { stats_ = IntegratorStats{}; on_reset_stats(); }

 protected:
  // progress is null for the 4-argument advance (then the reaction, if any, is zero-order).
  virtual void advance_impl(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress,
                            double t0, double t1) = 0;
  virtual void on_reset_stats() {}
  IntegratorStats stats_;
};

// Names: forward_euler, cvode_bdf, cvode_adams, arkode_erk, arkode_dirk.
// Throws std::invalid_argument for an unknown name (listing the valid ones) or bad options.
std::unique_ptr<Integrator> make_integrator(const std::string& name,
                                            const IntegratorOptions& options = {});
const std::vector<std::string>& integrator_names();

}  // namespace frictherm::thermal
