#pragma once
// Internal to the step's particle loops (simulation_step.cpp, simulation_particle_pass.cpp): the
// stencils as the hot loops index them.
#include <frictherm/mechanics/shape_functions.hpp>

#include <type_traits>
#include <vector>

namespace frictherm::mechanics::step_detail {

template <class Kernel>
constexpr bool is_extended = std::is_same_v<Kernel, ExtendedBSplineKernel>;

// A plain pointer to an array of Stencil (kept in a register: Eigen's vector stores may alias
// anything, so through the std::vector every store would reload its address), or the precomputed EBS
// entries themselves.
template <class T>
const T* indexable(const std::vector<T>& v) { return v.data(); }
template <int D>
const PrecomputedStencils<D>& indexable(const PrecomputedStencils<D>& p) { return p; }

}  // namespace frictherm::mechanics::step_detail
