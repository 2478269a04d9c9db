#pragma once
// A grid-velocity filter as the MPM step sees it (issue 32; docs/step.md, "Velocity filters"): the
// phases it adds to the step's phase list at named hook points. XPIC(m) (Hammerquist & Nairn 2017)
// and FMPM(k) (Nairn & Hammerquist 2021) are the implementations, one file each under
// mechanics/src/filters/; filters/registry.cpp lists them and velocity_filters_for returns the one the
// scene's solver.particle_update names (none under FLIP, whose PIC blend is a per-particle kernel of
// the particle pass: transfer/pic_blend.hpp). The Neumann series both use (filter_grid_velocity,
// simulation_transfer.cpp; transfer/grid_to_particle.hpp) is shared with the decomposed step.
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/step/phase_list.hpp>

#include <vector>

namespace frictherm::mechanics {

enum class UpdateScheme;  // simulation.hpp
template <int Dim>
class Simulation;

/// The points of the step where a filter's phases go (step/scheme_order.hpp, the order both engines build).
enum class FilterHook {
  start_velocity,  // before the velocity conditions: the momenta the update starts from
  velocities       // after nodal_velocities: v^{n+1} on the grid, before the particles read it
};

template <int Dim>
class StepVelocityFilter {
 public:
  virtual ~StepVelocityFilter() = default;
  virtual const char* name() const = 0;
  /// Appends this filter's phases for hook `at` to `phases` (none if it does nothing there), for the
  /// list of update scheme `scheme` and shape functions `shape`; the phases act on `sim`.
  virtual void add_phases(FilterHook at, UpdateScheme scheme, ShapeKind shape, Simulation<Dim>& sim,
                          PhaseList& phases) const = 0;
};

/// The velocity filters `sim` applies now, in registration order (filters/registry.cpp).
template <int Dim>
std::vector<const StepVelocityFilter<Dim>*> velocity_filters_for(Simulation<Dim>& sim);

// A filter's file defines its selection with FRICTHERM_STEP_COMPONENT_SELECTION
// (step/component_registry.hpp).

}  // namespace frictherm::mechanics
