// The rigid drivers of the step (step/rigid_driver.hpp): each file under rigids/ defines one and its
// selection, a function that returns it when the scene has rigid materials it drives, or null. A new
// driver is one new file plus its line below; the order of the lines is the order of the drivers'
// phases at a hook they share.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>
#include <frictherm/mechanics/step/rigid_driver.hpp>

namespace frictherm::mechanics {

// Defined in the drivers' files.
template <int Dim> const StepRigidDriver<Dim>* select_prescribed_velocity(Simulation<Dim>& sim);

template <int Dim>
std::vector<const StepRigidDriver<Dim>*> rigid_drivers_for(Simulation<Dim>& sim) {
  static constexpr const StepRigidDriver<Dim>* (*registry[])(Simulation<Dim>&) = {
      &select_prescribed_velocity<Dim>,  // prescribed_velocity.cpp: walls, pistons with v(t)
  };
  return select_components<StepRigidDriver<Dim>>(registry, sim);
}

template std::vector<const StepRigidDriver<2>*> rigid_drivers_for(Simulation<2>&);
template std::vector<const StepRigidDriver<3>*> rigid_drivers_for(Simulation<3>&);

}  // namespace frictherm::mechanics
