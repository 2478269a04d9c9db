#pragma once
// Internal to the step's particle loops (simulation_step.cpp, simulation_particle_pass.cpp): the
// stencils as the hot loops index them.
#include <frictherm/mechanics/shape_functions.hpp>

#include <algorithm>
#include <climits>
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

// One thread's boxes of nodes reached by each material's particles (lattice indices counted from the
// ghost node, as Stencil::first_node), while it evaluates stencils; merged into the step's boxes under
// a critical section by the caller (the boxes lay out the velocity fields: layout_fields).
template <int Dim>
struct StencilBoxes {
  std::vector<IVec<Dim>> lo, hi;
  static IVec<Dim> none_lo() {
    IVec<Dim> b;
    b.fill(INT_MAX);
    return b;
  }
  static IVec<Dim> none_hi() {
    IVec<Dim> b;
    b.fill(INT_MIN);
    return b;
  }
  void reset(std::size_t materials) {
    lo.assign(materials, none_lo());
    hi.assign(materials, none_hi());
  }
  template <class Kernel>
  FRICTHERM_ALWAYS_INLINE static void extend(const Stencil<Dim, Kernel>& s, IVec<Dim>& box_lo, IVec<Dim>& box_hi) {
    const IVec<Dim> f = s.first_node();
    for (int d = 0; d < Dim; ++d) {
      box_lo[d] = std::min(box_lo[d], f[d]);
      box_hi[d] = std::max(box_hi[d], f[d] + Kernel::K - 1);
    }
  }
  /// Material m's box grown to hold [add_lo, add_hi].
  void merge(std::size_t m, const IVec<Dim>& add_lo, const IVec<Dim>& add_hi) { merge(lo[m], hi[m], add_lo, add_hi); }
  static void merge(IVec<Dim>& box_lo, IVec<Dim>& box_hi, const IVec<Dim>& add_lo, const IVec<Dim>& add_hi) {
    for (int d = 0; d < Dim; ++d) {
      box_lo[d] = std::min(box_lo[d], add_lo[d]);
      box_hi[d] = std::max(box_hi[d], add_hi[d]);
    }
  }
  void merge_into(std::vector<IVec<Dim>>& box_lo, std::vector<IVec<Dim>>& box_hi) const {
    for (std::size_t m = 0; m < lo.size(); ++m) merge(box_lo[m], box_hi[m], lo[m], hi[m]);
  }
  /// Every material's box emptied (the step's boxes, before the threads' boxes are merged into them).
  static void clear(std::vector<IVec<Dim>>& box_lo, std::vector<IVec<Dim>>& box_hi) {
    for (std::size_t m = 0; m < box_lo.size(); ++m) box_lo[m] = none_lo(), box_hi[m] = none_hi();
  }
};

}  // namespace frictherm::mechanics::step_detail
