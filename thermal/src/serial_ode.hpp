// The serial thermal::Problem as a ThermalOde (thermal_ode.hpp): one process, N_Vector_Serial,
// KLU or the Jacobi-preconditioned Krylov path of OdeSystem. Internal header.
#pragma once

#include "ode_system.hpp"
#include "thermal_ode.hpp"

namespace frictherm::thermal::detail {

class SerialOde final : public ThermalOde {
 public:
  void attach(const Problem& problem) { problem_ = &problem; }  // the problem of the next window

  std::string who(const std::string& integrator) const override { return integrator; }
  std::uint64_t revision() const override { return problem_->revision(); }
  Index size() const override { return problem_->size(); }
  const Eigen::VectorXd& mass() const override { return problem_->mass(); }
  bool is_dirichlet(Index node) const override { return problem_->is_dirichlet(node); }
  void apply_dirichlet(Eigen::VectorXd& temperature) const override { problem_->apply_dirichlet(temperature); }
  const Reaction* reaction() const override { return problem_->has_reaction() ? &problem_->reaction() : nullptr; }
  bool reaction_consumes() const override { return problem_->reaction_consumes(); }
  std::string state_error(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress) const override;
  void rhs(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& dTdt) const override {
    problem_->rhs(t, temperature, dTdt);
  }
  void transport_heat_rate(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& w) const override {
    problem_->transport_heat_rate(t, temperature, w);
  }
  double dt_limit(const std::string& estimate) const override;
  bool all_ranks(bool mine) const override { return mine; }
  double max_all(double mine) const override { return mine; }

  void build(bool symmetric) override { sys_.build(*problem_, symmetric); }
  void bind() override { sys_.bind(*problem_); }
  Index nodes() const override { return sys_.nodes(); }
  Index state_size() const override { return sys_.state_size(); }
  bool has_reaction() const override { return sys_.has_reaction(); }
  bool nonsymmetric() const override { return sys_.nonsymmetric(); }
  bool conserves() const override { return false; }  // KLU and Jacobi keep Σ M T to round-off already
  NVectorPtr make_vector(SUNContext ctx) const override;
  void to_y(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress, N_Vector y) override {
    sys_.to_y(temperature, progress, y);
  }
  void to_T(N_Vector y, Eigen::VectorXd& temperature, Eigen::VectorXd* progress) const override {
    sys_.to_T(y, temperature, progress);
  }
  void fill_abstol(double atol, double progress_atol, N_Vector out) const override {
    sys_.fill_abstol(atol, progress_atol, out);
  }
  MatrixPtr make_jacobian_matrix(SUNContext ctx) const override { return sys_.make_jacobian_matrix(ctx); }
  OdeCallbacks callbacks() override;
  long jacobian_evaluations() const override { return -1; }

 private:
  const Problem* problem_ = nullptr;
  OdeSystem sys_;
};

}  // namespace frictherm::thermal::detail
