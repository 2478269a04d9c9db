// The decomposed step's phase lists (frictherm/mechanics/distributed.hpp): USL, MUSL and USF in the
// order step/scheme_order.hpp writes once for both engines, with the exchange phases at its exchange
// points, run in order and timed per phase_names() entry. The phases are in usl_phases.cpp (the USL ones),
// scheme_phases.cpp (what MUSL and USF add), contact_phases.cpp, contact_extents.cpp,
// penalty_phases.cpp, sparse_exchange.cpp and decomposition.cpp (migrate).
#include "distributed/decomposed_state.hpp"

#include <frictherm/mechanics/step/scheme_order.hpp>

#include <mpi.h>

#include <initializer_list>
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
    thread_local std::vector<Phase> P;  // reused from step to step
    P.clear();
    // The decomposed engine's phases at the points of the step (step/scheme_order.hpp, the order the
    // serial list has too), the exchanges inserted. Without contact (one velocity field) the per-field
    // exchanges and the contact phases have nothing to do, without penalty contact its phases, under
    // FLIP the velocity filter's. The point loads and tractions are in its particle_to_grid and
    // internal_forces (added to the slots before the sums to the owners).
    struct DecomposedEngine {
      std::vector<Phase>& P;
      bool musl;
      void add(std::initializer_list<Phase> phases) { P.insert(P.end(), phases); }
      void operator()(SchemePhase phase) {
        switch (phase) {
          case SchemePhase::particle_to_grid:  // USF: m and p only
            add({{&Impl::template particle_to_grid<Kernel>, 0}});
            break;
          case SchemePhase::velocity_from_momentum:
            add({{&Impl::velocity_from_momentum, 15}});
            break;
          case SchemePhase::stress_update:
            add({{&Impl::template stress_update<Kernel>, 12}});
            break;
          case SchemePhase::internal_forces:  // timed with particle_to_grid (as the serial one)
            add({{&Impl::template internal_forces<Kernel>, 0}});
            break;
          case SchemePhase::velocity_conditions:  // timed with momentum_update
            add({{&Impl::velocity_conditions, 6}});
            break;
          case SchemePhase::momentum_update:
            add({{&Impl::momentum_update, 6}});
            break;
          case SchemePhase::nodal_velocities:
            add({{&Impl::nodal_velocities, 8}});
            break;
          case SchemePhase::particle_update:  // the serial one-pass update as its two passes
            add({{&Impl::template grid_to_particle<Kernel>, 11}, {&Impl::template stress_update<Kernel>, 12}});
            break;
          case SchemePhase::grid_to_particle:
            add({{&Impl::template grid_to_particle<Kernel>, 11}});
            break;
          case SchemePhase::remap_momentum:
            add({{&Impl::template remap_momentum<Kernel>, 14}});
            break;
          case SchemePhase::time_step:            // set by the caller (DecomposedMpm::stable_time_step)
          case SchemePhase::shape_functions:      // in particle_to_grid
          case SchemePhase::extended_stencils:    // in particle_to_grid (extended_bsplines.cpp)
          case SchemePhase::end_particle_update:  // in grid_to_particle and migrate
            break;
        }
      }
      void operator()(ExchangeHook at) {
        switch (at) {
          case ExchangeHook::projected:
            // MUSL with several fields: the slots as particle_to_grid left them, for the remap.
            if (musl) add({{&Impl::keep_grid_values, 0}});
            add({{&Impl::sum_to_owners, 1}, {&Impl::exchange_field_ranges, 2}, {&Impl::fields_to_owners, 3}});
            break;
          case ExchangeHook::forces:
            add({{&Impl::forces_to_owners, 1}});
            break;
          case ExchangeHook::velocities:
            add({{&Impl::ghost_velocities, 9}, {&Impl::fields_to_ghosts, 10}});
            break;
          case ExchangeHook::remapped:
            add({{&Impl::sum_to_owners, 1}, {&Impl::fields_to_owners, 3}});
            break;
          case ExchangeHook::migrate:
            add({{&Impl::migrate, 13}});
            break;
        }
      }
      void operator()(ContactHook at) {
        switch (at) {
          case ContactHook::extrapolated:  // multimaterial contact (contact_phases.cpp, contact_extents.cpp)
            add({{&Impl::find_contact_nodes, 4},
                 {&Impl::template measure_contact_extents<Kernel>, 4},  // extent separation
                 {&Impl::contact_extrapolated, 5}});
            break;
          case ContactHook::stress_velocity:  // penalty contact (penalty_phases.cpp)
            add({{&Impl::move_boundary_points, 17}});
            break;
          case ContactHook::forces:
            add({{&Impl::penalty_forces, 16}});
            break;
          case ContactHook::updated:
            add({{&Impl::contact_updated, 7}});
            break;
          case ContactHook::remapped:  // timed with the extrapolated pass (both change momenta only)
            add({{&Impl::contact_remapped, 5}});
            break;
        }
      }
      void operator()(FilterHook at) {  // velocity_filter.cpp
        if (at == FilterHook::start_velocity) add({{&Impl::start_velocity, 6}});  // XPIC's v^n
        if (at == FilterHook::velocities) add({{&Impl::template velocity_filter<Kernel>, 11}});  // XPIC/FMPM
      }
      void operator()(LoadHook at) {  // point loads and tractions: in particle_to_grid and internal_forces
        if (at == LoadHook::conditioned_forces) add({{&Impl::damping, 6}});  // timed with momentum_update
      }
      void operator()(RigidHook) {}  // the drive in velocity_conditions and nodal_velocities, the motion in grid_to_particle
    };
    DecomposedEngine engine{P, s.opt.musl};
    add_scheme_phases(s.opt.usf, s.opt.musl, engine);
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
