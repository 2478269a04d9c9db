#pragma once
// The plane-strain (2D) particle kinematics and the Mie-Grüneisen / J2 and linear elastic (plane strain
// and plane stress) updates of Simulation::update_stress, written on scalars. The Eigen forms
// (mie_gruneisen.hpp, material.hpp) build 2×2 temporaries on the stack element by element and read
// them back as SSE pairs (GCC keeps the products out of line), which stalls store forwarding in the
// hottest loop of a PBX or sliding-block run; these functions keep every value in registers.
//
// They perform the same floating-point operations in the same order as the Eigen forms (no FMA
// contraction on baseline x86-64; two-term sums are exact to reorder as a + b = b + a), so results are
// bit-identical: tests/mechanics/test_plane_strain_update.cpp checks that bitwise. The one order that
// is not obvious is Eigen's vectorised squaredNorm of a column-major 2×2: (s00² + s01²) + (s10² + s11²).
#include <frictherm/mechanics/mie_gruneisen.hpp>

#include <cmath>
#include <limits>

namespace frictherm::mechanics {

/// Velocity gradient L = Σ_i v_i ⊗ G_ip of a 2D particle, kept as four scalars.
struct VelocityGradient2 {
  double l00 = 0.0, l01 = 0.0, l10 = 0.0, l11 = 0.0;
  void add(const Vec<2>& v, const Vec<2>& G) {
    l00 += v[0] * G[0];
    l01 += v[0] * G[1];
    l10 += v[1] * G[0];
    l11 += v[1] * G[1];
  }
  Mat<2> matrix() const {
    Mat<2> L;
    L << l00, l01, l10, l11;
    return L;
  }
};

/// F ← (I + dt L) F; returns det(I + dt L) (as Eigen's determinant: a00 a11 − a10 a01).
FRICTHERM_ALWAYS_INLINE double deformation_update_2d(const VelocityGradient2& L, double dt, Mat<2>& F) {
  const double a00 = 1.0 + dt * L.l00, a01 = 0.0 + dt * L.l01, a10 = 0.0 + dt * L.l10, a11 = 1.0 + dt * L.l11;
  const double f00 = F(0, 0), f01 = F(0, 1), f10 = F(1, 0), f11 = F(1, 1);
  F(0, 0) = a00 * f00 + a01 * f10;
  F(1, 0) = a10 * f00 + a11 * f10;
  F(0, 1) = a00 * f01 + a01 * f11;
  F(1, 1) = a10 * f01 + a11 * f11;
  return a00 * a11 - a10 * a01;
}

/// det F of a 2×2 (as Eigen's determinant).
inline double determinant_2d(const Mat<2>& F) { return F(0, 0) * F(1, 1) - F(1, 0) * F(0, 1); }

/// linear_elastic_update<2>(L, dt, lambda, mu, a, σ, σ_zz) (material.hpp) on scalars: the Jaumann-rotated
/// hypoelastic increment σ += (w σ − σ w) + 2μ dε + λ tr(dε) I, dε = sym(L) dt, w = skew(L) dt; plane
/// stress with λ* = 2λμ/(λ + 2μ) and σ_zz untouched, plane strain σ_zz += λ tr(dε). Same operations in
/// the same order as the Eigen form (tests/mechanics/test_plane_strain_update.cpp checks it bitwise).
FRICTHERM_ALWAYS_INLINE void linear_elastic_update_2d(const VelocityGradient2& L, double dt, double lambda, double mu,
                                                      Analysis a, Mat<2>& sigma, double& sigma_zz) {
  const double de00 = 0.5 * (L.l00 + L.l00) * dt, de01 = 0.5 * (L.l01 + L.l10) * dt;
  const double de10 = 0.5 * (L.l10 + L.l01) * dt, de11 = 0.5 * (L.l11 + L.l11) * dt;
  const double w00 = 0.5 * (L.l00 - L.l00) * dt, w01 = 0.5 * (L.l01 - L.l10) * dt;
  const double w10 = 0.5 * (L.l10 - L.l01) * dt, w11 = 0.5 * (L.l11 - L.l11) * dt;
  const double tr = de00 + de11;
  const double lam = (a == Analysis::plane_stress) ? 2.0 * lambda * mu / (lambda + 2.0 * mu) : lambda;
  double s00 = sigma(0, 0), s01 = sigma(0, 1), s10 = sigma(1, 0), s11 = sigma(1, 1);
  const double r00 = (w00 * s00 + w01 * s10) - (s00 * w00 + s01 * w10);  // (w σ − σ w)_ij
  const double r01 = (w00 * s01 + w01 * s11) - (s00 * w01 + s01 * w11);
  const double r10 = (w10 * s00 + w11 * s10) - (s10 * w00 + s11 * w10);
  const double r11 = (w10 * s01 + w11 * s11) - (s10 * w01 + s11 * w11);
  s00 += r00, s01 += r01, s10 += r10, s11 += r11;
  const double two_mu = 2.0 * mu;
  s00 += two_mu * de00, s01 += two_mu * de01, s10 += two_mu * de10, s11 += two_mu * de11;
  s00 += lam * tr, s11 += lam * tr;
  sigma(0, 0) = s00, sigma(1, 0) = s10, sigma(0, 1) = s01, sigma(1, 1) = s11;
  if (a == Analysis::plane_strain) sigma_zz += lambda * tr;
}

/// mie_gruneisen_update<2>(L, dt, J, m, min_J, ...) on scalars; det_A = det(I + dt L) from
/// deformation_update_2d. Same contract: nothing changes and beyond_hugoniot_limit is returned when
/// J <= min_J (or J is not a number).
FRICTHERM_ALWAYS_INLINE MieGruneisenStatus mie_gruneisen_update_plane_strain(
    const VelocityGradient2& L, double dt, double J, double det_A, const MieGruneisenParams& m, double min_J,
    Mat<2>& sigma, double& sigma_zz, double& plastic_strain, double& energy, double& plastic_work,
    double& wave_speed) {
  plastic_work = 0.0;
  if (!(J > min_J)) return MieGruneisenStatus::beyond_hugoniot_limit;
  const double J_old = J / det_A;
  const double zz = sigma_zz;
  const double p_old = -(sigma(0, 0) + sigma(1, 1) + zz) * (1.0 / 3.0);
  double s00 = sigma(0, 0) + p_old, s01 = sigma(0, 1), s10 = sigma(1, 0), s11 = sigma(1, 1) + p_old;
  double s_zz = zz + p_old;

  // j2_deviatoric_update: the Jaumann-rotated trial deviator (linear_elastic_update with λ = −2G/3) ...
  const double G = m.shear_modulus;
  const double lambda = -2.0 * G / 3.0;
  const double de00 = 0.5 * (L.l00 + L.l00) * dt, de01 = 0.5 * (L.l01 + L.l10) * dt;
  const double de10 = 0.5 * (L.l10 + L.l01) * dt, de11 = 0.5 * (L.l11 + L.l11) * dt;
  const double w00 = 0.5 * (L.l00 - L.l00) * dt, w01 = 0.5 * (L.l01 - L.l10) * dt;
  const double w10 = 0.5 * (L.l10 - L.l01) * dt, w11 = 0.5 * (L.l11 - L.l11) * dt;
  const double tr = de00 + de11;
  const double r00 = (w00 * s00 + w01 * s10) - (s00 * w00 + s01 * w10);  // (w s − s w)_ij
  const double r01 = (w00 * s01 + w01 * s11) - (s00 * w01 + s01 * w11);
  const double r10 = (w10 * s00 + w11 * s10) - (s10 * w00 + s11 * w10);
  const double r11 = (w10 * s01 + w11 * s11) - (s10 * w01 + s11 * w11);
  s00 += r00, s01 += r01, s10 += r10, s11 += r11;
  const double two_mu = 2.0 * G;
  s00 += two_mu * de00, s01 += two_mu * de01, s10 += two_mu * de10, s11 += two_mu * de11;
  s00 += lambda * tr, s11 += lambda * tr;
  s_zz += lambda * tr;
  // ... then the radial return to the von Mises surface.
  double dep = 0.0, wp = 0.0;
  const double sy = m.yield_stress + m.hardening_modulus * plastic_strain;
  if (sy < std::numeric_limits<double>::infinity()) {
    const double ss = ((s00 * s00 + s01 * s01) + (s10 * s10 + s11 * s11)) + s_zz * s_zz;
    const double h = 3.0 * G + m.hardening_modulus;
    if (!(1.5 * ss <= sy * sy) && h > 0.0) {
      const double q = std::sqrt(1.5 * ss);
      dep = (q - sy) / h;
      const double scale = 1.0 - 3.0 * G * dep / q;
      s00 *= scale, s01 *= scale, s10 *= scale, s11 *= scale;
      s_zz *= scale;
      wp = (q - 3.0 * G * dep) * dep;
    }
  }
  plastic_strain += dep;
  plastic_work = wp;

  // Pressure and energy (mie_gruneisen_update).
  const double p = mie_gruneisen_energy_and_pressure(m, J, J_old, p_old, wp, energy, &wave_speed);
  sigma(0, 0) = s00 - p;
  sigma(1, 0) = s10;
  sigma(0, 1) = s01;
  sigma(1, 1) = s11 - p;
  sigma_zz = s_zz - p;
  return MieGruneisenStatus::ok;
}

}  // namespace frictherm::mechanics
