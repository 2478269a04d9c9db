// The loads of the step (step/step_load.hpp): each file under loads/ defines one and its selection,
// a function that returns it when the scene applies it, or null. A new load is one new file plus its
// line below; the order of the lines is the order of the loads' phases at a hook they share.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/step_load.hpp>

namespace frictherm::mechanics {

template <int Dim>
using StepLoadSelection = const StepLoad<Dim>* (*)(const Simulation<Dim>&);

// Defined in the loads' files.
template <int Dim> const StepLoad<Dim>* select_particle_loads(const Simulation<Dim>& sim);
template <int Dim> const StepLoad<Dim>* select_mass_damping(const Simulation<Dim>& sim);

template <int Dim>
std::vector<const StepLoad<Dim>*> loads_for(const Simulation<Dim>& sim) {
  static constexpr StepLoadSelection<Dim> registry[] = {
      &select_particle_loads<Dim>,  // particle_loads.cpp: point loads and tractions
      &select_mass_damping<Dim>,    // mass_damping.cpp: mass-proportional damping
  };
  std::vector<const StepLoad<Dim>*> loads;
  for (const StepLoadSelection<Dim> select : registry)
    if (const StepLoad<Dim>* l = select(sim)) loads.push_back(l);
  return loads;
}

template std::vector<const StepLoad<2>*> loads_for(const Simulation<2>&);
template std::vector<const StepLoad<3>*> loads_for(const Simulation<3>&);

}  // namespace frictherm::mechanics
