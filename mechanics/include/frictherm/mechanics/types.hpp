#pragma once
// Basic fixed-size algebra types shared by the mechanics module. SI units throughout.
#include <Eigen/Core>
#include <Eigen/LU>  // determinant
#include <array>
#include <cstdint>

namespace frictherm::mechanics {

template <int Dim> using Vec = Eigen::Matrix<double, Dim, 1>;
template <int Dim> using Mat = Eigen::Matrix<double, Dim, Dim>;
template <int Dim> using IVec = std::array<int, Dim>;

/// How a 2D model is closed in the third direction; 3D models use `three_d`.
enum class Analysis { plane_strain, plane_stress, three_d };

}  // namespace frictherm::mechanics
