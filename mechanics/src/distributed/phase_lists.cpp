// The decomposed step's phase lists (frictherm/mechanics/distributed.hpp): USL, MUSL and USF, each
// the serial list (mechanics/src/simulation_step.cpp) with the exchange phases inserted, run in order
// and timed per phase_names() entry. The phases are in usl_phases.cpp (the USL ones),
// scheme_phases.cpp (what MUSL and USF add), contact_phases.cpp, contact_extents.cpp,
// penalty_phases.cpp, sparse_exchange.cpp and decomposition.cpp (migrate).
#include "distributed/decomposed_state.hpp"

#include <mpi.h>

#include <iterator>

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
    // USL, in order. Without contact (one velocity field) the per-field exchanges and the contact
    // phases have nothing to do.
    static constexpr Phase usl[] = {{&Impl::template particle_to_grid<Kernel>, 0},
                                    {&Impl::sum_to_owners, 1},
                                    {&Impl::exchange_field_ranges, 2},
                                    {&Impl::fields_to_owners, 3},
                                    {&Impl::find_contact_nodes, 4},
                                    {&Impl::template measure_contact_extents<Kernel>, 4},  // extent separation
                                    {&Impl::contact_extrapolated, 5},
                                    {&Impl::penalty_forces, 16},  // penalty contact (penalty_phases.cpp)
                                    {&Impl::start_velocity, 6},  // XPIC's v^n (velocity_filter.cpp)
                                    {&Impl::momentum_update, 6},
                                    {&Impl::contact_updated, 7},
                                    {&Impl::nodal_velocities, 8},
                                    {&Impl::ghost_velocities, 9},
                                    {&Impl::fields_to_ghosts, 10},
                                    {&Impl::template velocity_filter<Kernel>, 11},  // XPIC/FMPM
                                    {&Impl::template grid_to_particle<Kernel>, 11},
                                    {&Impl::move_boundary_points, 17},  // with v^{n+1}, as the serial USL
                                    {&Impl::template stress_update<Kernel>, 12},
                                    {&Impl::migrate, 13}};
    // MUSL: USL's phases up to the grid-to-particle update (with several velocity fields the slots of
    // particle_to_grid kept), then the momenta remapped from the updated particles with their exchange
    // (sum to the owners, the per-field entries to the owners, multimaterial contact on the remapped
    // momenta there, the velocity conditions and v_i = p_i/m_i, the ghost update), the penalty
    // contact's points moved with those velocities and the stress update from them (the serial MUSL
    // list, simulation_step.cpp: contact_extrapolated, contact_updated, contact_remapped). The
    // remapped pass is timed with the extrapolated one (both momentum changes only).
    static constexpr Phase musl[] = {{&Impl::template particle_to_grid<Kernel>, 0},
                                     {&Impl::keep_grid_values, 0},
                                     {&Impl::sum_to_owners, 1},
                                     {&Impl::exchange_field_ranges, 2},
                                     {&Impl::fields_to_owners, 3},
                                     {&Impl::find_contact_nodes, 4},
                                     {&Impl::template measure_contact_extents<Kernel>, 4},  // extent separation
                                     {&Impl::contact_extrapolated, 5},
                                     {&Impl::penalty_forces, 16},
                                     {&Impl::start_velocity, 6},  // XPIC's v^n (velocity_filter.cpp)
                                     {&Impl::momentum_update, 6},
                                     {&Impl::contact_updated, 7},
                                     {&Impl::nodal_velocities, 8},
                                     {&Impl::ghost_velocities, 9},
                                     {&Impl::fields_to_ghosts, 10},
                                     {&Impl::template velocity_filter<Kernel>, 11},  // XPIC/FMPM
                                     {&Impl::template grid_to_particle<Kernel>, 11},
                                     {&Impl::template remap_momentum<Kernel>, 14},
                                     {&Impl::sum_to_owners, 1},
                                     {&Impl::fields_to_owners, 3},
                                     {&Impl::contact_remapped, 5},
                                     {&Impl::velocity_from_momentum, 15},
                                     {&Impl::move_boundary_points, 17},
                                     {&Impl::ghost_velocities, 9},
                                     {&Impl::fields_to_ghosts, 10},
                                     {&Impl::template stress_update<Kernel>, 12},
                                     {&Impl::migrate, 13}};
    // USF: the momenta's exchange and the extrapolated contact pass as USL's, then the velocities from
    // those momenta (the post-condition momenta kept), the penalty contact's points moved with them,
    // their ghost update and the stress update from them; then the forces from the new stress and the
    // loads with their exchange to the owners (the kept momenta back), and USL's list from the
    // momentum update on (the serial USF list, simulation_step.cpp). The force pass is timed with
    // particle_to_grid and its exchange with sum_to_owners (as the serial internal_forces).
    static constexpr Phase usf[] = {{&Impl::template particle_to_grid<Kernel>, 0},
                                    {&Impl::sum_to_owners, 1},
                                    {&Impl::exchange_field_ranges, 2},
                                    {&Impl::fields_to_owners, 3},
                                    {&Impl::find_contact_nodes, 4},
                                    {&Impl::template measure_contact_extents<Kernel>, 4},
                                    {&Impl::contact_extrapolated, 5},
                                    {&Impl::velocity_from_momentum, 15},
                                    {&Impl::move_boundary_points, 17},
                                    {&Impl::ghost_velocities, 9},
                                    {&Impl::fields_to_ghosts, 10},
                                    {&Impl::template stress_update<Kernel>, 12},
                                    {&Impl::template internal_forces<Kernel>, 0},
                                    {&Impl::forces_to_owners, 1},
                                    {&Impl::penalty_forces, 16},
                                    {&Impl::start_velocity, 6},  // XPIC's v^n (velocity_filter.cpp)
                                    {&Impl::momentum_update, 6},
                                    {&Impl::contact_updated, 7},
                                    {&Impl::nodal_velocities, 8},
                                    {&Impl::ghost_velocities, 9},
                                    {&Impl::fields_to_ghosts, 10},
                                    {&Impl::template velocity_filter<Kernel>, 11},  // XPIC/FMPM
                                    {&Impl::template grid_to_particle<Kernel>, 11},
                                    {&Impl::migrate, 13}};
    const Phase* phases = s.opt.usf ? usf : s.opt.musl ? musl : usl;
    const std::size_t count = s.opt.usf ? std::size(usf) : s.opt.musl ? std::size(musl) : std::size(usl);
    for (std::size_t p = 0; p < count; ++p) {
      const double t0 = MPI_Wtime();
      (s.*phases[p].run)(dt);
      s.traffic.phase_seconds[static_cast<std::size_t>(phases[p].name)] += MPI_Wtime() - t0;
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
