#pragma once
// A rigid driver as the MPM step sees it (issue 32; docs/step.md, "Rigid drivers"): what moves the
// rigid materials (walls, pistons, anvils), as phases it adds to the step's phase list at named hook
// points. Rigid materials with a prescribed velocity history (Material::rigid_velocity_at; Nairn 2018
// eq. 44) are the implementation, mechanics/src/rigids/prescribed_velocity.cpp; rigids/registry.cpp
// lists the drivers and build_phases asks each whether the scene uses it (rigid_drivers_for).
// The node loops that apply what a driver sets (the velocity conditions, nodal_velocities, damping:
// conditions_.rigid_mask, layout_.field_velocity) and the particle pass that moves the rigid particles
// under USL with contact (layout_.rigid_motion) stay fused with the rest of the step: a driver's phase
// runs once per step, never per node or particle.
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/step/phase_list.hpp>

#include <vector>

namespace frictherm::mechanics {

template <int Dim>
class Simulation;

/// The points of the step where a rigid driver's phases go (step/scheme_order.hpp, the order both engines build).
enum class RigidHook {
  drive,            // the step's start, after shape_functions (before EBS builds its basis, which keeps
                    // the driven nodes): the rigid velocities at t onto the grid
  particle_update,  // just before the grid-to-particle pass (particle_update / grid_to_particle)
  moved             // after the particle pass and the contact methods' phases after it, before
                    // end_particle_update: the rigid particles moved
};

template <int Dim>
class StepRigidDriver {
 public:
  virtual ~StepRigidDriver() = default;
  virtual const char* name() const = 0;
  /// Appends this driver's phases for hook `at` to `phases` (none if it does nothing there), for shape
  /// functions `shape`; `pass_moves`: the particle pass moves the rigid particles (USL with contact,
  /// where it evaluates the next step's stencils in the same loop). The phases act on `sim`.
  virtual void add_phases(RigidHook at, bool pass_moves, ShapeKind shape, Simulation<Dim>& sim,
                          PhaseList& phases) const = 0;
};

/// The rigid drivers `sim` uses, in registration order (rigids/registry.cpp).
template <int Dim>
std::vector<const StepRigidDriver<Dim>*> rigid_drivers_for(Simulation<Dim>& sim);

// A driver's file defines its selection with FRICTHERM_STEP_COMPONENT_SELECTION
// (step/component_registry.hpp).

}  // namespace frictherm::mechanics
