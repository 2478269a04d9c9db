// The serial thermal::Problem as a ThermalOde (thermal_ode.hpp): one process, N_Vector_Serial,
// KLU or the Jacobi-preconditioned Krylov path of OdeSystem. Internal header.
#pragma once

#include "ode_system.hpp"
#include "thermal_ode.hpp"

namespace frictherm::thermal::detail {

class SerialOde final : public FormOde<Problem, OdeSystem> {
 public:
  std::string who(const std::string& integrator) const override { return integrator; }
  Index size() const override { return problem_->size(); }
  bool is_dirichlet(Index node) const override { return problem_->is_dirichlet(node); }
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

  void build(bool symmetric) override { form_.build(*problem_, symmetric); }
  bool conserves() const override { return false; }  // KLU and Jacobi keep Σ M T to round-off already
  NVectorPtr make_vector(SUNContext ctx) const override;
  MatrixPtr make_jacobian_matrix(SUNContext ctx) const override { return form_.make_jacobian_matrix(ctx); }
  OdeCallbacks callbacks() override;
  long jacobian_evaluations() const override { return -1; }
};

}  // namespace frictherm::thermal::detail
