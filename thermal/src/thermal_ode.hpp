// The thermal ODE as the integrators see it (issue 32: one set of integrators). forward_euler and
// the SUNDIALS integrators are written once against this interface; the serial Problem
// (serial_ode.hpp) and the DistributedProblem (distributed/distributed_thermal_ode.hpp) each
// implement it once. On one process the agreements (all_ranks, max_all) return their argument.
// Internal header.
#pragma once

#include "frictherm/thermal/reaction.hpp"
#include "sundials_support.hpp"

#include <sundials/sundials_types.h>

#include <cstdint>
#include <string>

namespace frictherm::thermal::detail {

// SUNDIALS callbacks of the ODE form (ode_system.hpp) and the user_data they take.
struct OdeCallbacks {
  int (*rhs)(sunrealtype, N_Vector, N_Vector, void*) = nullptr;
  int (*jac)(sunrealtype, N_Vector, N_Vector, SUNMatrix, void*, N_Vector, N_Vector, N_Vector) = nullptr;
  int (*jtimes)(N_Vector, N_Vector, sunrealtype, N_Vector, N_Vector, void*, N_Vector) = nullptr;
  int (*psetup)(sunrealtype, N_Vector, N_Vector, sunbooleantype, sunbooleantype*, sunrealtype, void*) = nullptr;
  int (*psolve)(sunrealtype, N_Vector, N_Vector, N_Vector, N_Vector, sunrealtype, sunrealtype, int, void*) = nullptr;
  void* user_data = nullptr;
};

class ThermalOde {
 public:
  virtual ~ThermalOde() = default;

  // ---- the problem of the window in course (this process's nodes) ----
  virtual std::string who(const std::string& integrator) const = 0;  // the integrator's name in messages
  virtual std::uint64_t revision() const = 0;
  virtual Index size() const = 0;
  virtual const Eigen::VectorXd& mass() const = 0;
  virtual bool is_dirichlet(Index node) const = 0;
  virtual void apply_dirichlet(Eigen::VectorXd& temperature) const = 0;
  virtual const Reaction* reaction() const = 0;  // null without one
  virtual bool reaction_consumes() const = 0;
  // Why T (and the progress, when given) cannot start a window here; empty when they can.
  virtual std::string state_error(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress) const = 0;
  // dT/dt = M⁻¹(−K T + q(t) + boundary terms) at λ = 0; w the same heat rate without reaction [W].
  virtual void rhs(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& dTdt) const = 0;
  virtual void transport_heat_rate(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& w) const = 0;
  // Forward Euler limit 2/λ_max(M⁻¹K_eff) over all free rows (+inf for λ_max = 0), by the named estimate.
  virtual double dt_limit(const std::string& estimate) const = 0;
  // Agreements over the processes: mine on every one; the largest value.
  virtual bool all_ranks(bool mine) const = 0;
  virtual double max_all(double mine) const = 0;

  // ---- the ODE form built from that problem (ode_system.hpp) ----
  virtual void build(bool symmetric) = 0;  // symmetric: y = M^{1/2}T (Krylov)
  virtual void bind() = 0;                 // same revision: the callbacks read the problem of this window
  virtual Index nodes() const = 0;         // as built
  virtual Index state_size() const = 0;    // nodes + λ of the reacting nodes when consuming
  virtual bool has_reaction() const = 0;
  virtual bool nonsymmetric() const = 0;   // consuming reaction: Krylov must be GMRES
  virtual bool conserves() const = 0;      // Σ M T invariant under conduction (conservative_krylov.hpp)
  virtual NVectorPtr make_vector(SUNContext ctx) const = 0;  // state_size() entries, serial or parallel
  virtual void to_y(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress, N_Vector y) = 0;
  virtual void to_T(N_Vector y, Eigen::VectorXd& temperature, Eigen::VectorXd* progress) const = 0;
  virtual void fill_abstol(double atol, double progress_atol, N_Vector out) const = 0;
  virtual MatrixPtr make_jacobian_matrix(SUNContext ctx) const = 0;  // direct (KLU) solves only
  virtual OdeCallbacks callbacks() = 0;
  // Jacobian evaluations the ODE counts itself (preconditioner set-ups), or −1 for SUNDIALS' count.
  virtual long jacobian_evaluations() const = 0;
};

// The members every implementation forwards alike: to its problem (Problem or DistributedProblem)
// and to its ODE form (OdeSystem or DistributedOde).
template <class ProblemT, class Form>
class FormOde : public ThermalOde {
 public:
  void attach(const ProblemT& problem) { problem_ = &problem; }  // the problem of the next window

  std::uint64_t revision() const override { return problem_->revision(); }
  const Eigen::VectorXd& mass() const override { return problem_->mass(); }
  void apply_dirichlet(Eigen::VectorXd& temperature) const override { problem_->apply_dirichlet(temperature); }
  const Reaction* reaction() const override { return problem_->has_reaction() ? &problem_->reaction() : nullptr; }
  bool reaction_consumes() const override { return problem_->reaction_consumes(); }

  void bind() override { form_.bind(*problem_); }
  Index nodes() const override { return form_.nodes(); }
  Index state_size() const override { return form_.state_size(); }
  bool has_reaction() const override { return form_.has_reaction(); }
  bool nonsymmetric() const override { return form_.nonsymmetric(); }
  void to_y(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress, N_Vector y) override {
    form_.to_y(temperature, progress, y);
  }
  void to_T(N_Vector y, Eigen::VectorXd& temperature, Eigen::VectorXd* progress) const override {
    form_.to_T(y, temperature, progress);
  }
  void fill_abstol(double atol, double progress_atol, N_Vector out) const override {
    form_.fill_abstol(atol, progress_atol, out);
  }

 protected:
  const ProblemT* problem_ = nullptr;
  Form form_;
};

}  // namespace frictherm::thermal::detail
