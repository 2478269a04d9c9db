#pragma once
// The grid-to-particle kernels of the transfer schemes (transfer.hpp), written once for the serial
// step (simulation_particle_pass.cpp, simulation_transfer.cpp) and the decomposed one
// (distributed/usl_phases.cpp, distributed/velocity_filter.cpp): a particle's velocity update under
// FLIP (with the PIC blend), XPIC and FMPM, and the two pieces of the filters' Neumann series
// v* = Σ_{j<order} (I − S⁺S)^j w0 (Hammerquist & Nairn 2017; Nairn & Hammerquist 2021): a particle's
// share of the round trip S⁺S and a node's next term.
#include <frictherm/mechanics/transfer.hpp>
#include <frictherm/mechanics/transfer/pic_blend.hpp>
#include <frictherm/mechanics/types.hpp>

#include <cstdint>

namespace frictherm::mechanics {

/// Particle velocity v_p (updated in place) from the grid: a = Σ S_ip a_i, v = Σ S_ip v_i^{n+1},
/// vf = Σ S_ip v*_i (XPIC/FMPM). FLIP: v_p += dt a, then the PIC blend of fraction `pic`; XPIC:
/// v_p = vf + dt a; FMPM: v_p = vf and the particle moves with it (v = vf). The position update is
/// x_p += dt v. Returns gravity's work on the particle over the step, m_p g · v̄ dt, v̄ the step's
/// mean velocity (FLIP: v_p + dt a / 2).
template <int Dim, class ParticleVelocity>
FRICTHERM_ALWAYS_INLINE double update_particle_velocity(ParticleUpdate update, double pic, double dt, double mp,
                                                        const Vec<Dim>& g, const Vec<Dim>& a, Vec<Dim>& v,
                                                        const Vec<Dim>& vf, ParticleVelocity&& vp) {
  const Vec<Dim> v_old = vp;
  if (update == ParticleUpdate::flip) {
    const double work = mp * g.dot(v_old + 0.5 * dt * a) * dt;
    vp += dt * a;
    pic_blend(vp, v, pic);
    return work;
  }
  if (update == ParticleUpdate::xpic) {
    vp = vf + dt * a;  // S (v* + Δt a): Hammerquist & Nairn 2017
  } else {
    vp = vf;  // S v*, v* ≈ M_C⁻¹ p^{n+1}: Nairn & Hammerquist 2021
    v = vf;
  }
  return mp * g.dot(0.5 * (v_old + vp)) * dt;
}

/// One particle's share of the round trip (S⁺S w)_i m_i = Σ_p S_ip m_p Σ_k S_kp w_k: u = Σ_k S_kp
/// term(k), then add(i, S_ip m_p u) for each of its nodes i.
template <int Dim, class Stencil, class Indexer, class Term, class Add>
FRICTHERM_ALWAYS_INLINE void filter_round_trip(const Stencil& s, const Indexer& ix, double mp, Term&& term, Add&& add) {
  Vec<Dim> u = Vec<Dim>::Zero();
  s.for_each(ix, [&](int i, double S, const Vec<Dim>&) { u += S * term(i); });
  const Vec<Dim> mu = mp * u;
  s.for_each(ix, [&](int i, double S, const Vec<Dim>&) { add(i, S * mu); });
}

/// A node's next term of the series, term − (S⁺S term) = term − round_trip / m (0 at a node of mass
/// m ≤ m_min), with the components a velocity condition holds (bit d of `conditions`) zero: v* keeps
/// w0 there.
template <int Dim>
FRICTHERM_ALWAYS_INLINE Vec<Dim> filter_next_term(const Vec<Dim>& term, const Vec<Dim>& round_trip, double m,
                                                  double m_min, std::uint8_t conditions) {
  Vec<Dim> next = m > m_min ? Vec<Dim>(term - round_trip / m) : Vec<Dim>(Vec<Dim>::Zero());
  if (conditions)
    for (int d = 0; d < Dim; ++d)
      if (conditions & (1u << d)) next[d] = 0.0;
  return next;
}

}  // namespace frictherm::mechanics
