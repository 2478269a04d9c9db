#pragma once
// The shape-function stencils S_ip, G_ip of every particle for the step's kernel (Simulation<Dim>;
// simulation_step.cpp): one array per kernel, only the scene's kernel is filled.
#include <frictherm/mechanics/shape_functions.hpp>

#include <vector>

namespace frictherm::mechanics {

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
};

}  // namespace frictherm::mechanics
