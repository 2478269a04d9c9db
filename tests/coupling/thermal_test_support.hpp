#pragma once
// Helpers of the coupling tests: particle lattices without a Simulation, and synthetic motion.
#include <frictherm/coupling/coupler.hpp>

#include <cmath>
#include <functional>
#include <vector>

namespace frictherm::coupling::test {

namespace fm = frictherm::mechanics;

constexpr double kPi = 3.14159265358979323846;

template <int Dim>
fm::Grid<Dim> make_grid(const fm::Vec<Dim>& lo, double h, const fm::IVec<Dim>& cells) {
  return fm::Grid<Dim>(lo, fm::Vec<Dim>::Constant(h), cells);
}

/// Fills the box [lo, hi] (whole cells of size h) with ppc^Dim particles per cell, as
/// Simulation::add_body does: centres at (k + 1/2) h / ppc, half-widths h / (2 ppc), volume
/// (h/ppc)^Dim (times `thickness` in 2D), mass density·volume. T(x) gives the temperature.
template <int Dim>
void fill_box(fm::Particles<Dim>& p, const fm::Vec<Dim>& lo, const fm::Vec<Dim>& hi, double h, int ppc,
              double density, int material, const std::function<double(const fm::Vec<Dim>&)>& T,
              double thickness = 1.0, int body = 0) {
  const double s = h / ppc;
  fm::IVec<Dim> n{};
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    n[static_cast<std::size_t>(d)] = static_cast<int>(std::lround((hi[d] - lo[d]) / s));
    total *= static_cast<std::size_t>(n[static_cast<std::size_t>(d)]);
  }
  const double V = std::pow(s, Dim) * (Dim == 2 ? thickness : 1.0);
  for (std::size_t k = 0; k < total; ++k) {
    std::size_t rem = k;
    fm::Vec<Dim> x;
    for (int d = 0; d < Dim; ++d) {
      const auto nd = static_cast<std::size_t>(n[static_cast<std::size_t>(d)]);
      x[d] = lo[d] + (static_cast<double>(rem % nd) + 0.5) * s;
      rem /= nd;
    }
    p.add(x, fm::Vec<Dim>::Constant(0.5 * s), density * V, V, material, body, T(x));
  }
}

/// Σ_p m_p C_p T_p over conducting particles (J).
template <int Dim>
double heat_content(const fm::Particles<Dim>& p, const std::vector<ThermalProperties>& mats) {
  return particle_thermal_energy(p, mats);
}

}  // namespace frictherm::coupling::test
