#pragma once
// Rigid sliding block of Nairn, Bardenhagen & Smith (2018), appendix eqs. 46–54: a block of height h
// and density rho under normal stress N, pushed by a tangential stress S(t) = R N (t − t2)/ts for
// t > t2 (ts = tf − t2), sliding with S_slide = (mu_d + k v) N + S_a once S reaches mu_s N + S_a.
#include <cmath>

namespace frictherm::verification {

struct RigidBlock {
  double rho = 1000.0, h = 0.015, l = 0.04, b = 0.001;  // density, height, length, thickness (SI)
  double N = 0.0;                                       // normal stress (Pa)
  double R = 1.0, t2 = 0.0, ts = 1.0;                  // tangential ramp: S = R N (t − t2)/ts
  double mu_s = 0.2, mu_d = 0.2, k = 0.0, S_a = 0.0;   // friction law (eq. 41)

  double onset() const { return t2 + (mu_s + S_a / N) * ts / R; }  // eq. 47
  double alpha() const { return R * N / (rho * h * ts); }           // eq. 49
  double beta() const { return (mu_s - mu_d) * N / (rho * h); }
  double gamma() const { return k * N / (rho * h); }

  /// Block velocity (eq. 50).
  double velocity(double t) const {
    const double T = t - onset();
    if (T <= 0.0) return 0.0;
    const double a = alpha(), be = beta(), g = gamma();
    if (k == 0.0) return 0.5 * a * T * T + be * T;
    const double psi = a / g, phi = (be - psi) / g;  // eq. 51
    return psi * T + phi * (1.0 - std::exp(-g * T));
  }

  /// Sliding distance since onset (integral of eq. 50).
  double distance(double t) const {
    const double T = t - onset();
    if (T <= 0.0) return 0.0;
    const double a = alpha(), be = beta(), g = gamma();
    if (k == 0.0) return a * T * T * T / 6.0 + 0.5 * be * T * T;
    const double psi = a / g, phi = (be - psi) / g;
    return 0.5 * psi * T * T + phi * (T - (1.0 - std::exp(-g * T)) / g);
  }

  /// Total friction work Q (J) (eqs. 52–54).
  double friction_work(double t) const {
    const double T = t - onset();
    if (T <= 0.0) return 0.0;
    const double a = alpha(), be = beta(), g = gamma();
    const double c = mu_d * N + S_a;
    if (k == 0.0) return l * b * c * (a * T * T * T / 6.0 + 0.5 * be * T * T);  // eq. 53
    const double psi = a / g, phi = (be - psi) / g, e1 = std::exp(-g * T), e2 = std::exp(-2.0 * g * T);
    // The first bracket is ∫v dt = ½ψT² + φ(T − (1 − e^{−γT})/γ); the printed eq. 54 swaps ψ and φ
    // there (its kN term, ∫v² dt, is right). The test checks both terms against quadrature.
    const double q = c * (0.5 * psi * T * T + phi * (T - (1.0 - e1) / g)) +
                     k * N *
                         (psi * psi * T * T * T / 3.0 + phi * phi * (T - (3.0 - 4.0 * e1 + e2) / (2.0 * g)) +
                          psi * phi * (T * T - 2.0 / (g * g) * (1.0 - (1.0 + T * g) * e1)));  // eq. 54
    return l * b * q;
  }
};

}  // namespace frictherm::verification
