// Plain conduction grids for thermal::Problem (no MPM), shared by the thermal benchmarks and by
// tests/thermal/grids.hpp: node-centred finite volumes on uniform 2D/3D grids with half cells on
// faces, quarter cells on edges (2D corners) and eighth cells on 3D corners. That is the
// 5-point (2D) or 7-point (3D) stencil with lumped boundary masses; the conductance between
// neighbours is k·(shared face area)/h (thermal-notes §2). Natural (adiabatic) boundaries.
// K has zero row sums, so Σ M_i T_i changes only through sources and boundaries, and the
// checkerboard is an exact eigenvector with λ = 2·max K_ii/M_i (the Gershgorin bound is exact:
// dt_FE = h²/(2dα)). 2D quantities are per unit depth.
#pragma once

#include "frictherm/thermal/problem.hpp"

#include <Eigen/Core>

#include <sstream>
#include <string>
#include <vector>

namespace thermal_grids {

namespace ft = frictherm::thermal;

/// "a,b,,c" -> {"a", "b", "c"} (command-line lists of the thermal benchmarks).
inline std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

struct Material {
  double rho_c = 1.0;  // volumetric heat capacity ρc [J/(m³K)]
  double k = 1.0;      // conductivity [W/(m K)]
  double alpha() const { return k / rho_c; }
};

// HMX-like (thermal-notes §3): ρ = 1900 kg/m³, c ≈ 1100 J/(kg K) → ρc = 2.09e6, k = 0.45.
inline Material hmx_like() { return Material{2.09e6, 0.45}; }

namespace detail {
// Weight of a node's cell along one axis: ½ on the two boundary nodes.
inline double edge_weight(int i, int n) { return (i == 0 || i == n - 1) ? 0.5 : 1.0; }

struct Links {
  std::vector<Eigen::Triplet<double>> t;
  void add(int a, int b, double c) {  // conductance c between nodes a and b
    t.emplace_back(a, a, c);
    t.emplace_back(b, b, c);
    t.emplace_back(a, b, -c);
    t.emplace_back(b, a, -c);
  }
  ft::SparseMatrix matrix(int n) const {
    ft::SparseMatrix k(n, n);
    k.setFromTriplets(t.begin(), t.end());
    return k;
  }
};
}  // namespace detail

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
  using detail::edge_weight;
  Grid2D g{nx, ny, x0, y0, h, Eigen::VectorXd(nx * ny), {}};
  detail::Links links;
  links.t.reserve(static_cast<std::size_t>(8) * nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double wx = edge_weight(i, nx), wy = edge_weight(j, ny);
      g.mass[g.id(i, j)] = mat.rho_c * h * h * wx * wy;
      // the face between (i,j) and (i+1,j) has length h·wy: conductance k·h·wy/h
      if (i + 1 < nx) links.add(g.id(i, j), g.id(i + 1, j), mat.k * wy);
      if (j + 1 < ny) links.add(g.id(i, j), g.id(i, j + 1), mat.k * wx);
    }
  g.k = links.matrix(g.size());
  return g;
}

struct Grid3D {
  int nx = 0, ny = 0, nz = 0;
  double x0 = 0.0, y0 = 0.0, z0 = 0.0, h = 0.0;  // cubic cells
  Eigen::VectorXd mass;                         // [J/K]
  ft::SparseMatrix k;                           // [W/K]
  int id(int i, int j, int l) const { return i + nx * (j + ny * l); }
  double x(int i) const { return x0 + h * i; }
  double y(int j) const { return y0 + h * j; }
  double z(int l) const { return z0 + h * l; }
  int size() const { return nx * ny * nz; }
  ft::Problem problem() const { return ft::Problem(mass, k); }
};

inline Grid3D make_grid_3d(int nx, int ny, int nz, double x0, double y0, double z0, double h,
                           const Material& mat) {
  using detail::edge_weight;
  Grid3D g{nx, ny, nz, x0, y0, z0, h, Eigen::VectorXd(nx * ny * nz), {}};
  detail::Links links;
  links.t.reserve(static_cast<std::size_t>(12) * nx * ny * nz);
  for (int l = 0; l < nz; ++l)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double wx = edge_weight(i, nx), wy = edge_weight(j, ny), wz = edge_weight(l, nz);
        g.mass[g.id(i, j, l)] = mat.rho_c * h * h * h * wx * wy * wz;
        // the face between (i,j,l) and (i+1,j,l) has area h²·wy·wz: conductance k·h·wy·wz
        if (i + 1 < nx) links.add(g.id(i, j, l), g.id(i + 1, j, l), mat.k * h * wy * wz);
        if (j + 1 < ny) links.add(g.id(i, j, l), g.id(i, j + 1, l), mat.k * h * wx * wz);
        if (l + 1 < nz) links.add(g.id(i, j, l), g.id(i, j, l + 1), mat.k * h * wx * wy);
      }
  g.k = links.matrix(g.size());
  return g;
}

}  // namespace thermal_grids
