#pragma once
// The order of the MPM step's phases, written once for the serial and the decomposed engine (issue 32,
// "decomposition as phases, not as a second engine"; docs/step.md). add_scheme_phases walks the step
// of an update scheme (USF, USL, MUSL) and hands each point of it to the engine: the engine's own core
// phases (SchemePhase), the components' hooks (contact methods, loads, velocity filters, rigid drivers)
// and the exchange points of a decomposed run (ExchangeHook). The serial engine
// (simulation_step.cpp build_phases) adds nothing at an exchange point; the decomposed one
// (distributed/phase_lists.cpp) adds its sums to the owners, ghost updates and migration there (its
// point loads and tractions stay inside its particle_to_grid and internal_forces, added before the
// sums). An engine adds nothing at a point it does not act on.
#include <frictherm/mechanics/step/contact_method.hpp>
#include <frictherm/mechanics/step/rigid_driver.hpp>
#include <frictherm/mechanics/step/step_load.hpp>
#include <frictherm/mechanics/step/velocity_filter.hpp>

namespace frictherm::mechanics {

/// The engine's own phases of the step.
enum class SchemePhase {
  time_step,               // the CFL step
  shape_functions,         // the step's stencils
  extended_stencils,       // the extended B-spline basis (after the rigid drivers: it keeps the driven nodes)
  particle_to_grid,        // m, p (USL/MUSL: and f) from the particles (Nairn 2018 eqs. 1–3)
  velocity_from_momentum,  // USF, MUSL: the velocity conditions on p, then v = p/m
  stress_update,           // USF, MUSL: the stress from the grid velocities
  internal_forces,         // USF: f from the updated stress
  velocity_conditions,     // fixed and driven components of p and f
  momentum_update,         // p^{n+1} = p^n + f dt
  nodal_velocities,        // v^{n+1} = p^{n+1}/m, a = f/m
  particle_update,         // USL: grid-to-particle and the stress update from v^{n+1}
  grid_to_particle,        // USF, MUSL: grid-to-particle
  end_particle_update,     // the particle pass's checks and the step's end
  remap_momentum,          // MUSL: p from the updated particles
};

/// The exchange points of a decomposed step (none in a serial one).
enum class ExchangeHook {
  projected,   // after particle_to_grid: the ranks' nodal sums to the nodes' owners, per-material entries
  forces,      // USF after internal_forces: the forces to the owners
  velocities,  // a grid velocity the stress update or the particles read is on the owned nodes: to the ghosts
  remapped,    // MUSL after remap_momentum: the remapped momenta to the owners
  migrate,     // the step's end: particles that left a rank's box to the rank that holds them now
};

/// Hands the points of the step of the update scheme (USF when `usf`, MUSL when `musl`, else USL) to
/// `engine` in order: engine(SchemePhase), engine(ContactHook), engine(LoadHook), engine(FilterHook),
/// engine(RigidHook), engine(ExchangeHook).
/// USF: the stress from the extrapolated grid velocities, then the forces; USL: the forces from the
/// start-of-step stress, the stress after the grid update (with grid-to-particle in one pass); MUSL: as
/// USL, then the momenta remapped from the updated particles and the stress from their velocities.
template <class Engine>
void add_scheme_phases(bool usf, bool musl, Engine& engine) {
  const bool usl = !usf && !musl;
  using P = SchemePhase;
  engine(P::time_step);
  engine(P::shape_functions);
  engine(RigidHook::drive);
  engine(P::extended_stencils);
  engine(P::particle_to_grid);
  engine(ExchangeHook::projected);
  engine(ContactHook::extrapolated);
  if (usf) {
    engine(P::velocity_from_momentum);
    engine(ContactHook::stress_velocity);
    engine(ExchangeHook::velocities);
    engine(P::stress_update);
    engine(P::internal_forces);
    engine(ExchangeHook::forces);
  }
  engine(LoadHook::forces);
  engine(ContactHook::forces);
  engine(FilterHook::start_velocity);
  engine(P::velocity_conditions);
  engine(LoadHook::conditioned_forces);
  engine(P::momentum_update);
  engine(ContactHook::updated);
  engine(P::nodal_velocities);
  engine(ExchangeHook::velocities);
  engine(FilterHook::velocities);
  engine(RigidHook::particle_update);
  if (usl) {
    engine(P::particle_update);
    engine(ContactHook::stress_velocity);
  } else {
    engine(P::grid_to_particle);
  }
  engine(RigidHook::moved);
  engine(P::end_particle_update);
  if (musl) {
    engine(P::remap_momentum);
    engine(ExchangeHook::remapped);
    engine(ContactHook::remapped);
    engine(P::velocity_from_momentum);
    engine(ContactHook::stress_velocity);
    engine(ExchangeHook::velocities);
    engine(P::stress_update);
  }
  engine(ExchangeHook::migrate);
}

}  // namespace frictherm::mechanics
