#pragma once
// The shape-function stencils S_ip, G_ip of every particle for the step's kernel (Simulation<Dim>;
// simulation_step.cpp): one array per kernel, only the scene's kernel is filled.
#include <frictherm/mechanics/shape_functions.hpp>

#include <type_traits>
#include <vector>

namespace frictherm::mechanics {

/// The stencils of kernel `Kernel` as the step stores them: an array of Stencil, or for the extended
/// B-spline its precomputed weights (the type Simulation::stencils<Kernel>() returns, so that the step's
/// component passes outside simulation_step.cpp can name it).
template <int Dim, class Kernel>
using StencilArray = std::conditional_t<std::is_same_v<Kernel, ExtendedBSplineKernel>, PrecomputedStencils<Dim>,
                                        std::vector<Stencil<Dim, Kernel>>>;

/// Per particle: its stencil of the linear, uGIMP or quadratic B-spline kernel, or the extended
/// B-spline's flattened weights (Kakouris 2024 §3.3).
template <int Dim>
struct StencilStore {
  std::vector<Stencil<Dim, LinearKernel>> linear;
  std::vector<Stencil<Dim, UGIMPKernel>> ugimp;
  std::vector<Stencil<Dim, QuadraticBSplineKernel>> quadratic;
  PrecomputedStencils<Dim> extended;  // EBS: N^e, ∇N^e of every particle, this step
  // linear/ugimp/quadratic were evaluated at the current positions (and, with contact, the
  // materials' node boxes from them) by current_stencils(): the next step starts from them.
  bool current = false;

  /// The array of kernel `Kernel`.
  template <class Kernel>
  StencilArray<Dim, Kernel>& of() {
    if constexpr (std::is_same_v<Kernel, LinearKernel>) return linear;
    else if constexpr (std::is_same_v<Kernel, UGIMPKernel>) return ugimp;
    else if constexpr (std::is_same_v<Kernel, ExtendedBSplineKernel>) return extended;
    else return quadratic;
  }
};

}  // namespace frictherm::mechanics
