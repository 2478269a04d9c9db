#pragma once
// The stress update of one particle (the constitutive switch), written once for the serial particle
// pass (simulation_particle_pass.cpp) and the decomposed stress_update (distributed/usl_phases.cpp):
// F ← (I + L dt) F, V = det(F) V0, then the material's stress: hypoelastic linear elastic (Jaumann),
// Neo-Hookean (Kakouris 2024 eq. 47) or Mie-Grüneisen pressure with J2 plasticity (mie_gruneisen.hpp;
// in 2D the plane-strain scalar form of plane_strain_update.hpp), which also update ε̄p, e, the
// plastic work V σ:Δε_p and the wave speed of the CFL step (time_step/cfl_time_step.hpp).
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/mie_gruneisen.hpp>
#include <frictherm/mechanics/plane_strain_update.hpp>
#include <frictherm/mechanics/small_products.hpp>

namespace frictherm::mechanics {

/// What the stress update needs of a material beyond its parameters, computed once per material
/// (not per particle).
struct StressLaw {
  MaterialKind kind = MaterialKind::linear_elastic;
  double lambda = 0.0, mu = 0.0;  // Lamé constants (linear elastic, Neo-Hookean)
  double c0 = 0.0;                // linear elastic: the P-wave speed (its wave speed at any state)
  double min_J = 0.0;             // Mie-Grüneisen: the limit of its Hugoniot (mie_gruneisen_min_J)
  bool mie_gruneisen() const { return kind == MaterialKind::mie_gruneisen; }
};

inline StressLaw stress_law(const Material& mat, Analysis an) {
  StressLaw law;
  law.kind = mat.kind;
  const bool mg = mat.kind == MaterialKind::mie_gruneisen;
  law.lambda = mat.lame_lambda(), law.mu = mat.shear_modulus();
  law.c0 = mat.kind == MaterialKind::linear_elastic ? mat.p_wave_speed(an) : 0.0;
  law.min_J = mg ? mie_gruneisen_min_J(mat.mie_gruneisen) : 0.0;
  return law;
}

/// One particle's state the stress update changes (references into the particle storage or locals).
template <int Dim>
struct StressState {
  Mat<Dim>& F;             // deformation gradient
  double& volume;          // V
  double initial_volume;   // V0
  Mat<Dim>& stress;        // σ
  double& stress_zz;       // σ_zz (plane strain)
  double& plastic_strain;  // ε̄p
  double& internal_energy; // Mie-Grüneisen: e (J/kg, mie_gruneisen.hpp); linear elastic: stress work (J/m^3 of V0)
  double& plastic_work;    // Σ V σ:Δε_p (J)
  double& wave_speed;      // c_p of the new state (m/s), for the CFL step
};

/// The stress power per unit current volume σ:L (= σ:D, σ symmetric; plane strain's σ_zz does no work,
/// D_zz = 0, and plane stress has σ_zz = 0), summed column by column in both forms below so that the
/// scalar 2D path gives the Eigen path's bits.
template <int Dim>
FRICTHERM_ALWAYS_INLINE double stress_power(const Mat<Dim>& sigma, const Mat<Dim>& L) {
  double p = 0.0;
  for (int j = 0; j < Dim; ++j)
    for (int i = 0; i < Dim; ++i) p += sigma(i, j) * L(i, j);
  return p;
}
FRICTHERM_ALWAYS_INLINE double stress_power(const Mat<2>& sigma, const VelocityGradient2& L) {
  double p = 0.0;
  p += sigma(0, 0) * L.l00;
  p += sigma(1, 0) * L.l10;
  p += sigma(0, 1) * L.l01;
  p += sigma(1, 1) * L.l11;
  return p;
}

/// A linear elastic particle's stored energy is the work its stress has done per unit reference volume
/// (StressState::internal_energy, J/m^3), the trapezoidal stress power over the step:
/// Δw = ½(σ_n:L + σ_{n+1}:L) dt · ½(J_n + J_{n+1}). The hypoelastic (Jaumann) law has no strain-energy
/// function: the closed form ½ σ:ε V the books used misses that work by about |ε|/3 of itself at a
/// strain ε (uniaxial: ½ ln²λ · λ against λ ln λ − λ + 1), 7 % at the PBX specimen's 20 % compaction,
/// and the books called the difference numerical dissipation.
FRICTHERM_ALWAYS_INLINE void add_stress_work(double power_old, double power_new, double dt, double J_old, double J_new,
                                             double& work) {
  work += 0.25 * (power_old + power_new) * dt * (J_old + J_new);
}

/// The update of a deformable particle from its velocity gradient L over dt; false: compressed past
/// its Hugoniot's limit (the state is then left as mie_gruneisen_update leaves it).
template <int Dim>
FRICTHERM_ALWAYS_INLINE bool update_stress(const Material& mat, const StressLaw& law, Analysis an, const Mat<Dim>& L,
                                           double dt, const StressState<Dim>& s) {
  const double J_old = s.volume / s.initial_volume;
  const Mat<Dim> A = Mat<Dim>::Identity() + dt * L;
  Mat<Dim> F_new;
  product_into<Dim>(A, s.F, F_new);  // F_new = A F, inlined (small_products.hpp)
  s.F = F_new;
  s.volume = s.F.determinant() * s.initial_volume;
  if (law.kind == MaterialKind::mie_gruneisen) {
    double wp = 0.0;  // plastic work per unit current volume (J/m^3)
    const bool ok = mie_gruneisen_update<Dim>(L, dt, s.volume / s.initial_volume, mat.mie_gruneisen, law.min_J, s.stress,
                                              s.stress_zz, s.plastic_strain, s.internal_energy, wp,
                                              &s.wave_speed) == MieGruneisenStatus::ok;
    s.plastic_work += wp * s.volume;
    return ok;
  }
  if (law.kind == MaterialKind::neo_hookean) {
    neo_hookean_stress<Dim>(s.F, law.lambda, law.mu, s.stress, s.stress_zz);
    s.wave_speed = mat.wave_speed(an, s.volume / s.initial_volume);
  } else {
    const double power_old = stress_power<Dim>(s.stress, L);
    linear_elastic_update<Dim>(L, dt, law.lambda, law.mu, an, s.stress, s.stress_zz);
    add_stress_work(power_old, stress_power<Dim>(s.stress, L), dt, J_old, s.volume / s.initial_volume,
                    s.internal_energy);
    s.wave_speed = law.c0;
  }
  return true;
}

/// The 2D Mie-Grüneisen update on scalars (the PBX path: plane_strain_update.hpp, the same arithmetic
/// as update_stress<2>). `params` best a local copy, so that the compiler hoists what depends on the
/// material only out of the particle loop.
FRICTHERM_ALWAYS_INLINE bool update_stress_plane_strain(const MieGruneisenParams& params, double min_J,
                                                        const VelocityGradient2& L, double dt,
                                                        const StressState<2>& s) {
  const double det_A = deformation_update_2d(L, dt, s.F);
  s.volume = determinant_2d(s.F) * s.initial_volume;
  double wp = 0.0;  // plastic work per unit current volume (J/m^3)
  const MieGruneisenStatus status =
      mie_gruneisen_update_plane_strain(L, dt, s.volume / s.initial_volume, det_A, params, min_J, s.stress, s.stress_zz,
                                        s.plastic_strain, s.internal_energy, wp, s.wave_speed);
  s.plastic_work += wp * s.volume;
  return status == MieGruneisenStatus::ok;
}

/// The 2D linear elastic update on scalars (plane_strain_update.hpp, the same arithmetic as
/// update_stress<2> for a linear elastic material, plane strain or plane stress).
FRICTHERM_ALWAYS_INLINE void update_stress_linear_elastic_2d(const StressLaw& law, Analysis an, const VelocityGradient2& L,
                                                             double dt, const StressState<2>& s) {
  const double J_old = s.volume / s.initial_volume;
  const double power_old = stress_power(s.stress, L);
  deformation_update_2d(L, dt, s.F);
  s.volume = determinant_2d(s.F) * s.initial_volume;
  linear_elastic_update_2d(L, dt, law.lambda, law.mu, an, s.stress, s.stress_zz);
  add_stress_work(power_old, stress_power(s.stress, L), dt, J_old, s.volume / s.initial_volume, s.internal_energy);
  s.wave_speed = law.c0;
}

}  // namespace frictherm::mechanics
