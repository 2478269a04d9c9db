// A time-integration method (forward_euler, cvode_bdf, cvode_adams, arkode_erk, arkode_dirk) on a
// ThermalOde: the one implementation behind thermal::Integrator and thermal::DistributedIntegrator
// (issue 32). Internal header.
#pragma once

#include "frictherm/thermal/integrator.hpp"
#include "thermal_ode.hpp"

#include <memory>
#include <string>

namespace frictherm::thermal::detail {

class Scheme {
 public:
  explicit Scheme(std::string name) : name_(std::move(name)) {}
  Scheme(const Scheme&) = delete;
  Scheme& operator=(const Scheme&) = delete;
  virtual ~Scheme() = default;

  const std::string& name() const { return name_; }
  const IntegratorStats& stats() const { return stats_; }
  void reset_stats() { stats_ = IntegratorStats{}; on_reset_stats(); }
  // One window t0 < t1 from T (Dirichlet values written, input checked: open_window); progress
  // null means λ = 0. Leaves T unchanged when it throws.
  virtual void advance(ThermalOde& ode, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0, double t1) = 0;

 protected:
  virtual void on_reset_stats() {}
  std::string name_;
  IntegratorStats stats_;
};

// The input checks of every window, agreed by all processes (a bad input on one process throws
// std::invalid_argument on each, so that none waits in a collective), then the Dirichlet values.
void open_window(const ThermalOde& ode, const std::string& name, Eigen::VectorXd& T, const Eigen::VectorXd* progress,
                 double t0, double t1);

enum class LinearSolverKind { Klu, Pcg, Gmres, FixedPoint, None };

// options.linear_solver for the named integrator (see IntegratorOptions). direct: KLU is
// available (serial) and the default of the implicit integrators; else PCG is.
LinearSolverKind parse_linear_solver(const std::string& integrator, const std::string& value, bool direct);

// The name (one of integrator_names(), else the list in the message) and the options shared by all
// integrators (rtol, atol, fe_* …); throws std::invalid_argument. linear_solver: parse_linear_solver.
void check_integrator_options(const std::string& name, const IntegratorOptions& options);

// name one of integrator_names(), options checked by make_integrator.
std::unique_ptr<Scheme> make_scheme(const std::string& name, const IntegratorOptions& options, LinearSolverKind lin);

}  // namespace frictherm::thermal::detail
