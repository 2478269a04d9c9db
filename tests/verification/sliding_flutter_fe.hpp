#pragma once
// An independent reference for the stability of steady Coulomb sliding in the sliding-block set-up
// (Nairn, Bardenhagen & Smith 2018, figure 2; sliding_block.hpp): the complex-eigenvalue analysis used
// for friction-induced vibration (mode-coupling flutter, e.g. Hoffmann, Fischer, Begout & Gaul 2002),
// on a finite-element model that shares nothing with the MPM code.
//
// Plane-strain bilinear quadrilaterals (2 × 2 Gauss points) on a square mesh of the base (140 × 25 mm,
// bottom fixed) and the block (40 × 15 mm at x = 10..50 mm), lumped masses. The block's bottom nodes
// are held on the coincident base nodes by a normal penalty, N = k_n (u_y,base − u_y,block) (compression
// positive), and slide freely along x. While the block slides in +x the Coulomb traction follows the
// normal force: δF_x = −μ δN on the block's node and +μ δN on the base's. Loads that are constant in
// time (the preload, the push) do not enter the linearised motion
//   M ü + (K + K_f) u = 0,
// whose solutions e^{st} have s² = λ(−M⁻¹(K + K_f)). K_f is not symmetric, so for μ > 0 pairs of modes
// can merge into s = ±a ± iω: a > 0 is a mode that grows at the rate a. With μ = 0 every s is
// imaginary.
#include <Eigen/Dense>

#include <cmath>
#include <complex>
#include <array>
#include <map>
#include <tuple>
#include <vector>

namespace frictherm::verification {

struct FlutterMode {
  double growth_rate = 0.0;  // Re s (1/s): > 0 grows, 0 neutral
  double frequency = 0.0;    // |Im s| / 2π (Hz)
};

// The modes of steady sliding with friction coefficient mu (one per conjugate pair, the block's free
// sliding left out) on a mesh of square elements of side `cell` (m; must divide 5 mm). penalty_factor:
// k_n / E per unit thickness; from 100 on the rates move by less than 2 % (the contact is then as
// stiff as the MPM's, which allows no approach at all).
inline std::vector<FlutterMode> sliding_block_modes(double cell, double mu, double penalty_factor = 1000.0) {
  const double E = 2500e6, nu = 0.33, rho = 1000.0;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), G = E / (2 * (1 + nu));
  Eigen::Matrix3d D;
  D << lambda + 2 * G, lambda, 0, lambda, lambda + 2 * G, 0, 0, 0, G;
  // Element stiffness of a square of side `cell` (the same for every element).
  Eigen::Matrix<double, 8, 8> Ke = Eigen::Matrix<double, 8, 8>::Zero();
  const double g = 1.0 / std::sqrt(3.0);
  for (double xi : {-g, g})
    for (double eta : {-g, g}) {
      const double dxi[4] = {-(1 - eta), (1 - eta), (1 + eta), -(1 + eta)};
      const double deta[4] = {-(1 - xi), -(1 + xi), (1 + xi), (1 - xi)};
      Eigen::Matrix<double, 3, 8> B = Eigen::Matrix<double, 3, 8>::Zero();
      for (int a = 0; a < 4; ++a) {
        const double dx = 0.25 * dxi[a] * 2.0 / cell, dy = 0.25 * deta[a] * 2.0 / cell;
        B(0, 2 * a) = dx, B(1, 2 * a + 1) = dy, B(2, 2 * a) = dy, B(2, 2 * a + 1) = dx;
      }
      Ke += B.transpose() * D * B * (cell * cell / 4.0);
    }
  // Nodes keyed by (body, i, j) on the lattice of spacing `cell`; elements listed counter-clockwise.
  std::map<std::tuple<int, int, int>, int> node;
  auto id = [&](int body, int i, int j) {
    auto [it, added] = node.try_emplace({body, i, j}, static_cast<int>(node.size()));
    return it->second;
  };
  std::vector<std::array<int, 4>> elements;
  auto mesh = [&](int body, double x0, double y0, double x1, double y1) {
    const int i0 = static_cast<int>(std::lround(x0 / cell)), j0 = static_cast<int>(std::lround(y0 / cell));
    const int nx = static_cast<int>(std::lround((x1 - x0) / cell)), ny = static_cast<int>(std::lround((y1 - y0) / cell));
    for (int i = i0; i < i0 + nx; ++i)
      for (int j = j0; j < j0 + ny; ++j)
        elements.push_back({id(body, i, j), id(body, i + 1, j), id(body, i + 1, j + 1), id(body, i, j + 1)});
  };
  mesh(0, 0.0, 0.0, 0.140, 0.025);
  mesh(1, 0.010, 0.025, 0.050, 0.040);
  const int ndof = 2 * static_cast<int>(node.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(ndof, ndof);
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(ndof);
  for (const auto& e : elements)
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 2; ++c) {
        mass(2 * e[a] + c) += rho * cell * cell / 4.0;
        for (int b = 0; b < 4; ++b)
          for (int d = 0; d < 2; ++d) K(2 * e[a] + c, 2 * e[b] + d) += Ke(2 * a + c, 2 * b + d);
      }
  // Contact: K + K_f holds −∂F/∂u of the penalty's normal force and the friction that follows it.
  const int j_contact = static_cast<int>(std::lround(0.025 / cell));
  const double kn = penalty_factor * E;
  for (const auto& [key, block_node] : node) {
    const auto [body, i, j] = key;
    if (body != 1 || j != j_contact) continue;
    const int base_node = node.at({0, i, j});
    const int xa = 2 * block_node, ya = xa + 1, xb = 2 * base_node, yb = xb + 1;
    for (const auto& [col, dN] : {std::pair<int, double>{yb, kn}, {ya, -kn}}) {  // ∂N/∂u
      K(ya, col) -= dN, K(yb, col) += dN;            // F_y: +N on the block, −N on the base
      K(xa, col) += mu * dN, K(xb, col) -= mu * dN;  // F_x: −μN on the block, +μN on the base
    }
  }
  // Free degrees of freedom: all but the base's bottom row.
  std::vector<int> free;
  for (const auto& [key, n] : node)
    if (!(std::get<0>(key) == 0 && std::get<2>(key) == 0)) free.push_back(2 * n), free.push_back(2 * n + 1);
  const int nf = static_cast<int>(free.size());
  Eigen::MatrixXd A(nf, nf);
  for (int r = 0; r < nf; ++r)
    for (int c = 0; c < nf; ++c) A(r, c) = -K(free[r], free[c]) / mass(free[r]);
  const Eigen::VectorXcd s2 = Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues();
  std::vector<FlutterMode> modes;
  for (int k = 0; k < nf; ++k) {
    const std::complex<double> s = std::sqrt(s2(k));  // principal root: Re s ≥ 0
    if (std::abs(s) < 1.0 || s2(k).imag() < 0.0) continue;  // the block's free sliding; one of each conjugate pair
    modes.push_back({s.real(), std::abs(s.imag()) / (2.0 * M_PI)});
  }
  return modes;
}

// The fastest-growing mode with a frequency in [f_lo, f_hi] (growth_rate ≤ 0: none grows there).
inline FlutterMode fastest_growing(const std::vector<FlutterMode>& modes, double f_lo = 0.0, double f_hi = 1e300) {
  FlutterMode best{0.0, 0.0};
  for (const FlutterMode& m : modes)
    if (m.frequency >= f_lo && m.frequency <= f_hi && m.growth_rate > 1e-6 * 2.0 * M_PI * m.frequency &&
        m.growth_rate > best.growth_rate)
      best = m;
  return best;
}

}  // namespace frictherm::verification
