// The contact methods (step/contact_method.hpp): each file under contact_methods/ defines one and its
// selection, a function that sets it up for a finalized simulation and returns it, or null when the
// scene does not use it. A new method is one new file plus its line below; the order of the lines is
// the order of the methods' phases at a hook they share.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>
#include <frictherm/mechanics/step/contact_method.hpp>

namespace frictherm::mechanics {

// Defined in the methods' files.
template <int Dim> const StepContactMethod<Dim>* select_multimaterial_contact(Simulation<Dim>& sim);
template <int Dim> const StepContactMethod<Dim>* select_penalty_contact(Simulation<Dim>& sim);

template <int Dim>
std::vector<const StepContactMethod<Dim>*> contact_methods_for(Simulation<Dim>& sim) {
  static constexpr const StepContactMethod<Dim>* (*registry[])(Simulation<Dim>&) = {
      &select_multimaterial_contact<Dim>,  // multimaterial_contact_method.cpp (Nairn 2018)
      &select_penalty_contact<Dim>,        // penalty_contact_method.cpp (Kakouris 2024)
  };
  return select_components<StepContactMethod<Dim>>(registry, sim);
}

template std::vector<const StepContactMethod<2>*> contact_methods_for(Simulation<2>&);
template std::vector<const StepContactMethod<3>*> contact_methods_for(Simulation<3>&);

}  // namespace frictherm::mechanics
