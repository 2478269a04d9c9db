// Verification of the sub-cell interface temperature through the coupler (interface_temperature.hpp):
// a strip of two materials meeting on a grid line, a uniform heat flux q(t) delivered to the
// interface nodes as nodal work each step (what frictional heating hands over), conduction on the
// particles' grid (eq. 38, CVODE). The interface temperature T_grid + correction is compared with
// the two-half-space solution of Carslaw & Jaeger,
//     constant q:        θ = 2 q √(t/π) / (e_a + e_b)
//     q = q₀ for t < t_off, then 0:  θ = 2 q₀ (√t − √(t − t_off)) / ((e_a + e_b) √π)
// and a heat source moving along the interface at speed V (each node heated for the passage time
// 2l/V, Péclet V l/α ≫ 1: Jaeger's high-speed limit is the 1D solution for that duration).
// The strip is wide and adiabatic at its sides, so the problem is 1D normal to the interface; it
// is tall enough that the heat never reaches its top or bottom.
#include "thermal_test_support.hpp"

#include <frictherm/coupling/coupler.hpp>
#include <frictherm/coupling/interface_reaction.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>

namespace fc = frictherm::coupling;
namespace fm = frictherm::mechanics;
using fc::test::fill_box;
using fc::test::kPi;
using fc::test::make_grid;

namespace {

struct Side {
  double density, heat_capacity, conductivity;
  double rho_c() const { return density * heat_capacity; }
  double effusivity() const { return std::sqrt(conductivity * rho_c()); }
  double diffusivity() const { return conductivity / rho_c(); }
};
const Side kHmx{1900.0, 1100.0, 0.45};
const Side kBinder{1800.0, 1200.0, 0.25};
const Side kHmxTwin{1900.0, 2200.0, 0.90};  // α of HMX, twice its ρc: the model's exact case

struct Trace {
  std::vector<double> time, interface, grid, exact;
  double worst_interface = 0.0, worst_grid = 0.0;  // max |error| / max exact
  double books_gap = 0.0;                          // |Σ M ΔT − heat delivered| / heat delivered
  std::vector<double> final_particle_temperature;
};

// Strip [0, W] × [−H, H], interface y = 0, material 0 below and 1 above. flux(x, t) in W/m² over the
// step ending at t (evaluated at the step's midpoint), sampled at the node above x_probe.
// `configure` may change the coupler's options; `finish` sees the coupler and particles at the end.
Trace run_strip(const Side& a, const Side& b, double h, fm::ShapeKind shape, double dt, long steps,
                long steps_per_window, const std::function<double(double, double)>& flux, double x_probe,
                bool model = true, const std::function<double(double)>& exact = {},
                const std::function<void(fc::CouplerOptions&)>& configure = {},
                const std::function<void(fc::Coupler<2>&, fm::Particles<2>&, double)>& finish = {}) {
  const int nx = 8, ny = 24;  // cells across, and per side
  const double thickness = 1e-3, T0 = 300.0;
  const auto grid = make_grid<2>({0.0, -ny * h}, h, {nx, 2 * ny});
  fm::Particles<2> p;
  fill_box<2>(p, {0.0, -ny * h}, {nx * h, 0.0}, h, 2, a.density, 0, [&](const fm::Vec<2>&) { return T0; }, thickness);
  fill_box<2>(p, {0.0, 0.0}, {nx * h, ny * h}, h, 2, b.density, 1, [&](const fm::Vec<2>&) { return T0; }, thickness);
  fc::CouplerOptions opt;
  opt.materials = {{true, a.heat_capacity, a.conductivity}, {true, b.heat_capacity, b.conductivity}};
  opt.integrator = "cvode_bdf";
  opt.integrator_options.rtol = 1e-9;
  opt.integrator_options.atol = 1e-9;
  opt.window.kind = fc::WindowPolicy::Kind::every_n_steps;
  opt.window.steps = steps_per_window;
  opt.thickness = thickness;
  opt.interface_temperature.enabled = model;
  if (configure) configure(opt);
  fc::Coupler<2> cp(grid, shape, opt);
  cp.start(p, 0.0);
  // The interface nodes and their share of the interface (half a cell at the strip's sides).
  std::vector<int> nodes;
  std::vector<double> width;
  int probe = -1;
  for (std::size_t n = 0; n < grid.node_count(); ++n) {
    const fm::Vec<2> x = grid.node_position(static_cast<int>(n));
    if (std::abs(x[1]) > 1e-6 * h || x[0] < -1e-6 * h || x[0] > nx * h * (1 + 1e-9)) continue;
    nodes.push_back(static_cast<int>(n));
    width.push_back(x[0] < 0.5 * h || x[0] > (nx - 0.5) * h ? 0.5 * h : h);
    if (std::abs(x[0] - x_probe) < 1e-6 * h) probe = static_cast<int>(n);
  }
  EXPECT_GE(probe, 0);
  std::vector<double> work(grid.node_count(), 0.0);
  Trace tr;
  double peak = 0.0;
  for (long s = 1; s <= steps; ++s) {
    const double t = dt * static_cast<double>(s), tm = t - 0.5 * dt;
    for (std::size_t j = 0; j < nodes.size(); ++j) {
      const double x = grid.node_position(nodes[j])[0];
      work[static_cast<std::size_t>(nodes[j])] = flux(x, tm) * width[j] * thickness * dt;
    }
    if (!cp.after_step(p, work, t) || !model || !exact) continue;
    const auto& it = cp.interface_temperature();
    double t_int = 0.0, t_grid = 0.0;
    for (std::size_t k = 0; k < it.nodes().size(); ++k)
      if (it.nodes()[k] == probe) t_int = it.node_temperature()[k], t_grid = t_int - it.node_correction()[k];
    const double e = exact(t);
    tr.time.push_back(t), tr.exact.push_back(e);
    tr.interface.push_back(t_int - T0);
    tr.grid.push_back(t_grid - T0);
    peak = std::max(peak, e);
  }
  if (std::getenv("FRICTHERM_TRACE"))
    for (std::size_t k = 0; k < tr.time.size(); k += 10)
      std::cout << "  t " << tr.time[k] << " exact " << tr.exact[k] << " interface " << tr.interface[k] << " grid "
                << tr.grid[k] << "\n";
  for (std::size_t k = 0; k < tr.time.size(); ++k) {
    tr.worst_interface = std::max(tr.worst_interface, std::abs(tr.interface[k] - tr.exact[k]) / peak);
    tr.worst_grid = std::max(tr.worst_grid, std::abs(tr.grid[k] - tr.exact[k]) / peak);
  }
  const fc::EnergyBooks& books = cp.books();
  tr.books_gap = std::abs(books.nodal_energy_change - books.heat_delivered) / books.heat_delivered;
  tr.final_particle_temperature = p.temperature;
  if (finish) finish(cp, p, dt * static_cast<double>(steps));
  return tr;
}

double half_spaces(const Side& a, const Side& b) { return 2.0 / ((a.effusivity() + b.effusivity()) * std::sqrt(kPi)); }

}  // namespace

// Constant flux, five cells (4 µm, the PBX study's coarse cell, to 0.25 µm), HMX against a binder and
// against its twin of equal diffusivity. The flux is sized for a 100 K rise in 2 µs, over which heat
// diffuses 0.66 µm: from a 37th of h²/α at 4 µm to seven times it at 0.25 µm. The step shrinks with
// the cell as an MPM run's does at a fixed CFL factor (5 ns at 4 µm, 400 steps; a window every 4 steps).
// Measured worst errors over the run, of the final rise (uGIMP, 2 particles a cell):
//   h (µm)                 4       2       1       0.5     0.25
//   interface, HMX|twin    0.25 %  0.35 %  0.41 %  0.25 %  0.14 %
//   interface, HMX|binder  0.14 %  0.33 %  0.41 %  0.19 %  0.15 %
//   grid alone             82–84 % 65–69 % 38–44 % 19–22 % 9–11 %
// The model's error is largest where the diffusion length is about a cell (1 µm): coarser, the
// half-space term carries the answer; finer, the grid does and the correction vanishes. With the step
// held at 5 ns instead, the error grows to 0.85 % at 0.5 µm: a window of 20 ns is then 1.7 % of the
// cell's diffusion time h²/α; with steps of 2.5 / 1.25 / 0.625 ns it is 0.43 / 0.29 / 0.25 % (HMX|twin):
// first order in the window until the cell's own error is reached.
// Tolerance 3 % of the final rise (issue 31), the interface error below a quarter of the grid's, and
// falling with the cell once the diffusion length is resolved (h ≤ 1 µm).
TEST(InterfaceTemperature, ConstantFluxIntoTwoHalfSpaces) {
  const double t_end = 2e-6;
  for (const Side* b : {&kHmxTwin, &kBinder}) {
    const double c = half_spaces(kHmx, *b);
    const double q = 100.0 / (c * std::sqrt(t_end));
    double previous = 1.0, previous_interface = 1.0;
    for (double h : {4e-6, 2e-6, 1e-6, 0.5e-6, 0.25e-6}) {
      const long steps = std::lround(400 * 4e-6 / h);  // dt = 5 ns · h / 4 µm
      const Trace tr = run_strip(
          kHmx, *b, h, fm::ShapeKind::ugimp, t_end / steps, steps, 4, [&](double, double) { return q; }, 4 * h, true,
          [&](double t) { return q * c * std::sqrt(t); });
      std::cout << (b == &kBinder ? "HMX|binder" : "HMX|twin") << " h = " << h * 1e6
                << " um: worst interface error " << 100 * tr.worst_interface << " % of the final rise (grid alone "
                << 100 * tr.worst_grid << " %)\n";
      EXPECT_LT(tr.worst_interface, 0.03) << "h = " << h;
      EXPECT_LT(tr.worst_interface, 0.25 * tr.worst_grid) << "h = " << h;  // far closer than the grid alone
      EXPECT_LT(tr.worst_grid, previous) << "h = " << h;  // and the grid converges towards it
      if (h < 0.9e-6) {
        EXPECT_LT(tr.worst_interface, previous_interface) << "h = " << h;  // converging
      }
      previous = tr.worst_grid;
      previous_interface = tr.worst_interface;
      EXPECT_LT(tr.books_gap, 1e-6);
    }
  }
}

// Flux switched off half way: the interface cools as √t − √(t − t_off); checked to 3 % of the peak.
TEST(InterfaceTemperature, FluxSwitchedOffCoolsLikeTheHalfSpaces) {
  const double t_end = 4e-6, t_off = 2e-6, h = 4e-6;
  const double c = half_spaces(kHmx, kBinder);
  const double q = 100.0 / (c * std::sqrt(t_off));
  const Trace tr = run_strip(
      kHmx, kBinder, h, fm::ShapeKind::ugimp, t_end / 800, 800, 4, [&](double, double t) { return t < t_off ? q : 0.0; },
      4 * h, true, [&](double t) { return q * c * (std::sqrt(t) - (t > t_off ? std::sqrt(t - t_off) : 0.0)); });
  std::cout << "switched off: worst interface error " << 100 * tr.worst_interface << " % of the peak\n";
  EXPECT_LT(tr.worst_interface, 0.03);
}

// A band source of width 2l moving along the interface at V (Péclet V l/α = 50): each node sees the
// flux for 2l/V, so at its trailing edge the interface is at 2 q √(2l/(πV))/(e_a+e_b) — Jaeger's
// high-Péclet limit for a moving source, which the 1D model reproduces; lateral conduction (resolved
// by the grid) lowers it by O(Pe^{-1/2}). Checked at the probe node after the source has passed:
// within 5 % of the 1D limit (the Pe^{-1/2} ≈ 14 % lateral effect is shared by the grid here,
// which is why the bound is not looser).
TEST(InterfaceTemperature, MovingSourceReachesTheFlashTemperature) {
  const double h = 4e-6, l = 2 * h;  // band half-width: two cells
  const double V = 50.0 * kHmx.diffusivity() / l;
  const double c = half_spaces(kHmx, kBinder);
  const double duration = 2 * l / V, q = 100.0 / (c * std::sqrt(duration));
  const double x_probe = 4 * h, x0 = -l;  // source centre starts at x0
  double peak_interface = 0.0;
  const double dt = duration / 100;
  const long steps = static_cast<long>(std::lround((x_probe + 2 * l - x0) / V / dt));
  const Trace tr = run_strip(
      kHmx, kBinder, h, fm::ShapeKind::ugimp, dt, steps, 1,
      [&](double x, double t) { return std::abs(x - (x0 + V * t)) < l ? q : 0.0; }, x_probe, true,
      [&](double t) { return q * c * std::sqrt(std::max(0.0, std::min(t, duration))); });
  for (double v : tr.interface) peak_interface = std::max(peak_interface, v);
  const double flash = q * c * std::sqrt(duration);
  std::cout << "moving source: peak interface rise " << peak_interface << " K, flash limit " << flash << " K\n";
  EXPECT_NEAR(peak_interface, flash, 0.05 * flash);
}

// The correction holds no heat: with the model on or off the particles end at the same temperatures
// (bit for bit) and the books close the same way.
TEST(InterfaceTemperature, ModelAddsAndTakesNoHeat) {
  const double h = 4e-6, q = 3e8;
  auto flux = [&](double, double) { return q; };
  const Trace on = run_strip(kHmx, kBinder, h, fm::ShapeKind::ugimp, 5e-9, 100, 4, flux, 4 * h, true);
  const Trace off = run_strip(kHmx, kBinder, h, fm::ShapeKind::ugimp, 5e-9, 100, 4, flux, 4 * h, false);
  ASSERT_EQ(on.final_particle_temperature.size(), off.final_particle_temperature.size());
  for (std::size_t k = 0; k < on.final_particle_temperature.size(); ++k)
    ASSERT_EQ(on.final_particle_temperature[k], off.final_particle_temperature[k]);
  EXPECT_EQ(on.books_gap, off.books_gap);
}

// A hot spot of size ℓ (patch_length): the heat of the heated nodes within ℓ/2 spread over the patch
// on their mean grid temperature. Checked on the strip: a uniform flux gives every patch inside the
// interface its node's own value (the edge weights make the patch's nodes cover exactly ℓ, for ℓ a
// multiple of the cell or not; to round-off, 1e-9 of the rise), and a source on one node gives the
// patch that node's grid temperature plus its correction times h/ℓ (the heat spread over the patch).
TEST(InterfaceTemperature, PatchIsTheMeanFluxOverTheHotSpot) {
  const double h = 4e-6, q = 3e8, x_probe = 4 * h;
  const auto grid = make_grid<2>({0.0, -24 * h}, h, {8, 48});  // run_strip's grid
  for (double patch : {4 * h, 5.3 * h, 6 * h}) {
    for (bool one_node : {false, true}) {
      auto flux = [&](double x, double) { return !one_node || std::abs(x - x_probe) < 0.5 * h ? q : 0.0; };
      int checked = 0;
      run_strip(
          kHmx, kBinder, h, fm::ShapeKind::ugimp, 5e-9, 100, 4, flux, x_probe, true, {},
          [&](fc::CouplerOptions& o) { o.interface_temperature.patch_length = patch; },
          [&](fc::Coupler<2>& cp, fm::Particles<2>&, double) {
            const auto& it = cp.interface_temperature();
            ASSERT_EQ(it.patch_temperature().size(), it.nodes().size());
            for (std::size_t k = 0; k < it.nodes().size(); ++k) {
              const double x = grid.node_position(it.nodes()[k])[0];
              const double node = it.node_temperature()[k], correction = it.node_correction()[k];
              const double patch_t = it.patch_temperature()[k];
              ASSERT_GT(correction, 1.0);  // a sub-cell rise of more than a kelvin to compare
              // Patches clear of the strip's end nodes (their share of the interface is half a cell, so
              // their flux per node area is half: the model spreads a node's heat over its whole cell).
              if (!one_node && x >= 0.5 * patch + 0.5 * h - 1e-9 * h && x <= 7.5 * h - 0.5 * patch + 1e-9 * h) {
                EXPECT_NEAR(patch_t, node, 1e-9 * correction) << "patch " << patch / h << " h, x = " << x / h << " h";
                ++checked;
              }
              if (one_node) {  // the probe is the only heated node
                EXPECT_NEAR(patch_t, node - correction + correction * h / patch, 1e-9 * correction) << patch / h;
                ++checked;
              }
            }
            EXPECT_NEAR(it.max_temperature(), *std::max_element(it.patch_temperature().begin(), it.patch_temperature().end()),
                        1e-12 * it.max_temperature());
          });
      EXPECT_GE(checked, 1) << "patch " << patch / h << " h";
    }
  }
}

// The Arrhenius verdict at the interface temperature (interface_reaction.hpp). A constant flux
// heats the HMX|binder interface by θ(t) = 100 K √(t/t_end) over t_end = 2 µs (the constant-flux case
// above); HMX reacts with first-order kinetics, Θ = 4000 K and Z chosen so that the exact interface
// history gives the exposure E = ∫ Z exp(−Θ/(T0 + θ(t))) dt = 1.5 (λ = 1 − e^{−E} = 0.78). At 4 µm
// the grid shows a sixth of the rise, so the nodal progress at the grid temperature stays at 0.14,
// and only the interface reading calls the hot spot a runaway (λ ≥ 0.5). The heat of reaction is
// 1 J/kg (a millikelvin at full reaction): the check is of the verdict, not of the ignition.
// Measured: λ_int 0.794 against 0.777 exact; tolerance 10 % of λ (a 1 % error in the rise moves k by
// 4 % at Θ/T² = 0.025/K).
TEST(InterfaceTemperature, ArrheniusVerdictAtTheInterface) {
  const double t_end = 2e-6, h = 4e-6, T0 = 300.0, theta = 4000.0;
  const double c = half_spaces(kHmx, kBinder);
  const double q = 100.0 / (c * std::sqrt(t_end));
  const auto rise = [&](double t) { return q * c * std::sqrt(t); };
  double unit_exposure = 0.0;  // ∫ exp(−Θ/T(t)) dt by the midpoint rule on 10⁵ intervals
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) * t_end / n;
    unit_exposure += std::exp(-theta / (T0 + rise(t))) * t_end / n;
  }
  const double Z = 1.5 / unit_exposure, exact = 1.0 - std::exp(-1.5);
  for (bool by_interface : {true, false}) {
    double lambda_interface = 0.0, lambda_grid = 0.0;
    frictherm::coupling::HotSpotFate fate = frictherm::coupling::HotSpotFate::undecided;
    run_strip(
        kHmx, kBinder, h, fm::ShapeKind::ugimp, t_end / 400, 400, 4, [&](double, double) { return q; }, 4 * h, true,
        {},
        [&](fc::CouplerOptions& o) {
          o.reaction.enabled = true;
          o.reaction.kinetics = {Z, theta, 1.0};  // 1 J/kg: 1 mK at full reaction, but the nodes react
          o.reaction.reacting = {1, 0};  // HMX (material 0) reacts
          o.hotspots.threshold = 5.0;    // K of rise: the interface layer of particles is hot
          o.hotspots_by_interface_temperature = by_interface;
        },
        [&](fc::Coupler<2>& cp, fm::Particles<2>& p, double t) {
          cp.continue_thermal(p, t + 1e-9);  // one short interval: the fates' first look
          for (double l : cp.interface_reaction().progress()) lambda_interface = std::max(lambda_interface, l);
          for (double l : cp.reaction_progress()) lambda_grid = std::max(lambda_grid, l);
          ASSERT_FALSE(cp.fates().records().empty());
          fate = cp.fates().records().front().fate;
          for (const auto& r : cp.fates().records())
            if (r.fate == frictherm::coupling::HotSpotFate::runaway) fate = r.fate;
        });
    std::cout << (by_interface ? "by interface" : "by grid") << ": interface progress " << lambda_interface
              << " (exact history " << exact << "), grid progress " << lambda_grid << "\n";
    EXPECT_NEAR(lambda_interface, exact, 0.1 * exact);
    EXPECT_LT(lambda_grid, 0.25 * lambda_interface);
    EXPECT_EQ(fate == frictherm::coupling::HotSpotFate::runaway, by_interface);
  }
}

// The progress integrator alone: exact for a constant temperature, second order in the update
// interval for a rising one (T = 300 K + 200 K t/t₁, Θ = 4000 K: E from 10⁵ midpoint intervals).
TEST(InterfaceTemperature, ReactionProgressIsSecondOrderInTheUpdateInterval) {
  fc::ReactionOptions r;
  r.enabled = true;
  r.kinetics = {1e6, 4000.0, 0.0};
  r.reacting = {1};
  const std::vector<std::int32_t> material{0};
  fc::InterfaceReaction constant;
  constant.start(1, 0.0);
  for (int i = 1; i <= 7; ++i) constant.advance(material, r, {500.0}, 1e-7 * i);
  const double k500 = 1e6 * std::exp(-4000.0 / 500.0);
  EXPECT_NEAR(constant.progress()[0], 1.0 - std::exp(-k500 * 7e-7), 1e-14);
  const double t1 = 1e-5;
  auto T = [&](double t) { return 300.0 + 200.0 * t / t1; };
  double E = 0.0;
  for (int i = 0; i < 100000; ++i) E += 1e6 * std::exp(-4000.0 / T((i + 0.5) * t1 / 100000)) * t1 / 100000;
  const double exact = 1.0 - std::exp(-E);
  double previous = 0.0;
  for (int updates : {10, 20, 40}) {
    fc::InterfaceReaction ramp;
    ramp.start(1, 0.0);
    ramp.advance(material, r, {T(0.0)}, 0.0);
    for (int i = 1; i <= updates; ++i) ramp.advance(material, r, {T(t1 * i / updates)}, t1 * i / updates);
    const double error = std::abs(ramp.progress()[0] - exact);
    if (previous > 0.0) {
      EXPECT_NEAR(previous / error, 4.0, 0.4) << updates << " updates";
    }
    previous = error;
  }
}
