#pragma once
// The step's shape-function kernel as a type, for a step component whose phase reads the step's
// stencils (contact_methods/multimaterial_contact_method.cpp, loads/particle_loads.cpp,
// filters/filter_phases.hpp, rigids/prescribed_velocity.cpp): the kernel is chosen once, when the
// phase list is built, and the phase's loops are compiled for it (no dispatch per step or particle).
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/step/phase_list.hpp>

#include <functional>

namespace frictherm::mechanics {

/// make(Kernel{}) for the kernel of `shape`, the extended B-spline's included (dispatch_shape gives
/// it the plain quadratic B-spline): the phase function `make` builds for that kernel.
template <class Make>
std::function<void(StepContext&)> step_kernel_phase(ShapeKind shape, Make&& make) {
  if (shape == ShapeKind::extended_bspline) return make(ExtendedBSplineKernel{});
  return dispatch_shape(shape, make);
}

}  // namespace frictherm::mechanics
