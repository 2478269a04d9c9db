#include "distributed_thermal_ode.hpp"

#include "frictherm/thermal/stability.hpp"

#include <limits>
#include <stdexcept>

namespace frictherm::thermal::detail {

std::string DistributedThermalOde::who(const std::string& integrator) const {
  return integrator + " (distributed, rank " + std::to_string(problem_->rank()) + ")";
}

std::string DistributedThermalOde::state_error(const Eigen::VectorXd& temperature,
                                               const Eigen::VectorXd* progress) const {
  const auto n = std::to_string(problem_->local_size());
  if (temperature.size() != problem_->local_size())
    return "temperature vector has " + std::to_string(temperature.size()) + " entries for " + n + " owned nodes";
  if (!temperature.allFinite()) return "temperature vector has a non-finite entry";
  if (progress == nullptr) return {};
  if (progress->size() != problem_->local_size())
    return "progress has " + std::to_string(progress->size()) + " entries for " + n + " owned nodes";
  if (progress->size() > 0 && !(progress->allFinite() && progress->minCoeff() >= 0.0 && progress->maxCoeff() <= 1.0))
    return "progress must be finite and in [0, 1]";
  return {};
}

void DistributedThermalOde::rhs(double t, const Eigen::VectorXd& temperature, Eigen::VectorXd& dTdt) const {
  problem_->heat_rate(t, temperature.data(), dTdt.data());  // w, then M⁻¹ w
  dTdt.array() /= problem_->mass().array();
}

double DistributedThermalOde::dt_limit(const std::string& estimate) const {
  // The serial rule (stability.hpp) on the global estimates (MPI_MAX, the power iteration's reductions).
  return forward_euler_dt_limit_of(problem_->lambda_max_gershgorin(), estimate,
                                   [this] { return problem_->lambda_max_power(); });
}

bool DistributedThermalOde::all_ranks(bool mine) const {
  int in = mine ? 1 : 0, out = 0;
  MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_MIN, problem_->comm());
  DistributedProblem::count_reductions(1);
  return out == 1;
}

double DistributedThermalOde::max_all(double mine) const {
  double out = 0.0;
  MPI_Allreduce(&mine, &out, 1, MPI_DOUBLE, MPI_MAX, problem_->comm());
  DistributedProblem::count_reductions(1);
  return out;
}

NVectorPtr DistributedThermalOde::make_vector(SUNContext ctx) const {
  long local = static_cast<long>(form_.state_size()), global = 0;  // [s ⊙ T; λ of the reacting nodes]
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_SUM, problem_->comm());
  DistributedProblem::count_reductions(1);
  return make_parallel_vector(problem_->comm(), form_.state_size(), static_cast<Index>(global), ctx);
}

MatrixPtr DistributedThermalOde::make_jacobian_matrix(SUNContext) const {
  throw std::logic_error("thermal (distributed): no sparse direct solver (klu) in the distributed solve");
}

OdeCallbacks DistributedThermalOde::callbacks() {
  OdeCallbacks c;
  c.rhs = &DistributedOde::rhs;
  c.jtimes = &DistributedOde::jtimes;
  c.psetup = &DistributedOde::psetup;  // the PETSc PC on P = I − γJ, or the reaction's blocks
  c.psolve = &DistributedOde::psolve;
  c.user_data = &form_;
  return c;
}

}  // namespace frictherm::thermal::detail
