#pragma once
// Mie-Grüneisen pressure with hypoelastic shear and J2 (von Mises) plasticity: the HMX and binder
// materials of the PBX study (Nairn, Bardenhagen & Smith, §3 and table 1; Wilkins, "Computer
// Simulation of Dynamic Phenomena", 1999). Header-only inline functions: they run in particle loops,
// allocate nothing and make no virtual calls. See docs/materials.md.
//
// Notation: J = V/V0 (det F; plane strain F_zz = 1), η = 1 − J = 1 − ρ0/ρ, μ = ρ/ρ0 − 1 = 1/J − 1,
// e = specific internal energy (J/kg) measured from the reference state (ρ0, initial temperature).
//
//   Shock velocity fit (Steinberg form, S2 dimensionless):  U_s = C0 + S1 u_p + S2 u_p²/U_s
//   with mass conservation u_p = η U_s this gives U_s = C0 / d(η), d(η) = 1 − S1 η − S2 η², and
//   Hugoniot           p_H(η) = ρ0 U_s u_p = ρ0 C0² η / d(η)²                    (η > 0)
//   Mie-Grüneisen      p = p_H (1 − γ0 η / 2) + γ0 ρ0 e        (ρΓ = ρ0 γ0; e_H = p_H η/(2ρ0))
//   tension            p = ρ0 C0² μ + γ0 ρ0 e                                     (η ≤ 0)
//   bulk sound speed   c² = ∂p/∂ρ|_s = (J²/ρ0) (∂p/∂η|_e + γ0 p)
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/types.hpp>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

/// The smallest J the Hugoniot admits: d(η) = 1 − S1 η − S2 η² first vanishes at η* and p_H → ∞
/// there (the limiting shock compression ρ/ρ0 = 1/(1 − η*)). Returns 1 − η* or 0 if d > 0 on (0, 1).
inline double mie_gruneisen_min_J(const MieGruneisenParams& m) {
  double eta = 1.0;  // smallest root of S2 η² + S1 η − 1 = 0 in (0, 1)
  if (m.S2 == 0.0) {
    if (m.S1 > 1.0) eta = 1.0 / m.S1;
  } else {
    const double disc = m.S1 * m.S1 + 4.0 * m.S2;
    if (disc >= 0.0) {
      const double q = -0.5 * (m.S1 + std::copysign(std::sqrt(disc), m.S1));
      const double r[2] = {q / m.S2, q != 0.0 ? -1.0 / q : -1.0};
      for (double x : r)
        if (x > 0.0 && x < eta) eta = x;
    }
  }
  return 1.0 - eta;
}

/// Throws std::invalid_argument naming the offending parameter ("<context>.<name>: expected ..., got ...").
/// An equation of state has no plane-stress form: Analysis::plane_stress is rejected too.
inline void validate(const MieGruneisenParams& m, Analysis a, const std::string& context = "mie_gruneisen") {
  auto fail = [&](const char* name, const char* expected, double got) {
    std::ostringstream os;
    os.precision(12);
    os << context << "." << name << ": expected " << expected << ", got " << got;
    throw std::invalid_argument(os.str());
  };
  auto finite = [](double x) { return std::isfinite(x); };
  if (!(finite(m.density) && m.density > 0.0)) fail("density", "a finite number > 0 (kg/m^3)", m.density);
  if (!(finite(m.C0) && m.C0 > 0.0)) fail("C0", "a finite number > 0 (m/s)", m.C0);
  if (!finite(m.S1)) fail("S1", "a finite number", m.S1);
  if (!finite(m.S2)) fail("S2", "a finite number", m.S2);
  if (!(finite(m.gamma0) && m.gamma0 >= 0.0)) fail("gamma0", "a finite number >= 0", m.gamma0);
  if (!(finite(m.shear_modulus) && m.shear_modulus >= 0.0))
    fail("shear_modulus", "a finite number >= 0 (Pa)", m.shear_modulus);
  if (!(m.yield_stress > 0.0)) fail("yield_stress", "a number > 0 (Pa), or infinity for no yielding", m.yield_stress);
  if (!(finite(m.hardening_modulus) && m.hardening_modulus >= 0.0))
    fail("hardening_modulus", "a finite number >= 0 (Pa)", m.hardening_modulus);
  if (mie_gruneisen_min_J(m) > 0.9)
    fail("S1", "S1, S2 whose Hugoniot stays finite to 10 % compression (1 - S1 eta - S2 eta^2 > 0 for eta <= 0.1)", m.S1);
  if (a == Analysis::plane_stress)
    throw std::invalid_argument(context + ": a Mie-Gruneisen material needs a plane_strain or three_d analysis, not plane_stress");
}

/// Hugoniot pressure p_H(J) = ρ0 C0² η / (1 − S1 η − S2 η²)² for η = 1 − J > 0 (compression only).
inline double hugoniot_pressure(const MieGruneisenParams& m, double J) {
  const double eta = 1.0 - J;
  const double d = 1.0 - eta * (m.S1 + m.S2 * eta);
  return m.density * m.C0 * m.C0 * eta / (d * d);
}

/// Pressure, its derivative and the bulk sound speed at (J, e).
struct MieGruneisenState {
  double pressure = 0.0;     // p (Pa), positive in compression
  double dp_deta = 0.0;      // ∂p/∂η at constant e (Pa), η = 1 − J
  double sound_speed = 0.0;  // bulk (isentropic) sound speed c = sqrt(∂p/∂ρ|_s) (m/s), 0 if c² < 0
};

/// The energy-independent part f(η) of p = f(η) + γ0 ρ0 e and its derivative f'(η).
FRICTHERM_ALWAYS_INLINE void mie_gruneisen_reference_part(const MieGruneisenParams& m, double J, double& f, double& df) {
  const double eta = 1.0 - J;
  const double rc2 = m.density * m.C0 * m.C0;
  if (eta > 0.0) {  // compression: p_H (1 − γ0 η/2)
    const double d = 1.0 - eta * (m.S1 + m.S2 * eta);
    const double dd = -(m.S1 + 2.0 * m.S2 * eta);
    const double g = 1.0 - 0.5 * m.gamma0 * eta;
    // One division: the stress update of a PBX is bound by the divider, not by multiplications.
    const double inv_d = 1.0 / d, inv_d2 = inv_d * inv_d;
    f = rc2 * eta * g * inv_d2;
    df = rc2 * ((1.0 - m.gamma0 * eta) * inv_d2 - 2.0 * eta * g * dd * inv_d2 * inv_d);
  } else {  // tension: ρ0 C0² μ, μ = 1/J − 1, dμ/dη = 1/J²
    const double inv_J = 1.0 / J;
    f = rc2 * (inv_J - 1.0);
    df = rc2 * inv_J * inv_J;
  }
}

/// The bulk sound speed squared c² = (J²/ρ0)(∂p/∂η|_e + γ0 p), negative values clipped to 0 (a state
/// without a real sound speed), and the dilatational wave speed sqrt(c² + (4/3) G J/ρ0) from it.
/// inv_density = 1/ρ0.
FRICTHERM_ALWAYS_INLINE double mie_gruneisen_sound_speed_squared(const MieGruneisenParams& m, double inv_density,
                                                                 double J, double df, double p) {
  const double c2 = J * J * inv_density * (df + m.gamma0 * p);
  return c2 > 0.0 ? c2 : 0.0;
}
FRICTHERM_ALWAYS_INLINE double mie_gruneisen_wave_speed_from(const MieGruneisenParams& m, double inv_density,
                                                             double J, double c2) {
  return std::sqrt(c2 + 4.0 / 3.0 * m.shear_modulus * J * inv_density);
}

/// Mie-Grüneisen pressure and bulk sound speed at volume ratio J and specific internal energy e (J/kg).
/// Compression needs J > mie_gruneisen_min_J(m).
inline MieGruneisenState mie_gruneisen_eos(const MieGruneisenParams& m, double J, double e) {
  double f = 0.0, df = 0.0;
  mie_gruneisen_reference_part(m, J, f, df);
  MieGruneisenState s;
  s.pressure = f + m.gamma0 * m.density * e;
  s.dp_deta = df;
  s.sound_speed = std::sqrt(mie_gruneisen_sound_speed_squared(m, 1.0 / m.density, J, df, s.pressure));
  return s;
}

/// Dilatational wave speed for the CFL time step: sqrt(c² + (4/3) G/ρ) with ρ = ρ0/J.
inline double mie_gruneisen_wave_speed(const MieGruneisenParams& m, double J, double e) {
  double f = 0.0, df = 0.0;
  mie_gruneisen_reference_part(m, J, f, df);
  const double inv_density = 1.0 / m.density;
  const double p = f + m.gamma0 * m.density * e;
  return mie_gruneisen_wave_speed_from(m, inv_density, J, mie_gruneisen_sound_speed_squared(m, inv_density, J, df, p));
}

/// One step of plastic flow: equivalent plastic strain increment Δε̄p and plastic work per unit
/// current volume σ:Δε_p (J/m^3); the plastic heat of a particle is β σ:Δε_p V_p (Taylor–Quinney β).
struct J2Increment {
  double plastic_strain = 0.0;
  double plastic_work = 0.0;
};

/// Deviatoric stress update: Jaumann-rotated hypoelastic trial s + 2G dev(sym(L) dt) (by the very
/// linear_elastic_update of material.hpp with λ = −2G/3), then radial return to the von Mises surface
/// q = sqrt(3/2 s:s) = σ_y + H ε̄p (backward Euler, exact for linear hardening):
///   Δε̄p = (q_trial − σ_y(ε̄p)) / (3G + H),  s ← s_trial (1 − 3G Δε̄p / q_trial),
///   Δε_p = (3/2) Δε̄p s/q,  σ:Δε_p = q Δε̄p (q after the return).
/// 2D is plane strain: s_zz is the out-of-plane deviator (dε_zz = 0); in 3D s_zz is unused.
template <int Dim>
FRICTHERM_ALWAYS_INLINE J2Increment j2_deviatoric_update(const Mat<Dim>& L, double dt, double G, double yield_stress,
                                        double hardening, double plastic_strain, Mat<Dim>& s, double& s_zz) {
  constexpr Analysis an = Dim == 2 ? Analysis::plane_strain : Analysis::three_d;
  linear_elastic_update<Dim>(L, dt, -2.0 * G / 3.0, G, an, s, s_zz);
  J2Increment inc;
  const double sy = yield_stress + hardening * plastic_strain;
  if (!(sy < std::numeric_limits<double>::infinity())) return inc;
  const double ss = s.squaredNorm() + (Dim == 2 ? s_zz * s_zz : 0.0);
  const double h = 3.0 * G + hardening;
  if (1.5 * ss <= sy * sy || !(h > 0.0)) return inc;  // q <= σ_y (sy >= 0): no square root while elastic
  const double q = std::sqrt(1.5 * ss);
  const double dep = (q - sy) / h;
  const double scale = 1.0 - 3.0 * G * dep / q;
  s *= scale;
  if (Dim == 2) s_zz *= scale;
  inc.plastic_strain = dep;
  inc.plastic_work = (q - 3.0 * G * dep) * dep;  // = σ_y(ε̄p + Δε̄p) Δε̄p
  return inc;
}

/// The end of a step's update, shared by mie_gruneisen_update and its plane-strain scalar form: the
/// specific energy by the trapezoidal pressure work −½(p_n + p_{n+1}) ΔJ/ρ0 plus the plastic work
/// (J/ρ0) σ:Δε_p, solved in closed form since p = f(J) + γ0 ρ0 e is linear in e; returns p_{n+1} and,
/// if asked, the wave speed of the new state (as mie_gruneisen_wave_speed). wp: σ:Δε_p per unit
/// current volume. Divisions are few on purpose: the PBX stress update is bound by the divider.
FRICTHERM_ALWAYS_INLINE double mie_gruneisen_energy_and_pressure(const MieGruneisenParams& m, double J, double J_old,
                                                                 double p_old, double wp, double& energy,
                                                                 double* wave_speed) {
  double f = 0.0, df = 0.0;
  mie_gruneisen_reference_part(m, J, f, df);
  const double inv_density = 1.0 / m.density;  // hoisted out of particle loops over one material
  const double dJ = J - J_old;
  energy = (energy - (0.5 * (p_old + f) * dJ - wp * J) * inv_density) / (1.0 + 0.5 * m.gamma0 * dJ);
  const double p = f + m.gamma0 * m.density * energy;
  if (wave_speed)
    *wave_speed = mie_gruneisen_wave_speed_from(m, inv_density, J, mie_gruneisen_sound_speed_squared(m, inv_density, J, df, p));
  return p;
}

/// Status of one particle update.
enum class MieGruneisenStatus { ok, beyond_hugoniot_limit };

/// The per-particle entry point for Simulation::update_stress. Given the velocity gradient L over the
/// step dt and the NEW volume ratio J = det F (after F ← (I + dt L) F), updates in place
///   sigma, sigma_zz   total Cauchy stress (plane strain σ_zz in 2D, ignored and left 0 in 3D),
///   plastic_strain    equivalent plastic strain ε̄p,
///   energy            specific internal energy e (J/kg): trapezoidal pressure work −½(p_n + p_{n+1}) ΔJ/ρ0
///                     plus the plastic work (J/ρ0) σ:Δε_p, solved in closed form since p is linear in e;
///                     elastic shear energy is stored, not added to e,
/// and returns in plastic_work the step's σ:Δε_p per unit current volume (J/m^3) and, if asked, in
/// wave_speed the dilatational wave speed of the new state (as mie_gruneisen_wave_speed, for the CFL step).
/// J_old = J / det(I + dt L). If J is at or beyond the Hugoniot limit (J <= mie_gruneisen_min_J, or
/// J <= 0) nothing is changed and beyond_hugoniot_limit is returned.
/// min_J = mie_gruneisen_min_J(m), a constant of the material: the particle loop passes it in rather
/// than solving the quadratic (a square root and two divisions) for every particle.
template <int Dim>
FRICTHERM_ALWAYS_INLINE MieGruneisenStatus mie_gruneisen_update(const Mat<Dim>& L, double dt, double J,
                                                                const MieGruneisenParams& m, double min_J,
                                                                Mat<Dim>& sigma, double& sigma_zz,
                                                                double& plastic_strain, double& energy,
                                                                double& plastic_work, double* wave_speed) {
  plastic_work = 0.0;
  if (!(J > min_J)) return MieGruneisenStatus::beyond_hugoniot_limit;  // also J <= 0, NaN
  const double J_old = J / (Mat<Dim>::Identity() + dt * L).determinant();
  const double zz = Dim == 2 ? sigma_zz : 0.0;
  const double p_old = -(sigma.trace() + zz) * (1.0 / 3.0);
  Mat<Dim> s = sigma;
  s.diagonal().array() += p_old;
  double s_zz = zz + p_old;
  const J2Increment inc =
      j2_deviatoric_update<Dim>(L, dt, m.shear_modulus, m.yield_stress, m.hardening_modulus, plastic_strain, s, s_zz);
  plastic_strain += inc.plastic_strain;
  plastic_work = inc.plastic_work;
  const double p = mie_gruneisen_energy_and_pressure(m, J, J_old, p_old, inc.plastic_work, energy, wave_speed);
  sigma = s;
  sigma.diagonal().array() -= p;
  sigma_zz = Dim == 2 ? s_zz - p : 0.0;
  return MieGruneisenStatus::ok;
}

/// Same, solving for the material's limit J itself.
template <int Dim>
inline MieGruneisenStatus mie_gruneisen_update(const Mat<Dim>& L, double dt, double J, const MieGruneisenParams& m,
                                               Mat<Dim>& sigma, double& sigma_zz, double& plastic_strain,
                                               double& energy, double& plastic_work,
                                               double* wave_speed = nullptr) {
  return mie_gruneisen_update<Dim>(L, dt, J, m, mie_gruneisen_min_J(m), sigma, sigma_zz, plastic_strain, energy,
                                   plastic_work, wave_speed);
}

}  // namespace frictherm::mechanics
