// Grid-to-particle transfer schemes (transfer.hpp): FLIP, the PIC blend, XPIC(m) and FMPM(k).
//  * XPIC(1) is PIC: v_p = Σ S_ip (v_i^n + Δt a_i) = Σ S_ip v_i^{n+1} (Hammerquist & Nairn 2017).
//  * Momentum is kept to round-off: Σ_i m_i (S⁺S w)_i = Σ_i m_i w_i on every field.
//  * A uniform translation is kept exactly (test_momentum_conservation.cpp).
//  * Energy dissipation of a vibrating bar in its first mode: PIC loses energy every period;
//    XPIC(m) and FMPM(k) remove only what the grid cannot see and lose far less, less with order.
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

using namespace frictherm::mechanics;

namespace {

Material rubber() {
  Material m;
  m.name = "rubber", m.kind = MaterialKind::linear_elastic, m.density = 1100.0, m.youngs_modulus = 5e6,
  m.poisson_ratio = 0.4;
  return m;
}

SimulationOptions with_update(ParticleUpdate u, int order, double pic_time = std::numeric_limits<double>::infinity()) {
  SimulationOptions o;
  o.particle_update = u;
  o.transfer_order = order;
  o.pic_relaxation_time = pic_time;
  return o;
}

// A disk translating, spinning and pulsing radially (stress waves), as in test_momentum_conservation.
std::unique_ptr<Simulation<2>> spinning_disk(const SimulationOptions& o) {
  auto sim = std::make_unique<Simulation<2>>(Grid<2>(Vec<2>::Zero(), Vec<2>::Constant(0.05), IVec<2>{40, 40}), o);
  const int mat = sim->add_material(rubber());
  const Vec<2> c(1.0, 1.0);
  sim->add_body("disk", *make_ellipse<2>(c, Vec<2>(0.5, 0.5), 0.0, mat), 2, Vec<2>::Zero());
  auto& p = sim->particles();
  for (std::size_t k = 0; k < p.size(); ++k) {
    const Vec<2> r = p.position[k] - c;
    p.velocity[k] = Vec<2>(0.3 - 4.0 * r[1] + 5.0 * r[0] * r[0], -0.2 + 4.0 * r[0]);
  }
  return sim;
}

}  // namespace

TEST(TransferSchemes, XpicOfOrderOneIsPic) {
  // PIC as the limit of the blend: τ far below a step gives α = 1 − e^(−Δt/τ) = 1 in double precision.
  auto pic = spinning_disk(with_update(ParticleUpdate::flip, 1, 1e-12));
  auto xpic = spinning_disk(with_update(ParticleUpdate::xpic, 1));
  double scale = 0.0;
  for (const auto& v : pic->particles().velocity) scale = std::max(scale, v.norm());
  double worst = 0.0;
  for (int s = 0; s < 300; ++s) {
    pic->step();
    xpic->step();
    for (std::size_t k = 0; k < pic->particles().size(); ++k)
      worst = std::max(worst, (pic->particles().velocity[k] - xpic->particles().velocity[k]).norm() / scale);
  }
  std::printf("[XPIC(1) vs PIC] max |v_XPIC - v_PIC| / v_max over 300 steps = %.2e\n", worst);
  // The two sum the same terms in a different order (S v^n + Δt S a against S v^{n+1}): round-off,
  // growing at most linearly over the steps. 300 steps × ~10 roundings × ε ≈ 1e-12.
  EXPECT_LT(worst, 1e-11);
}

TEST(TransferSchemes, MomentumKeptToRoundOff) {
  for (const auto& [u, order] : {std::pair{ParticleUpdate::xpic, 2}, std::pair{ParticleUpdate::xpic, 5},
                                 std::pair{ParticleUpdate::fmpm, 2}, std::pair{ParticleUpdate::fmpm, 5}}) {
    for (UpdateScheme scheme : {UpdateScheme::usl, UpdateScheme::musl}) {
      SimulationOptions o = with_update(u, order);
      o.scheme = scheme;
      auto sim = spinning_disk(o);
      const auto& p = sim->particles();
      const Vec<2> P0 = sim->linear_momentum();
      double scale = 0.0;  // Σ m |v|: the size of the terms whose round-off accumulates
      for (std::size_t k = 0; k < p.size(); ++k) scale += p.mass[k] * p.velocity[k].norm();
      double worst = 0.0;
      for (int s = 0; s < 1000; ++s) {
        sim->step();
        worst = std::max(worst, (sim->linear_momentum() - P0).norm() / scale);
      }
      std::printf("[momentum %s(%d) %s] max |P - P0| / sum m|v| over 1000 steps = %.2e\n", to_string(u), order,
                  to_string(scheme), worst);
      // As for FLIP (test_momentum_conservation): 1000 steps × N particle terms × ε at worst; each
      // extra order adds one more rounded sweep, well inside the bound.
      EXPECT_LT(worst, 1000.0 * p.size() * 1.1e-16) << to_string(u) << order;
    }
  }
}

namespace {

// Fixed-free bar (ν = 0) started in its first mode, as test_bar_vibration; returns the fraction of
// the initial energy lost per period, averaged over `periods` periods.
double energy_loss_per_period(const SimulationOptions& base, int periods) {
  constexpr double L = 1.0, E = 1e8, rho = 1000.0, v0 = 0.1, h = L / 50;
  SimulationOptions o = base;
  o.analysis = Analysis::plane_stress;
  Simulation<2> sim(Grid<2>(Vec<2>::Zero(), Vec<2>::Constant(h), IVec<2>{54, 4}), o);
  Material m;
  m.name = "bar", m.density = rho, m.youngs_modulus = E, m.poisson_ratio = 0.0;
  const int mat = sim.add_material(m);
  sim.add_body("bar", *make_box<2>(Vec<2>(0.0, h), Vec<2>(L, 3 * h), mat), 2, Vec<2>::Zero());
  sim.fix_face(FixedFace{0, false, {{true, false, false}}});
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k) p.velocity[k][0] = v0 * std::sin(M_PI * p.position[k][0] / (2 * L));
  const double T = 4.0 * L / std::sqrt(E / rho);
  const double E0 = sim.kinetic_energy() + sim.strain_energy();
  while (sim.time() < periods * T) sim.step(periods * T - sim.time());
  const double E1 = sim.kinetic_energy() + sim.strain_energy();
  return 1.0 - std::pow(E1 / E0, 1.0 / periods);
}

}  // namespace

TEST(TransferSchemes, VibratingBarDissipatesFarLessThanPic) {
  const int periods = 4;
  const double flip = energy_loss_per_period(with_update(ParticleUpdate::flip, 1), periods);
  const double pic = energy_loss_per_period(with_update(ParticleUpdate::xpic, 1), periods);
  double xpic[3], fmpm[3];
  const int orders[3] = {2, 4, 8};
  for (int i = 0; i < 3; ++i) {
    xpic[i] = energy_loss_per_period(with_update(ParticleUpdate::xpic, orders[i]), periods);
    fmpm[i] = energy_loss_per_period(with_update(ParticleUpdate::fmpm, orders[i]), periods);
  }
  std::printf("[bar energy lost per period] FLIP %.3e  PIC %.3e  XPIC(2,4,8) %.3e %.3e %.3e  FMPM(2,4,8) %.3e %.3e %.3e\n",
              flip, pic, xpic[0], xpic[1], xpic[2], fmpm[0], fmpm[1], fmpm[2]);
  EXPECT_GT(pic, 0.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(xpic[i], 0.01 * pic) << "XPIC(" << orders[i] << ")";  // measured: ~1e-3 of PIC
    EXPECT_LT(fmpm[i], 0.01 * pic) << "FMPM(" << orders[i] << ")";
  }
  EXPECT_LT(xpic[2], xpic[0]);  // higher order, less filtering
  EXPECT_LT(fmpm[2], fmpm[0]);
}
