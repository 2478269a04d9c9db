// Plain test grids for the thermal module (no MPM): node-centred finite volumes on uniform
// 1D/2D grids with half (1D, 2D edges) and quarter (2D corners) cells on the boundary.
// In 1D this is exactly linear FE with a lumped mass; in 2D the 5-point stencil with lumped
// boundary masses. Natural (adiabatic) boundaries unless a test adds boundary conditions.
// K has zero row sums, so Σ M_i T_i changes only through sources and boundaries, and the
// checkerboard (−1)^(i+j) is an exact eigenvector with λ = 2·max K_ii/M_i (Gershgorin exact).
#pragma once

#include "frictherm/thermal/problem.hpp"

#include <Eigen/Core>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace thermal_test {

namespace ft = frictherm::thermal;

struct Material {
  double rho_c = 1.0;  // volumetric heat capacity ρc [J/(m³K)]
  double k = 1.0;      // conductivity [W/(m K)]
  double alpha() const { return k / rho_c; }
};

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

struct Grid2D {
  int nx = 0, ny = 0;
  double x0 = 0.0, y0 = 0.0, h = 0.0;  // square cells
  Eigen::VectorXd mass;               // per unit depth [J/(K m)]
  ft::SparseMatrix k;                 // per unit depth [W/(K m)]
  int id(int i, int j) const { return i + nx * j; }
  double x(int i) const { return x0 + h * i; }
  double y(int j) const { return y0 + h * j; }
  int size() const { return nx * ny; }
  ft::Problem problem() const { return ft::Problem(mass, k); }
};

inline Grid2D make_grid_2d(int nx, int ny, double x0, double y0, double h, const Material& mat) {
  Grid2D g;
  g.nx = nx;
  g.ny = ny;
  g.x0 = x0;
  g.y0 = y0;
  g.h = h;
  const int n = nx * ny;
  g.mass.resize(n);
  auto wx = [&](int i) { return (i == 0 || i == nx - 1) ? 0.5 : 1.0; };
  auto wy = [&](int j) { return (j == 0 || j == ny - 1) ? 0.5 : 1.0; };
  std::vector<Eigen::Triplet<double>> t;
  auto link = [&](int a, int b, double c) {
    t.emplace_back(a, a, c);
    t.emplace_back(b, b, c);
    t.emplace_back(a, b, -c);
    t.emplace_back(b, a, -c);
  };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      g.mass[g.id(i, j)] = mat.rho_c * h * h * wx(i) * wy(j);
      // face between (i,j) and (i+1,j) has length h·wy(j); conductance k·face/h
      if (i + 1 < nx) link(g.id(i, j), g.id(i + 1, j), mat.k * wy(j));
      if (j + 1 < ny) link(g.id(i, j), g.id(i, j + 1), mat.k * wx(i));
    }
  }
  g.k.resize(n, n);
  g.k.setFromTriplets(t.begin(), t.end());
  return g;
}

inline double max_abs(const Eigen::VectorXd& v) { return v.cwiseAbs().maxCoeff(); }

// "1.234e-05": measured errors are recorded as test properties (see --gtest_output=xml).
inline std::string sci(double x) {
  std::ostringstream os;
  os.precision(3);
  os << std::scientific << x;
  return os.str();
}

}  // namespace thermal_test
