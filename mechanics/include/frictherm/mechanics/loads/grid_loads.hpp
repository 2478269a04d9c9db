#pragma once
// The loads of the grid update, written once for the serial Simulation
// (loads/particle_loads.cpp, simulation_particle_pass.cpp, simulation_fields.cpp apply_damping) and the
// decomposed step (distributed/usl_phases.cpp): point loads and tractions resolved to particles
// (ParticleLoad, loads.hpp) scattered into the nodal forces, their work, and the mass-proportional
// damping of the nodal momenta. Each engine passes its own storage (accessors), the arithmetic is here.
#include <frictherm/mechanics/time_function.hpp>
#include <frictherm/mechanics/types.hpp>

#include <cstdint>

namespace frictherm::mechanics {

/// The force of a load resolved to a particle at time t: F(t) = F scale(t) (N).
template <int Dim>
inline Vec<Dim> load_force(const Vec<Dim>& force, const TimeFunction& scale, double t) {
  return force * scale(t);
}

/// The external force's share of the nodal forces, f_i += S_ip F(t) over the loaded particle's
/// stencil (Nairn 2018 eq. 3 with an external force on the particle). `force_at(i)` is the nodal
/// force (a Vec<Dim> or an Eigen::Map of one) of stencil node i in the engine's numbering.
template <int Dim, class Stencil, class Indexer, class ForceAt>
inline void add_load_to_grid(const Stencil& stencil, const Indexer& index, const Vec<Dim>& F, ForceAt&& force_at) {
  stencil.for_each(index, [&](int i, double S, const Vec<Dim>&) { force_at(i) += S * F; });
}

/// The grid acceleration at a loaded particle, a_p = Σ_i S_ip a_i over its stencil of this step
/// (load_work's mean displacement). `acceleration_at(i)` is the nodal acceleration of stencil node i in
/// the engine's numbering (a Vec<Dim> or an Eigen::Map of one).
template <int Dim, class Stencil, class Indexer, class AccelerationAt>
inline Vec<Dim> load_point_acceleration(const Stencil& stencil, const Indexer& index, AccelerationAt&& acceleration_at) {
  Vec<Dim> a = Vec<Dim>::Zero();
  stencil.for_each(index, [&](int i, double S, const Vec<Dim>&) { a += S * acceleration_at(i); });
  return a;
}

/// The work of a load over a step (the energy books' external work; t the step's start, F = F(t) the
/// force the step applies): F · Δx̄_p, Δx̄_p = Δx_p − ½ dt² a_p = dt Σ_i S_ip ½(v_i^L + v_i^{n+1}), the
/// particle's displacement at the mean of its nodes' start (lumped) and end velocities (Δx_p = dt Σ_i
/// S_ip v_i^{n+1} its displacement in the step, a_p = Σ_i S_ip a_i its grid acceleration). The load
/// enters the grid as f_i = S_ip F, and the kinetic energy it gives a node over the step is exactly
/// f_i · ½(v_i^L + v_i^{n+1}) dt (½ m (v⁺² − v⁻²) = m Δv · v̄). Booked at the end velocity, F · Δx_p,
/// the work gained ½ dt F · Δv_p per step: a sum that telescopes under a constant load but under a
/// ramp adds ½ dt ∫ v dF, an O(dt) drift of the books' energy lost (the undamped oscillating block's
/// 0.25 ms preload ramp, 2.5 mm, C = 0.5: the books showed 8 % more heat than energy lost; docs/output.md). The
/// particle's own (FLIP) velocity is not used: it carries modes the grid does not see, and F · v_p dt
/// summed over a long run under a constant load drifted from F · Δx (the undamped oscillating block at
/// 1.25 mm, C = 0.0125: 190 mJ of an external work that should stay constant after the preload ramp).
template <int Dim>
inline double load_work(const Vec<Dim>& F, const Vec<Dim>& displacement, const Vec<Dim>& acceleration, double dt) {
  return F.dot(displacement - (0.5 * dt * dt) * acceleration);
}

/// Whether the mass-proportional damping acts in the step starting at t.
inline bool damping_active(double rate, double until, double t) { return rate > 0.0 && t < until; }

/// Mass-proportional damping at one node of one velocity field: f_d −= c p_d on the components a rigid
/// material does not drive (`driven`: bit d), taken at the step's start momentum, after the velocity
/// conditions (explicit: stable for c dt < 2). The work it removes, c p_d²/m dt per component (J), is
/// added to `removed` where the node's mass exceeds `min_mass`.
template <int Dim, class Force, class Momentum>
FRICTHERM_ALWAYS_INLINE void damp_node(Force&& force, const Momentum& momentum, double mass, std::uint8_t driven,
                                       double c, double dt, double min_mass, double& removed) {
  for (int d = 0; d < Dim; ++d) {
    if (driven & (1u << d)) continue;
    const double p = momentum[d];
    force[d] -= c * p;
    if (mass > min_mass) removed += c * p * p / mass * dt;
  }
}

}  // namespace frictherm::mechanics
