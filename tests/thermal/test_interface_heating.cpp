// Sub-cell interface temperature (interface_heating.hpp): the step responses against the analytic
// two-half-space solution and against a direct simulation of the lumped grid they model, and the
// binned history's convolution against analytic flux histories.
#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/interface_heating.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

namespace ft = frictherm::thermal;

namespace {

constexpr double kPi = 3.14159265358979323846;
const ft::HalfSpace kHmx{0.45, 1900.0 * 1100.0};     // HMX-like
const ft::HalfSpace kBinder{0.25, 1800.0 * 1200.0};  // a binder-like second material (α 2.2× smaller)

// The interface node of a lumped two-material chain (n nodes a side beyond the interface node, spacing
// h), unit flux into the interface node from t = 0, integrated accurately; its temperature at `times`.
std::vector<double> chain_interface_temperature(const ft::HalfSpace& a, const ft::HalfSpace& b, double h, int n,
                                                const std::vector<double>& times, double f = 1.0) {
  const int size = 2 * n + 1, mid = n;  // nodes 0..n−1 side a, n the interface, n+1.. side b
  Eigen::VectorXd mass(size);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < size; ++i) {
    mass[i] = i < mid ? h * a.volumetric_heat_capacity : i > mid ? h * b.volumetric_heat_capacity
                                                                 : 0.5 * h * (a.volumetric_heat_capacity + b.volumetric_heat_capacity) / f;
  }
  for (int i = 0; i + 1 < size; ++i) {
    const double c = (i < mid ? a.conductivity : b.conductivity) / h;
    t.emplace_back(i, i, c), t.emplace_back(i + 1, i + 1, c), t.emplace_back(i, i + 1, -c), t.emplace_back(i + 1, i, -c);
  }
  ft::SparseMatrix k(size, size);
  k.setFromTriplets(t.begin(), t.end());
  ft::Problem p(mass, k);
  p.add_flux(mid, 1.0);  // 1 W per m² of interface
  ft::IntegratorOptions o;
  o.rtol = 1e-10, o.atol = 1e-14;
  auto integrator = ft::make_integrator("cvode_bdf", o);
  Eigen::VectorXd T = Eigen::VectorXd::Zero(size);
  std::vector<double> out;
  double t0 = 0.0;
  for (double time : times) {
    integrator->advance(p, T, t0, time);
    t0 = time;
    out.push_back(T[mid]);
  }
  return out;
}

}  // namespace

// The interface node of a uniform chain (n nodes a side, spacing h, material s) integrating
// dT/dt = P M⁻¹ (q − K T) with P the projection stencil [(1−f)/2, f, (1−f)/2] (interface_heating.hpp),
// unit flux into the middle node, by classical RK4 with steps far below its stability limit.
std::vector<double> filtered_chain_temperature(const ft::HalfSpace& s, double h, double f, int n,
                                               const std::vector<double>& times) {
  const int size = 2 * n + 1, mid = n;
  const double m = h * s.volumetric_heat_capacity, g = s.conductivity / h, lambda = g / m;
  auto rate = [&](const std::vector<double>& T) {
    std::vector<double> r(size), out(size);
    for (int i = 0; i < size; ++i) {
      double flow = (i == mid ? 1.0 : 0.0);
      if (i > 0) flow += g * (T[i - 1] - T[i]);
      if (i + 1 < size) flow += g * (T[i + 1] - T[i]);
      r[i] = flow / m;
    }
    for (int i = 0; i < size; ++i)
      out[i] = f * r[i] + 0.5 * (1.0 - f) * ((i > 0 ? r[i - 1] : 0.0) + (i + 1 < size ? r[i + 1] : 0.0));
    return out;
  };
  std::vector<double> T(size, 0.0), out;
  double t = 0.0;
  for (double target : times) {
    const int steps = static_cast<int>(std::ceil((target - t) / std::min(0.02 / lambda, target / 400.0)));
    const double dt = (target - t) / steps;
    for (int k = 0; k < steps; ++k) {
      const auto k1 = rate(T);
      std::vector<double> y(size);
      for (int i = 0; i < size; ++i) y[i] = T[i] + 0.5 * dt * k1[i];
      const auto k2 = rate(y);
      for (int i = 0; i < size; ++i) y[i] = T[i] + 0.5 * dt * k2[i];
      const auto k3 = rate(y);
      for (int i = 0; i < size; ++i) y[i] = T[i] + dt * k3[i];
      const auto k4 = rate(y);
      for (int i = 0; i < size; ++i) T[i] += dt / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
    t = target;
    out.push_back(T[mid]);
  }
  return out;
}

// The lumped-grid step response is the interface node of the chain it models, simulated directly:
// HMX against a twin of equal diffusivity (model exact), against a binder (α 2.2× smaller: the
// effusivity split is an approximation, measured below 1.5 % of θ_c), and one material with the
// projection filter f = 0.625 (linear hats, two particles a cell). Chains long enough that their far
// ends stay cold (≫ √(α t_max)/h = 10 cells). CVODE at rtol 1e-10 from rest is 1.3e-5 off at
// t = 0.01 h²/α; RK4 at these steps is below 1e-8: the exact cases are held to 5e-5.
TEST(InterfaceHeating, LumpedResponseIsTheChainItModels) {
  const ft::HalfSpace twin{2.0 * kHmx.conductivity, 2.0 * kHmx.volumetric_heat_capacity};  // same α, e ×2
  const double h = 2e-6, tau = h * h / kHmx.diffusivity();
  std::vector<double> times;
  for (double s : {0.01, 0.1, 0.5, 1.0, 5.0, 20.0, 100.0}) times.push_back(s * tau);
  const auto exact_twin = chain_interface_temperature(kHmx, twin, h, 400, times);
  const auto split_binder = chain_interface_temperature(kHmx, kBinder, h, 400, times);
  const auto filtered = filtered_chain_temperature(kHmx, h, 0.625, 150, times);
  double worst_split = 0.0;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double t = times[i];
    EXPECT_NEAR(ft::lumped_grid_step_response(t, kHmx, twin, h), exact_twin[i], 5e-5 * exact_twin[i]) << t / tau;
    EXPECT_NEAR(ft::lumped_grid_step_response(t, kHmx, kHmx, h, 0.625), filtered[i], 5e-5 * filtered[i]) << t / tau;
    worst_split = std::max(worst_split, std::abs(ft::lumped_grid_step_response(t, kHmx, kBinder, h) - split_binder[i]) /
                                           ft::half_space_pair_step_response(t, kHmx, kBinder));
  }
  EXPECT_LT(worst_split, 0.015);
  std::printf("effusivity split, HMX|binder: worst %.3g of θ_c\n", worst_split);
}

// The correction: √t-like while the heat is inside a cell, gone once it has spread over many; the
// table reproduces R_c − R_g (interpolation error measured 2.8e-5 of R_c; bound 1e-4, far below the
// model's own percent-level error against the MPM grid).
TEST(InterfaceHeating, CorrectionRelaxesToTheGrid) {
  const double h = 2e-6, tau = h * h / kHmx.diffusivity();
  const ft::SubcellCorrection x(kHmx, kBinder, h, 0.8);
  double worst = 0.0;
  for (double s = 1e-7; s < 1e6; s *= 1.37) {
    const double t = s * tau, rc = ft::half_space_pair_step_response(t, kHmx, kBinder);
    const double direct = rc - ft::lumped_grid_step_response(t, kHmx, kBinder, h, 0.8);
    worst = std::max(worst, std::abs(x.step_response(t) - direct) / rc);
  }
  EXPECT_LT(worst, 1e-4);
  // Early: the grid's interface node has hardly warmed: the correction is most of θ_c.
  const double early = 1e-4 * tau;
  EXPECT_GT(x.step_response(early), 0.97 * ft::half_space_pair_step_response(early, kHmx, kBinder));
  // Late: relative to θ_c the correction decays as 1/t (the lattice's next term): below 1e-3 at 1e3 τ,
  // below 1e-5 at 1e5 τ.
  for (const auto& [s, bound] : {std::pair{1e3, 1e-3}, std::pair{1e5, 1e-5}}) {
    const double late = s * tau;
    EXPECT_LT(std::abs(x.step_response(late)), bound * ft::half_space_pair_step_response(late, kHmx, kBinder));
  }
  // It shrinks with the cell at a fixed time: the grid resolves more.
  const ft::SubcellCorrection finer(kHmx, kBinder, h / 2, 0.8);
  EXPECT_LT(finer.step_response(tau), x.step_response(tau));
}

// A constant flux is represented exactly however bins merge (the merged bin's flux is the same
// constant): the convolution equals 2 q √(t/π)/(e_a + e_b) to round-off, over 5000 uneven steps.
TEST(InterfaceHeating, BinnedHistoryConstantFluxIsExact) {
  ft::BinnedHeatHistory hist(4);
  const std::size_t s = hist.add_slot();
  const double q = 3e8;  // W/m²
  double t = 0.0;
  for (int n = 0; n < 5000; ++n) {
    const double dt = 1e-10 * (1.0 + 0.5 * std::sin(0.01 * n));
    hist.add(s, q * dt);
    t += dt;
    hist.close(t);
  }
  EXPECT_LT(hist.bin_count(), 4u * 14u);  // O(bins_per_level · log₂ steps)
  std::vector<double> r;
  for (double tb : hist.boundaries()) r.push_back(ft::half_space_pair_step_response(t - tb, kHmx, kBinder));
  std::vector<double> out;
  hist.convolve({r}, {0}, out);
  const double exact = q * ft::half_space_pair_step_response(t, kHmx, kBinder);
  EXPECT_NEAR(out[0], exact, 1e-10 * exact);
  EXPECT_NEAR(hist.total_energy(s), q * t, 1e-12 * q * t);  // merging keeps the heat
}

// Time-varying fluxes against closed forms of the two-half-space convolution:
//   ramp q = β t:                 θ = (4/3) β t^{3/2} / ((e_a+e_b) √π)
//   switched off at t_off (q₀):   θ = 2 q₀ (√t − √(t − t_off)) / ((e_a+e_b) √π)
// With 8 bins a level a bin of width w sits at a lag ≥ 4 w, where averaging the flux over the bin
// errs by ~(w/lag)²/24 of that bin's share: the bound 2e-3 is a few times the sum over levels.
TEST(InterfaceHeating, BinnedHistoryTimeVaryingFluxes) {
  const double e = kHmx.effusivity() + kBinder.effusivity();
  for (int kind = 0; kind < 2; ++kind) {
    ft::BinnedHeatHistory hist(8);
    const std::size_t s = hist.add_slot();
    const double dt = 1e-10, beta = 1e17, q0 = 1e8, t_off = 2e-6;
    double t = 0.0;
    for (int n = 0; n < 40000; ++n) {
      const double tm = t + 0.5 * dt;  // midpoint: the step's exact heat for a linear ramp
      const double q = kind == 0 ? beta * tm : (tm < t_off ? q0 : 0.0);
      hist.add(s, q * dt);
      t += dt;
      hist.close(t);
    }
    std::vector<double> r;
    for (double tb : hist.boundaries()) r.push_back(ft::half_space_pair_step_response(t - tb, kHmx, kBinder));
    std::vector<double> out;
    hist.convolve({r}, {0}, out);
    const double exact = kind == 0 ? 4.0 / 3.0 * beta * std::pow(t, 1.5) / (e * std::sqrt(kPi))
                                   : 2.0 * q0 * (std::sqrt(t) - std::sqrt(t - t_off)) / (e * std::sqrt(kPi));
    EXPECT_NEAR(out[0], exact, 2e-3 * exact) << (kind == 0 ? "ramp" : "switched off");
  }
}

TEST(InterfaceHeating, FlattenRestoreRoundTripAndRefusesBadSizes) {
  ft::BinnedHeatHistory a(3);
  a.add_slot();
  for (int n = 1; n <= 50; ++n) {
    if (n == 20) a.add_slot();
    a.add(0, n);
    if (n >= 20) a.add(1, 2.0 * n);
    a.close(n * 1e-9);
  }
  ft::BinnedHeatHistory b(3);
  b.restore(a.flatten());
  ASSERT_EQ(b.bin_count(), a.bin_count());
  for (std::size_t bin = 0; bin < a.bin_count(); ++bin)
    for (std::size_t s = 0; s < 2; ++s) EXPECT_EQ(a.energy(bin, s), b.energy(bin, s));
  auto bad = a.flatten();
  bad.energy.pop_back();
  EXPECT_THROW(b.restore(bad), std::invalid_argument);
  EXPECT_THROW(a.close(1e-9), std::invalid_argument);  // not after the last boundary
}
