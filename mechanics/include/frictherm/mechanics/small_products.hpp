#pragma once
// The product of the 2×2 and 3×3 matrices of the stress update's F ← (I + dt L) F, inlined into the
// particle loop. GCC keeps Eigen's fixed-size product out of line and passes the matrices through
// memory; this gives the same bits as Eigen's lazy product on baseline x86-64 (SSE2, no FMA): 2×2
// entries are two-term sums (exact to reorder), and a 3×3 product's rows 0 and 1 are Eigen's packets,
// summed over k in order, row 2 its scalar reduction a0 + (a1 + a2).
// tests/mechanics/test_plane_strain_update.cpp checks it bitwise against Eigen. Other vector
// extensions (FRICTHERM_NATIVE with AVX) keep Eigen's own product.
#include <frictherm/mechanics/types.hpp>

namespace frictherm::mechanics {

#if defined(EIGEN_VECTORIZE_SSE2) && !defined(EIGEN_VECTORIZE_AVX)
#define FRICTHERM_INLINE_SMALL_PRODUCTS 1
#else
#define FRICTHERM_INLINE_SMALL_PRODUCTS 0
#endif

namespace small_detail {
/// (A B)_ij as Eigen's lazy product of a fixed-size matrix evaluates it (see above).
template <int Dim>
FRICTHERM_ALWAYS_INLINE double product_entry(const Mat<Dim>& A, const Mat<Dim>& B, int i, int j) {
  if constexpr (Dim == 2) {
    return A(i, 0) * B(0, j) + A(i, 1) * B(1, j);
  } else {
    const double a0 = A(i, 0) * B(0, j), a1 = A(i, 1) * B(1, j), a2 = A(i, 2) * B(2, j);
    return i < 2 ? (a0 + a1) + a2 : a0 + (a1 + a2);
  }
}
}  // namespace small_detail

/// C = A B (C distinct from A and B), as C.noalias() = A * B.
template <int Dim>
FRICTHERM_ALWAYS_INLINE void product_into(const Mat<Dim>& A, const Mat<Dim>& B, Mat<Dim>& C) {
#if FRICTHERM_INLINE_SMALL_PRODUCTS
  for (int j = 0; j < Dim; ++j)
    for (int i = 0; i < Dim; ++i) C(i, j) = small_detail::product_entry<Dim>(A, B, i, j);
#else
  C.noalias() = A * B;
#endif
}

}  // namespace frictherm::mechanics
