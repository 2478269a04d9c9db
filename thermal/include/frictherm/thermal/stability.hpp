// Explicit-stability estimates for M dT/dt = −(K + diag hA) T + … (thermal-notes §2).
// Forward Euler is stable iff dt ≤ 2/λmax(M⁻¹K_eff) (the spectrum is real and ≥ 0 since
// M⁻¹K_eff is similar to the symmetric M^{-1/2}K_eff M^{-1/2}).
#pragma once

#include "frictherm/thermal/problem.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace frictherm::thermal {

// Gershgorin bound on the rows of M⁻¹K_eff over free (non-Dirichlet) nodes:
// λmax ≤ max_i (Σ_j |K_ij| + hA_i)/M_i. For zero-row-sum M-matrices this is 2·max_i K_ii/M_i,
// i.e. dt ≤ min_i M_i/K_ii; it is exact for 3/5/7-point FD with lumped boundary masses.
double lambda_max_gershgorin(const Problem& problem);

// Power iteration on the symmetric M^{-1/2}K_eff M^{-1/2} restricted to free nodes; returns
// the Rayleigh quotient after `iterations` steps (a lower bound on λmax that converges from
// below). Deterministic start vector (checkerboard-like plus a smooth part).
double lambda_max_power(const Problem& problem, int iterations = 200);

// Forward Euler limit 2/λ for the chosen estimate: "gershgorin" or "power". For "power"
// λ = min(1.05·λ_power, λ_gershgorin): a 5 % margin for the iteration's underestimate.
// Returns +inf when λ = 0 (no conduction or everything fixed).
double forward_euler_dt_limit(const Problem& problem, const std::string& estimate = "gershgorin");

// Forward Euler sub-steps for a window dt: stable under the bound lambda (h ≤ safety · 2/λ; λ ≤ 0: no
// limit) and no longer than max_dt when max_dt > 0 (IntegratorOptions::fe_max_dt).
inline long forward_euler_substeps(double dt, double lambda, double safety, double max_dt) {
  long n = 1;
  if (lambda > 0.0) n = std::max(n, static_cast<long>(std::ceil(dt / (safety * 2.0 / lambda) - 1e-12)));
  if (max_dt > 0.0) n = std::max(n, static_cast<long>(std::ceil(dt / max_dt - 1e-12)));
  return n;
}

}  // namespace frictherm::thermal
