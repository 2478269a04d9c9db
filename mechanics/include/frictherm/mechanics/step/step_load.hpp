#pragma once
// A load as the MPM step sees it (issue 32; docs/step.md, "Loads"): the phases it adds to the step's
// phase list at named hook points. Point loads and tractions (into the nodal forces) and the
// mass-proportional damping of the nodal momenta are the implementations, each in its own file under
// mechanics/src/loads/; loads/registry.cpp lists them, and build_phases asks each whether the scene
// uses it (loads_for), every time it builds the lists. Gravity is not one: it is a body force the
// particle-to-grid loop adds per particle (map_to_grid), fused there so that it costs no second pass.
// The kernels the phases call are shared with the decomposed step (loads/grid_loads.hpp).
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/step/phase_list.hpp>

#include <vector>

namespace frictherm::mechanics {

template <int Dim>
class Simulation;

/// The points of the step where a load's phases go (step/scheme_order.hpp, the order both engines build).
enum class LoadHook {
  forces,             // into the nodal forces: after the internal forces (USF) and before the contact
                      // methods' forces (penalty) and the velocity conditions
  conditioned_forces  // after the velocity conditions, before the momentum update (forces the
                      // conditions leave on the free components)
};

template <int Dim>
class StepLoad {
 public:
  virtual ~StepLoad() = default;
  virtual const char* name() const = 0;
  /// Appends this load's phases for hook `at` to `phases` (none if it does nothing there), for shape
  /// functions `shape`; the phases act on `sim`.
  virtual void add_phases(LoadHook at, ShapeKind shape, Simulation<Dim>& sim, PhaseList& phases) const = 0;
};

/// The loads `sim` applies now, in registration order (loads/registry.cpp).
template <int Dim>
std::vector<const StepLoad<Dim>*> loads_for(Simulation<Dim>& sim);

// A load's file defines its selection with FRICTHERM_STEP_COMPONENT_SELECTION
// (step/component_registry.hpp).

}  // namespace frictherm::mechanics
