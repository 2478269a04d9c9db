// Plain test grids for the thermal module (no MPM): node-centred finite volumes on uniform
// 1D/2D grids with half (1D, 2D edges) and quarter (2D corners) cells on the boundary. The 2D
// builder lives in bench/thermal_grids.hpp (shared with the thermal benchmarks).
// In 1D this is exactly linear FE with a lumped mass; in 2D the 5-point stencil with lumped
// boundary masses. Natural (adiabatic) boundaries unless a test adds boundary conditions.
// K has zero row sums, so Σ M_i T_i changes only through sources and boundaries, and the
// checkerboard (−1)^(i+j) is an exact eigenvector with λ = 2·max K_ii/M_i (Gershgorin exact).
#pragma once

#include "../../bench/thermal_grids.hpp"  // the 2D (and 3D) grids, shared with the benchmarks
#include "frictherm/thermal/problem.hpp"

#include <Eigen/Core>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace thermal_test {

namespace ft = frictherm::thermal;

using thermal_grids::Material;  // Material, Grid2D and make_grid_2d: bench/thermal_grids.hpp

struct Grid1D {
  int n = 0;
  double x0 = 0.0, dx = 0.0;
  Eigen::VectorXd mass;  // per unit cross-section [J/(K m²)]
  ft::SparseMatrix k;    // per unit cross-section [W/(K m²)]
  double x(int i) const { return x0 + dx * i; }
  ft::Problem problem() const { return ft::Problem(mass, k); }
};

inline Grid1D make_grid_1d(int n, double x0, double length, const Material& mat) {
  Grid1D g;
  g.n = n;
  g.x0 = x0;
  g.dx = length / (n - 1);
  g.mass = Eigen::VectorXd::Constant(n, mat.rho_c * g.dx);
  g.mass[0] *= 0.5;
  g.mass[n - 1] *= 0.5;
  std::vector<Eigen::Triplet<double>> t;
  const double c = mat.k / g.dx;  // conductance between neighbours
  for (int i = 0; i + 1 < n; ++i) {
    t.emplace_back(i, i, c);
    t.emplace_back(i + 1, i + 1, c);
    t.emplace_back(i, i + 1, -c);
    t.emplace_back(i + 1, i, -c);
  }
  g.k.resize(n, n);
  g.k.setFromTriplets(t.begin(), t.end());
  return g;
}

using thermal_grids::Grid2D;
using thermal_grids::make_grid_2d;

inline double max_abs(const Eigen::VectorXd& v) { return v.cwiseAbs().maxCoeff(); }

// "1.234e-05": measured errors are recorded as test properties (see --gtest_output=xml).
inline std::string sci(double x) {
  std::ostringstream os;
  os.precision(3);
  os << std::scientific << x;
  return os.str();
}

}  // namespace thermal_test
