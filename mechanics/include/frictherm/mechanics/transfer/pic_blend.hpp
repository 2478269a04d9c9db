#pragma once
// The FLIP/PIC blend of the grid-to-particle update, written once for the serial particle pass
// (simulation_particle_pass.cpp) and the decomposed grid_to_particle (distributed/usl_phases.cpp).
#include <frictherm/mechanics/types.hpp>

#include <cmath>

namespace frictherm::mechanics {

/// The PIC fraction of a step dt for a relaxation time τ: α = 1 − e^(−dt/τ) (0 without τ, pure
/// FLIP), which damps the particle velocity modes the grid cannot see at a rate independent of dt.
inline double pic_blend_fraction(double dt, double relaxation_time) {
  return std::isfinite(relaxation_time) ? -std::expm1(-dt / relaxation_time) : 0.0;
}

/// v_p ← (1 − α) v_p + α Σ_i S_ip v_i^{n+1} (after the FLIP update v_p += dt Σ S_ip a_i); α = 0: unchanged.
template <class ParticleVelocity, class GridVelocity>
FRICTHERM_ALWAYS_INLINE void pic_blend(ParticleVelocity&& v_p, const GridVelocity& v_grid, double alpha) {
  if (alpha > 0.0) v_p = (1.0 - alpha) * v_p + alpha * v_grid;
}

}  // namespace frictherm::mechanics
