// The loads of the step (step/step_load.hpp): each file under loads/ defines one and its selection,
// a function that returns it when the scene applies it, or null. A new load is one new file plus its
// line below; the order of the lines is the order of the loads' phases at a hook they share.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>
#include <frictherm/mechanics/step/step_load.hpp>

namespace frictherm::mechanics {

// Defined in the loads' files.
template <int Dim> const StepLoad<Dim>* select_particle_loads(Simulation<Dim>& sim);
template <int Dim> const StepLoad<Dim>* select_mass_damping(Simulation<Dim>& sim);

template <int Dim>
std::vector<const StepLoad<Dim>*> loads_for(Simulation<Dim>& sim) {
  static constexpr const StepLoad<Dim>* (*registry[])(Simulation<Dim>&) = {
      &select_particle_loads<Dim>,  // particle_loads.cpp: point loads and tractions
      &select_mass_damping<Dim>,    // mass_damping.cpp: mass-proportional damping
  };
  return select_components<StepLoad<Dim>>(registry, sim);
}

template std::vector<const StepLoad<2>*> loads_for(Simulation<2>&);
template std::vector<const StepLoad<3>*> loads_for(Simulation<3>&);

}  // namespace frictherm::mechanics
