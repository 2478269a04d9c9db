// FMPM(k) (Nairn & Hammerquist 2021) as a grid-velocity filter of the step (step/velocity_filter.hpp):
// the updated velocity v^{n+1} filtered by the truncated Neumann series of k terms after
// nodal_velocities; the particles take the filtered velocity (transfer/grid_to_particle.hpp).
#include "filters/filter_phases.hpp"
#include <frictherm/mechanics/step/component_registry.hpp>

namespace frictherm::mechanics {

template <int Dim>
class FmpmFilter final : public StepVelocityFilter<Dim> {
 public:
  using Sim = Simulation<Dim>;
  const char* name() const override { return "fmpm"; }

  void add_phases(FilterHook at, UpdateScheme scheme, ShapeKind shape, Sim& sim, PhaseList& P) const override {
    if (at == FilterHook::velocities) VelocityFilterPhases<Dim>::add_filter(scheme, shape, sim, P);
  }

  static const StepVelocityFilter<Dim>* select(Sim& sim) {
    static const FmpmFilter filter;
    return sim.options().particle_update == ParticleUpdate::fmpm ? &filter : nullptr;
  }
};

FRICTHERM_STEP_COMPONENT_SELECTION(StepVelocityFilter, select_fmpm_filter, FmpmFilter)

}  // namespace frictherm::mechanics
