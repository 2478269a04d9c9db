// The DistributedProblem as a ThermalOde (thermal_ode.hpp): this rank's owned nodes,
// N_Vector_Parallel, the Krylov path preconditioned by a PETSc PC (distributed_ode.hpp), the
// agreements as MPI_Allreduce (counted in DistributedProblem::count_reductions). Internal header.
#pragma once

#include "../thermal_ode.hpp"
#include "distributed_ode.hpp"

#include <string>

namespace frictherm::thermal::detail {

class DistributedThermalOde final : public FormOde<DistributedProblem, DistributedOde> {
 public:
  explicit DistributedThermalOde(std::string preconditioner) : pc_(std::move(preconditioner)) {}

  std::string who(const std::string& integrator) const override;
  Index size() const override { return problem_->local_size(); }
  bool is_dirichlet(Index node) const override { return problem_->is_dirichlet_local(node); }
  std::string state_error(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress) const override;
  void rhs(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& dTdt) const override;
  void transport_heat_rate(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& w) const override {
    problem_->heat_rate(t, temperature.data(), w.data());  // one ghost exchange
  }
  double dt_limit(const std::string& estimate) const override;
  bool all_ranks(bool mine) const override;
  double max_all(double mine) const override;

  void build(bool symmetric) override { form_.build(*problem_, symmetric, symmetric ? pc_ : std::string()); }
  bool conserves() const override { return form_.conserves(); }
  NVectorPtr make_vector(SUNContext ctx) const override;
  MatrixPtr make_jacobian_matrix(SUNContext ctx) const override;  // throws: no distributed KLU
  OdeCallbacks callbacks() override;
  long jacobian_evaluations() const override { return form_.preconditioner_setups(); }  // P = I − γJ assemblies

 private:
  std::string pc_;
};

}  // namespace frictherm::thermal::detail
