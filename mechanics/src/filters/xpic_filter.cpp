// XPIC(m) (Hammerquist & Nairn 2017) as a grid-velocity filter of the step (step/velocity_filter.hpp):
// the start-of-step velocity v^n kept before the velocity conditions, filtered by the truncated
// Neumann series of m terms after nodal_velocities; the particle pass then updates the particles with
// v^{n+1} and the filtered v^n (transfer/grid_to_particle.hpp, update_particle_velocity).
#include "filters/filter_phases.hpp"
#include <frictherm/mechanics/step/component_registry.hpp>

namespace frictherm::mechanics {

template <int Dim>
class XpicFilter final : public StepVelocityFilter<Dim> {
 public:
  using Sim = Simulation<Dim>;
  const char* name() const override { return "xpic"; }

  void add_phases(FilterHook at, UpdateScheme scheme, ShapeKind shape, Sim& sim, PhaseList& P) const override {
    if (at == FilterHook::start_velocity) VelocityFilterPhases<Dim>::add_start_velocity(sim, P);
    if (at == FilterHook::velocities) VelocityFilterPhases<Dim>::add_filter(scheme, shape, sim, P);
  }

  static const StepVelocityFilter<Dim>* select(Sim& sim) {
    static const XpicFilter filter;
    return sim.options().particle_update == ParticleUpdate::xpic ? &filter : nullptr;
  }
};

FRICTHERM_STEP_COMPONENT_SELECTION(StepVelocityFilter, select_xpic_filter, XpicFilter)

}  // namespace frictherm::mechanics
