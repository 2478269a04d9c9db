#pragma once
// Internal to the step's particle loops (simulation_step.cpp, simulation_particle_pass.cpp): the
// stencils as the hot loops index them.
#include <frictherm/mechanics/shape_functions.hpp>

#include <algorithm>
#include <climits>
#include <cstdint>
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

// The slot of a stencil's lowest node (its first_node) in the indexer's storage: the slot
// Stencil::for_each calls f with first.
template <int Dim, class Kernel>
FRICTHERM_ALWAYS_INLINE int first_slot(const Stencil<Dim, Kernel>& s, const NodeIndexer<Dim>& ix) {
  const IVec<Dim> b = s.first_node();
  int slot = ix.shift;
  for (int d = 0; d < Dim; ++d) slot += b[d] * ix.stride[d];
  return slot;
}

// Per-slot flags dilated by a stencil's box (issue 35, speed-s52): for each velocity field (a box of
// slots, x fastest, laid out by layout_fields), out[s] = OR of in[] over the K^Dim slots s + Σ_d i_d
// stride_d, 0 <= i_d < K, i.e. over the stencil of a particle whose first_node is at slot s. So
// "does this particle's stencil reach a flagged slot" is out[first_slot(stencil)], one load instead
// of K^Dim (2D uGIMP 9, 3D 27). Separable, one pass per axis; along axis d the slots with c_d <=
// e_d - K of each block of the outer axes are contiguous, so a pass is a plain byte OR of K shifted
// runs (vectorised). The other slots (within K - 1 of a box's upper face: no stencil's first node,
// as every stencil of a field's particles lies inside its box) get 1. `tmp` is scratch; both vectors
// keep their capacity.
template <int K, int Dim, class Fields>
void dilate_slot_flags(const Fields& fields, const std::vector<std::uint8_t>& in, std::vector<std::uint8_t>& out,
                       std::vector<std::uint8_t>& tmp) {
  out.resize(in.size());
  tmp.resize(in.size());
  for (const auto& F : fields) {
    if (F.count == 0) continue;
    const std::uint8_t* src = in.data() + F.first;
    std::size_t stride = 1;  // of axis d
    // Passes alternate between tmp and out so that the last (axis Dim - 1) writes out.
    for (int d = 0; d < Dim; ++d) {
      std::uint8_t* const dst = ((Dim - 1 - d) % 2 == 0 ? out.data() : tmp.data()) + F.first;
      const std::size_t e = static_cast<std::size_t>(F.extent[d]);
      const std::size_t block = stride * e;                               // slots of one block of the outer axes
      const std::size_t valid = e >= static_cast<std::size_t>(K) ? stride * (e - K + 1) : 0;  // its first slots
      for (std::size_t b = 0; b < F.count; b += block) {
        const std::uint8_t* const a = src + b;
        std::uint8_t* const o = dst + b;
        for (std::size_t s = 0; s < valid; ++s) {
          std::uint8_t v = a[s];
          for (int i = 1; i < K; ++i) v |= a[s + static_cast<std::size_t>(i) * stride];
          o[s] = v;
        }
        std::fill(o + valid, o + block, std::uint8_t{1});
      }
      src = dst;
      stride = block;
    }
  }
}

// The same for the stencils' kernel, given the stencils.
template <int Dim, class Kernel, class Fields>
void dilate_slot_flags_for(const std::vector<Stencil<Dim, Kernel>>&, const Fields& fields,
                           const std::vector<std::uint8_t>& in, std::vector<std::uint8_t>& out,
                           std::vector<std::uint8_t>& tmp) {
  dilate_slot_flags<Kernel::K, Dim>(fields, in, out, tmp);
}

}  // namespace frictherm::mechanics::step_detail
