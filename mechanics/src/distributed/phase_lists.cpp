// The decomposed step's phase lists (frictherm/mechanics/distributed.hpp): USL, MUSL and USF, each
// the serial list (mechanics/src/simulation_step.cpp) with the exchange phases inserted, run in order
// and timed per phase_names() entry. The phases are in usl_phases.cpp (the USL ones),
// scheme_phases.cpp (what MUSL and USF add), contact_phases.cpp, contact_extents.cpp,
// penalty_phases.cpp, sparse_exchange.cpp and decomposition.cpp (migrate).
#include "distributed/decomposed_state.hpp"

#include <mpi.h>

#include <vector>

namespace frictherm::mechanics {

template <int Dim>
const std::array<const char*, 18>& DecomposedMpm<Dim>::phase_names() {
  static const std::array<const char*, 18> names{
      {"particle_to_grid", "sum_to_owners", "exchange_field_ranges", "fields_to_owners", "find_contact_nodes",
       "contact_extrapolated", "momentum_update", "contact_updated", "nodal_velocities", "ghost_velocities",
       "fields_to_ghosts", "grid_to_particle", "stress_update", "migrate", "remap_momentum",
       "velocity_from_momentum", "penalty_forces", "move_boundary_points"}};
  return names;
}

template <int Dim>
void DecomposedMpm<Dim>::step(double dt) {
  Impl& s = *impl_;
  s.take_initial_energy();  // the energy books' start, once (energy_books.cpp)
  s.penalty_mass_current = false;  // the penalty weights' masses: gathered once in the step
  s.current_valid = false;  // the particles move: current_stencils() evaluates them again
  // The kernel's phases: dispatch_shape names the quadratic B-spline for extended_bspline (the kernel
  // outside the step), so the extended one is chosen here (as the serial build_phases).
  const auto run = [&](auto kernel) {
    using Kernel = decltype(kernel);
    // A phase and the phase_names() entry that times it.
    struct Phase {
      void (Impl::*run)(double);
      int name;
    };
    // The serial lists (simulation_step.cpp, build_phases) with the exchanges inserted. Without
    // contact (one velocity field) the per-field exchanges and the contact phases have nothing to do,
    // without penalty contact its phases, under FLIP the velocity filter's.
    const bool usf = s.opt.usf, usl = !s.opt.usf && !s.opt.musl, musl = s.opt.musl;
    thread_local std::vector<Phase> P;  // reused from step to step
    P.clear();
    P.push_back({&Impl::template particle_to_grid<Kernel>, 0});  // USF: m and p only
    // MUSL with several fields: the slots as particle_to_grid left them, for the remap.
    if (musl) P.push_back({&Impl::keep_grid_values, 0});
    P.insert(P.end(), {{&Impl::sum_to_owners, 1},
                       {&Impl::exchange_field_ranges, 2},
                       {&Impl::fields_to_owners, 3},
                       {&Impl::find_contact_nodes, 4},
                       {&Impl::template measure_contact_extents<Kernel>, 4},  // extent separation
                       {&Impl::contact_extrapolated, 5}});
    // USF: the stress from the extrapolated velocities (their ghost update first; the post-condition
    // momenta kept), the penalty contact's points moved with them, then the forces from the new stress
    // and the loads, summed to the owners (scheme_phases.cpp). Timed with particle_to_grid and
    // sum_to_owners (as the serial internal_forces).
    if (usf)
      P.insert(P.end(), {{&Impl::velocity_from_momentum, 15},
                         {&Impl::move_boundary_points, 17},
                         {&Impl::ghost_velocities, 9},
                         {&Impl::fields_to_ghosts, 10},
                         {&Impl::template stress_update<Kernel>, 12},
                         {&Impl::template internal_forces<Kernel>, 0},
                         {&Impl::forces_to_owners, 1}});
    P.insert(P.end(), {{&Impl::penalty_forces, 16},  // penalty contact (penalty_phases.cpp)
                       {&Impl::start_velocity, 6},  // XPIC's v^n (velocity_filter.cpp)
                       {&Impl::momentum_update, 6},
                       {&Impl::contact_updated, 7},
                       {&Impl::nodal_velocities, 8},
                       {&Impl::ghost_velocities, 9},
                       {&Impl::fields_to_ghosts, 10},
                       {&Impl::template velocity_filter<Kernel>, 11},  // XPIC/FMPM
                       {&Impl::template grid_to_particle<Kernel>, 11}});
    if (usl)  // the points with v^{n+1}, then the stress from it
      P.insert(P.end(), {{&Impl::move_boundary_points, 17}, {&Impl::template stress_update<Kernel>, 12}});
    // MUSL: the momenta remapped from the updated particles with their exchange (sum to the owners,
    // the per-field entries, multimaterial contact on the remapped momenta), the velocity conditions
    // and v_i = p_i/m_i, the points moved with them, the ghost update and the stress from them. The
    // remapped contact pass is timed with the extrapolated one (both change momenta only).
    if (musl)
      P.insert(P.end(), {{&Impl::template remap_momentum<Kernel>, 14},
                         {&Impl::sum_to_owners, 1},
                         {&Impl::fields_to_owners, 3},
                         {&Impl::contact_remapped, 5},
                         {&Impl::velocity_from_momentum, 15},
                         {&Impl::move_boundary_points, 17},
                         {&Impl::ghost_velocities, 9},
                         {&Impl::fields_to_ghosts, 10},
                         {&Impl::template stress_update<Kernel>, 12}});
    P.push_back({&Impl::migrate, 13});
    for (const Phase& phase : P) {
      const double t0 = MPI_Wtime();
      (s.*phase.run)(dt);
      s.traffic.phase_seconds[static_cast<std::size_t>(phase.name)] += MPI_Wtime() - t0;
    }
  };
  if (s.opt.shape == ShapeKind::extended_bspline)
    run(ExtendedBSplineKernel{});
  else
    dispatch_shape(s.opt.shape, run);
  s.time += dt;
  s.steps_taken += 1.0;
  ++s.traffic.steps;
}

#define FRICTHERM_INSTANTIATE_PHASE_LISTS(D)                             \
  template void DecomposedMpm<D>::step(double);                          \
  template const std::array<const char*, 18>& DecomposedMpm<D>::phase_names();
FRICTHERM_INSTANTIATE_PHASE_LISTS(2)
FRICTHERM_INSTANTIATE_PHASE_LISTS(3)
#undef FRICTHERM_INSTANTIATE_PHASE_LISTS

}  // namespace frictherm::mechanics
