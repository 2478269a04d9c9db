// Mass-proportional damping of the nodal momenta as a load of the step (step/step_load.hpp): after the
// velocity conditions, f_d −= c p_d on the free components while t < damping_until, and the work it
// removes into the energy books (Simulation::apply_damping, simulation_fields.cpp; the node kernel
// damp_node, loads/grid_loads.hpp, shared with the decomposed step). Its time-step bound is in
// stable_time_step (damping_time_step_limit).
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/step_load.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>

namespace frictherm::mechanics {

template <int Dim>
class MassDamping final : public StepLoad<Dim> {
 public:
  using Sim = Simulation<Dim>;
  const char* name() const override { return "mass_damping"; }

  void add_phases(LoadHook at, ShapeKind, Sim& sim, PhaseList& P) const override {
    if (at == LoadHook::conditioned_forces)
      P.add("damping", &StepPhaseTimes::grid_update, [&sim](StepContext& c) { sim.apply_damping(c.dt); });
  }

  static const StepLoad<Dim>* select(Sim& sim) {
    static const MassDamping load;
    return sim.opt_.damping_rate > 0.0 ? &load : nullptr;
  }
};

FRICTHERM_STEP_COMPONENT_SELECTION(StepLoad, select_mass_damping, MassDamping)

}  // namespace frictherm::mechanics
