// The grid-velocity filters of the step (step/velocity_filter.hpp): each file under filters/ defines
// one and its selection, a function that returns it when the scene's solver.particle_update names it,
// or null. A new filter is one new file plus its line below (and its name in ParticleUpdate).
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>
#include <frictherm/mechanics/step/velocity_filter.hpp>

namespace frictherm::mechanics {

// Defined in the filters' files.
template <int Dim> const StepVelocityFilter<Dim>* select_xpic_filter(Simulation<Dim>& sim);
template <int Dim> const StepVelocityFilter<Dim>* select_fmpm_filter(Simulation<Dim>& sim);

template <int Dim>
std::vector<const StepVelocityFilter<Dim>*> velocity_filters_for(Simulation<Dim>& sim) {
  static constexpr const StepVelocityFilter<Dim>* (*registry[])(Simulation<Dim>&) = {
      &select_xpic_filter<Dim>,  // xpic_filter.cpp (Hammerquist & Nairn 2017)
      &select_fmpm_filter<Dim>,  // fmpm_filter.cpp (Nairn & Hammerquist 2021)
  };
  return select_components<StepVelocityFilter<Dim>>(registry, sim);
}

template std::vector<const StepVelocityFilter<2>*> velocity_filters_for(Simulation<2>&);
template std::vector<const StepVelocityFilter<3>*> velocity_filters_for(Simulation<3>&);

}  // namespace frictherm::mechanics
