#pragma once
// Basic fixed-size algebra types shared by the mechanics module. SI units throughout.
#include <Eigen/Core>
#include <Eigen/LU>  // determinant
#include <array>
#include <cstdint>

/// For the small constitutive functions called once per particle in the stress update: inlined into
/// the particle loop (GCC otherwise keeps some of them out of line and passes the matrices through memory).
#if defined(__GNUC__)
#define FRICTHERM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define FRICTHERM_ALWAYS_INLINE inline
#endif

namespace frictherm::mechanics {

template <int Dim> using Vec = Eigen::Matrix<double, Dim, 1>;
template <int Dim> using Mat = Eigen::Matrix<double, Dim, Dim>;
template <int Dim> using IVec = std::array<int, Dim>;

/// How a 2D model is closed in the third direction; 3D models use `three_d`.
enum class Analysis { plane_strain, plane_stress, three_d };

}  // namespace frictherm::mechanics
