#pragma once
// Grid-to-particle transfer schemes: how the particles' velocities (and positions) are updated from
// the grid each step.
//
//   flip  v_p ← v_p + Δt Σ S_ip a_i, x_p ← x_p + Δt Σ S_ip v_i^{n+1} (optionally blended with PIC,
//         SimulationOptions::pic_relaxation_time).
//   xpic  XPIC(m) (Hammerquist & Nairn 2017): v_p ← Σ S_ip (v*_i + Δt a_i) with
//         v* = Σ_{j=0}^{m−1} (I − S⁺S)^j v^n, v^n the lumped grid velocity at the momentum update and
//         S⁺S the grid → particle → grid round trip (S⁺ = M_L⁻¹ Sᵀ M_p). On particle velocities this is
//         v_p ← [I − (I − S S⁺)^m] v_p + Δt S a: XPIC(1) is PIC, and as m → ∞ only the null-space part of
//         v_p (the noise the grid cannot see) is removed. Positions as FLIP.
//   fmpm  FMPM(k) (Nairn & Hammerquist 2021): the updated grid velocity from the momentum through the
//         order-k approximation of the full (consistent) mass matrix inverse,
//         M_C⁻¹ ≈ Σ_{j=0}^{k−1} (I − M_L⁻¹ M_C)^j M_L⁻¹ with M_L⁻¹ M_C = S⁺S, i.e.
//         v* = Σ_{j=0}^{k−1} (I − S⁺S)^j v^{n+1}; then v_p ← Σ S_ip v*_i and x_p ← x_p + Δt Σ S_ip v*_i.
//
// Both filters act per velocity field (with contact, per material) and conserve each field's
// momentum: Σ_i m_i (S⁺S w)_i = Σ_i m_i w_i. Velocity conditions are kept: at fixed and rigid-driven
// components every term j ≥ 1 of the series is zero, so v* keeps the lumped value there. Rigid
// fields are not filtered. Each order above 1 costs one grid → particle → grid sweep.
#include <string>

namespace frictherm::mechanics {

enum class ParticleUpdate { flip, xpic, fmpm };

ParticleUpdate particle_update_from_string(const std::string& name);  // "flip", "xpic", "fmpm"; throws std::invalid_argument
const char* to_string(ParticleUpdate u);

}  // namespace frictherm::mechanics
