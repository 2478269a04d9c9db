#pragma once
// The phases the grid-velocity filters (step/velocity_filter.hpp) share: XPIC's start velocity and
// the Neumann-series filter pass over the step's stencils, timed with the particle pass that reads the
// filtered velocity (USL: the combined particle_update, else grid_to_particle).
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/step_kernel.hpp>
#include <frictherm/mechanics/step/velocity_filter.hpp>

#include <functional>

namespace frictherm::mechanics {

template <int Dim>
struct VelocityFilterPhases {
  using Sim = Simulation<Dim>;
  /// XPIC: v^n = p^n/m, the velocity the momentum update starts from (save_start_velocity).
  static void add_start_velocity(Sim& sim, PhaseList& P) {
    P.add("start_velocity", &StepPhaseTimes::grid_update, [&sim](StepContext&) { sim.save_start_velocity(); });
  }
  /// The filter of order opt.transfer_order on `start` (XPIC: v^n) or v^{n+1} (FMPM): the kernel is
  /// chosen here, once per list.
  static void add_filter(UpdateScheme scheme, ShapeKind shape, Sim& sim, PhaseList& P) {
    P.add("velocity_filter", scheme == UpdateScheme::usl ? &StepPhaseTimes::stress_update : &StepPhaseTimes::grid_to_particle,
          step_kernel_phase(shape, [&sim](auto kernel) -> std::function<void(StepContext&)> {
            using Kernel = decltype(kernel);
            return [&sim](StepContext&) { sim.filter_grid_velocity(sim.template stencils<Kernel>()); };
          }));
  }
};

}  // namespace frictherm::mechanics
