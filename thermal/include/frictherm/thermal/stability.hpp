// Explicit-stability estimates for M dT/dt = −(K + diag hA) T + … (thermal-notes §2).
// Forward Euler is stable iff dt ≤ 2/λmax(M⁻¹K_eff) (the spectrum is real and ≥ 0 since
// M⁻¹K_eff is similar to the symmetric M^{-1/2}K_eff M^{-1/2}).
#pragma once

#include "frictherm/thermal/problem.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::thermal {

// Gershgorin bound on the rows of M⁻¹K_eff over free (non-Dirichlet) nodes:
// λmax ≤ max_i (Σ_j |K_ij| + hA_i)/M_i. For zero-row-sum M-matrices this is 2·max_i K_ii/M_i,
// i.e. dt ≤ min_i M_i/K_ii; it is exact for 3/5/7-point FD with lumped boundary masses.
double lambda_max_gershgorin(const Problem& problem);

// The power iteration of lambda_max_power, written once for any storage (the serial Problem and the
// distributed one, whose dot products and norms are reduced over ranks): from v (zero on the fixed
// nodes, not normalised), `iterations` steps w = S v, λ = v·w, v = w/|w|; returns the last Rayleigh
// quotient (0 when v or some w vanishes).
template <class Vector, class Apply, class Dot, class Norm>
double power_iteration(Vector v, int iterations, Apply&& apply, Dot&& dot, Norm&& norm) {
  const double vn = norm(v);
  if (vn == 0.0) return 0.0;
  v /= vn;
  Vector w(v.size());
  double lam = 0.0;
  for (int it = 0; it < iterations; ++it) {
    apply(v, w);
    lam = dot(v, w);  // Rayleigh quotient
    const double wn = norm(w);
    if (wn == 0.0) return 0.0;
    v = w / wn;
  }
  return lam;
}

// The deterministic start vector's entry at node i (checkerboard-like plus a smooth part).
inline double power_iteration_start(Index i) {
  return ((i % 2) ? -1.0 : 1.0) + 0.1 * std::sin(0.7 * static_cast<double>(i));
}

// forward_euler_dt_limit from the Gershgorin bound and, for "power", the power iteration's λ (called
// only then): 2/λ with λ = min(1.05·λ_power, λ_gershgorin); +inf when λ ≤ 0.
template <class Power>
double forward_euler_dt_limit_of(double lambda_gershgorin, const std::string& estimate, Power&& lambda_power) {
  double lam = lambda_gershgorin;
  if (estimate == "power") {
    lam = std::min(1.05 * lambda_power(), lam);
  } else if (estimate != "gershgorin") {
    throw std::invalid_argument("forward_euler_dt_limit: unknown estimate \"" + estimate +
                                "\" (valid: gershgorin, power)");
  }
  if (lam <= 0.0) return std::numeric_limits<double>::infinity();
  return 2.0 / lam;  // FE amplification |1 − dt·λ| ≤ 1
}

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
