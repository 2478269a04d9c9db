#pragma once
// A contact method as the MPM step sees it (issue 32; docs/step.md, "Contact methods"): the phases it
// adds to the step's phase list at named hook points, and what the energy books and the time step
// ask of it. Multimaterial contact on the grid (Nairn, Bardenhagen & Smith 2018) and penalty contact
// on boundary material points (Kakouris, Chatzis & Triantafyllou 2024) are the two implementations,
// each in its own file under mechanics/src/contact_methods/; registry.cpp lists them, and finalize()
// keeps those the scene uses (contact_methods_for). The phases are built once per scene: a phase is
// called once per step through its std::function, the particle and node loops are inside it, and
// nothing here is called per particle or per node.
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/step/phase_list.hpp>

#include <limits>
#include <vector>

namespace frictherm::mechanics {

enum class UpdateScheme;  // simulation.hpp
template <int Dim>
class Simulation;

/// The points of the step where a contact method's phases go (step/scheme_order.hpp, the order both
/// engines build; docs/step.md lists where each scheme puts them).
enum class ContactHook {
  extrapolated,     // after the momentum projection particle_to_grid
  stress_velocity,  // the velocity the stress update uses is on the grid: USF after velocity_from_momentum,
                    // USL after particle_update, MUSL after the remap's velocity_from_momentum
  forces,           // into the nodal forces, after the external loads and before the velocity conditions
  updated,          // after the momentum update
  remapped,         // MUSL: after remap_momentum
};

template <int Dim>
class StepContactMethod {
 public:
  virtual ~StepContactMethod() = default;
  virtual const char* name() const = 0;
  /// Appends this method's phases for hook `at` to `phases` (none if it does nothing there), for the
  /// list of update scheme `scheme` and shape functions `shape`; the phases act on `sim`.
  virtual void add_phases(ContactHook at, UpdateScheme scheme, ShapeKind shape, Simulation<Dim>& sim,
                          PhaseList& phases) const = 0;
  /// Energy the method stores now (J; penalty springs), for EnergyBalance::stored.
  virtual double stored_energy(const Simulation<Dim>&) const { return 0.0; }
  /// Time step (Simulation::stable_time_step): a factor on the CFL wave speed and a bound on the step
  /// given the wave speed (before the factor).
  virtual double wave_speed_factor(const Simulation<Dim>&) const { return 1.0; }
  virtual double time_step_limit(const Simulation<Dim>&, double /*wave_speed*/) const {
    return std::numeric_limits<double>::infinity();
  }
};

/// The contact methods `sim` uses, in registration order (contact_methods/registry.cpp). Called once
/// by finalize(); a method's selection also does its set-up (penalty: pairs and boundary points).
template <int Dim>
std::vector<const StepContactMethod<Dim>*> contact_methods_for(Simulation<Dim>& sim);

// A method's file defines its selection with FRICTHERM_STEP_COMPONENT_SELECTION
// (step/component_registry.hpp).

}  // namespace frictherm::mechanics
