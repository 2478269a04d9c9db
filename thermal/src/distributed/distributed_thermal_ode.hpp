// The DistributedProblem as a ThermalOde (thermal_ode.hpp): this rank's owned nodes,
// N_Vector_Parallel, the Krylov path preconditioned by a PETSc PC (distributed_ode.hpp), the
// agreements as MPI_Allreduce (counted in DistributedProblem::count_reductions). Internal header.
#pragma once

#include "../thermal_ode.hpp"
#include "distributed_ode.hpp"

#include <string>

namespace frictherm::thermal::detail {

class DistributedThermalOde final : public ThermalOde {
 public:
  explicit DistributedThermalOde(std::string preconditioner) : pc_(std::move(preconditioner)) {}
  void attach(const DistributedProblem& problem) { problem_ = &problem; }  // the problem of the next window

  std::string who(const std::string& integrator) const override;
  std::uint64_t revision() const override { return problem_->revision(); }
  Index size() const override { return problem_->local_size(); }
  const Eigen::VectorXd& mass() const override { return problem_->mass(); }
  bool is_dirichlet(Index node) const override { return problem_->is_dirichlet_local(node); }
  void apply_dirichlet(Eigen::VectorXd& temperature) const override { problem_->apply_dirichlet(temperature); }
  const Reaction* reaction() const override { return problem_->has_reaction() ? &problem_->reaction() : nullptr; }
  bool reaction_consumes() const override { return problem_->reaction_consumes(); }
  std::string state_error(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress) const override;
  void rhs(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& dTdt) const override;
  void transport_heat_rate(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& w) const override {
    problem_->heat_rate(t, temperature.data(), w.data());  // one ghost exchange
  }
  double dt_limit(const std::string& estimate) const override;
  bool all_ranks(bool mine) const override;
  double max_all(double mine) const override;

  void build(bool symmetric) override { sys_.build(*problem_, symmetric, symmetric ? pc_ : std::string()); }
  void bind() override { sys_.bind(*problem_); }
  Index nodes() const override { return sys_.nodes(); }
  Index state_size() const override { return sys_.state_size(); }
  bool has_reaction() const override { return sys_.reacts(); }
  bool nonsymmetric() const override { return sys_.nonsymmetric(); }
  bool conserves() const override { return sys_.conserves(); }
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
  MatrixPtr make_jacobian_matrix(SUNContext ctx) const override;  // throws: no distributed KLU
  OdeCallbacks callbacks() override;
  long jacobian_evaluations() const override { return sys_.preconditioner_setups(); }  // P = I − γJ assemblies

 private:
  std::string pc_;
  const DistributedProblem* problem_ = nullptr;
  DistributedOde sys_;
};

}  // namespace frictherm::thermal::detail
