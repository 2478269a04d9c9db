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
  Eigen::VectorXd v(n), w(n);
  for (Index i = 0; i < n; ++i) {
    v[i] = ((i % 2) ? -1.0 : 1.0) + 0.1 * std::sin(0.7 * static_cast<double>(i));
  }
  v = free.cwiseProduct(v);
  double vn = v.norm();
  if (vn == 0.0) return 0.0;
  v /= vn;
  double lam = 0.0;
  for (int it = 0; it < iterations; ++it) {
    apply(v, w);
    lam = v.dot(w);  // Rayleigh quotient
    const double wn = w.norm();
    if (wn == 0.0) return 0.0;
    v = w / wn;
  }
  return lam;
}

double forward_euler_dt_limit(const Problem& problem, const std::string& estimate) {
  double lam = lambda_max_gershgorin(problem);
  if (estimate == "power") {
    lam = std::min(1.05 * lambda_max_power(problem), lam);
  } else if (estimate != "gershgorin") {
    throw std::invalid_argument("forward_euler_dt_limit: unknown estimate \"" + estimate +
                                "\" (valid: gershgorin, power)");
  }
  if (lam <= 0.0) return std::numeric_limits<double>::infinity();
  return 2.0 / lam;  // FE amplification |1 − dt·λ| ≤ 1
}

}  // namespace frictherm::thermal
