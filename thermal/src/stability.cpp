#include "frictherm/thermal/stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::thermal {

double lambda_max_gershgorin(const Problem& problem) {
  const auto& k = problem.conductance();
  const auto& m = problem.mass();
  const auto& ha = problem.convection_coefficients();
  double lam = 0.0;
  for (Index i = 0; i < problem.size(); ++i) {
    if (problem.is_dirichlet(i)) continue;  // rows with dT/dt = 0 contribute λ = 0
    double row = ha[i];
    for (SparseMatrix::InnerIterator it(k, i); it; ++it) row += std::abs(it.value());
    lam = std::max(lam, row / m[i]);  // Gershgorin disc of row i of M⁻¹K_eff
  }
  return lam;
}

double lambda_max_power(const Problem& problem, int iterations) {
  const Index n = problem.size();
  const auto& k = problem.conductance();
  const Eigen::VectorXd rsm = problem.mass().cwiseSqrt().cwiseInverse();  // M^{-1/2}
  const auto& ha = problem.convection_coefficients();
  Eigen::VectorXd free = Eigen::VectorXd::Ones(n);
  for (Index d : problem.dirichlet_nodes()) free[d] = 0.0;
  // S v = P M^{-1/2} (K + diag hA) M^{-1/2} P v with P the projector on free nodes.
  auto apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
    const Eigen::VectorXd u = rsm.cwiseProduct(free.cwiseProduct(v));
    out = k * u + ha.cwiseProduct(u);
    out = free.cwiseProduct(rsm.cwiseProduct(out));
  };
  Eigen::VectorXd v(n);
  for (Index i = 0; i < n; ++i) v[i] = power_iteration_start(i);
  return power_iteration(
      Eigen::VectorXd(free.cwiseProduct(v)), iterations, apply,
      [](const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return a.dot(b); },
      [](const Eigen::VectorXd& a) { return a.norm(); });
}

double forward_euler_dt_limit(const Problem& problem, const std::string& estimate) {
  return forward_euler_dt_limit_of(lambda_max_gershgorin(problem), estimate,
                                   [&] { return lambda_max_power(problem); });
}

}  // namespace frictherm::thermal
