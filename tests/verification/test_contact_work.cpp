// Frictional work books (Nairn, Bardenhagen & Smith 2018, §2.10 and eqs. 27, 34, 36): the nodal
// array frictional_work(order) the coupling hands to the thermal solver, its running total
// cumulative_frictional_work(order), the two orders on the sliding block, and the guard of nodes
// where one material is barely present (a tiny reduced mass must never give infinite or NaN heat).
#include "sliding_block.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm;
using namespace frictherm::mechanics;
using namespace frictherm::verification;

namespace {

struct NodalBooks {
  bool all_finite = true, all_non_negative = true;
  double summed[2] = {0.0, 0.0};  // Σ_steps Σ_nodes frictional_work(order)
  long steps_with_work = 0;
};

void add_step(const Simulation<2>& sim, NodalBooks& b) {
  bool any = false;
  for (int o = 0; o < 2; ++o) {
    const auto& w = sim.frictional_work(o == 0 ? HeatingOrder::first : HeatingOrder::second);
    double step_sum = 0.0;
    for (double x : w) {
      b.all_finite = b.all_finite && std::isfinite(x);
      b.all_non_negative = b.all_non_negative && x >= 0.0;
      step_sum += x;
    }
    b.summed[o] += step_sum;
    any = any || step_sum > 0.0;
  }
  if (any) ++b.steps_with_work;
}

}  // namespace

TEST(FrictionalWork, SlidingBlockBooksAndOrders) {
  using C = SlidingBlockConstants;
  SlidingBlockSetup s;
  s.law = FrictionLaw::coulomb(0.2);
  int block = 0;
  Simulation<2> sim = make_sliding_block(s, block);
  NodalBooks b;
  const double tf = C::t_final();
  while (sim.time() < tf * (1 - 1e-12)) {
    sim.step(tf - sim.time());
    add_step(sim, b);
  }
  const double W1 = sim.cumulative_frictional_work(HeatingOrder::first);
  const double W2 = sim.cumulative_frictional_work(HeatingOrder::second);
  const double Q = rigid_solution(0.2, 0.2, 0.0, 0.0).friction_work(tf);
  const double gap = std::fabs(W2 - W1) / W1;
  const double books1 = std::fabs(b.summed[0] - W1) / W1, books2 = std::fabs(b.summed[1] - W2) / W2;
  // The stored energy at the velocities' time: the strain energy less the last update's half-step lead
  // (energy_books.hpp; here 6.9e-8 J, 7e-7 of the heat: the block slides at a steady strain).
  const double lead = sim.energy_balance(HeatingOrder::second).stored_lead;
  const double heat_by_energy = sim.external_work() - sim.kinetic_energy() - (sim.strain_energy() - lead);
  std::printf("[frictional work] %ld steps (%ld with work): first order %.6g J, second order %.6g J (gap %.2e), "
              "rigid %.6g J; Σ nodal per step vs cumulative: %.1e (first), %.1e (second); all finite %d, all ≥ 0 %d; "
              "external − kinetic − strain = %.6g J (%.2f %% from the second-order work)\n",
              sim.step_count(), b.steps_with_work, W1, W2, gap, Q, books1, books2, b.all_finite, b.all_non_negative,
              heat_by_energy, 100.0 * (heat_by_energy - W2) / W2);
  EXPECT_TRUE(b.all_finite);
  EXPECT_TRUE(b.all_non_negative);
  // The paper: first and second order "indistinguishable" on this problem (continuous sliding under
  // a monotonically increasing acceleration, so W2 ≪ W1 at every node). Bound: 1 %.
  EXPECT_LT(gap, 0.01);
  // The nodal arrays are what the coupling hands on; the cumulative totals are what the output
  // reports. They must be the same numbers added in another order: round-off only, 1e-12 relative
  // (sums of ~1e5 positive terms: ≤ 1e5 ε ≈ 2e-11 worst case, in practice far less).
  EXPECT_LT(books1, 1e-12);
  EXPECT_LT(books2, 1e-12);
  EXPECT_GT(b.steps_with_work, 0);
  // Energy: the friction heat is the energy the loads put in that is neither kinetic nor elastic.
  // MPM's own numerical dissipation also lands there; we measured 0.04 %, so 1 % is a safe bound.
  EXPECT_NEAR(heat_by_energy, W2, 0.01 * W2);
  // The same books as EnergyBalance keeps them (the series' energy_lost and numerical_dissipation):
  // the block starts at rest, so what the loads put in less the kinetic and strain energy is what was
  // lost, and the remainder after the heat is the scheme's own, −0.04 % of the heat: 0.2 %.
  const EnergyBalance e = sim.energy_balance(HeatingOrder::second);
  EXPECT_EQ(e.initial, 0.0);
  EXPECT_EQ(e.rigid_work + e.damping_work + e.plastic_work, 0.0);
  EXPECT_NEAR(e.lost(), heat_by_energy, 1e-12 * W2);
  EXPECT_LT(std::fabs(e.numerical_dissipation()), 0.002 * W2);
}

namespace {

struct SliverRun {
  long guarded = 0, contact_nodes = 0, sliding = 0;
  bool all_finite = true, all_non_negative = true;
  double work[2] = {0.0, 0.0};
  double min_fraction = 1.0, max_fraction = 0.0;  // block mass fraction at the contact nodes
};

// A block hovering one cell above a base, its particles lowered by ε so that the block's bottom row
// reaches the base's surface nodes with uGIMP weight S = ε²/(4 h l_p) ≈ 2e-9: those nodes carry the
// block at a mass fraction of ~1e-9. The block moves down and sideways and contact is detected
// from velocities alone, so the sliver nodes are in sliding contact with a tiny reduced mass.
SliverRun sliver(double min_mass_fraction) {
  const double h = 0.005, lp = h / 4, eps = std::sqrt(2e-9 * 4 * h * lp);
  SimulationOptions o;
  o.thickness = 0.001;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(h, h), IVec<2>{16, 10}), o);
  Material m;
  m.name = "base";
  m.density = 1000.0;
  m.youngs_modulus = 1e8;
  m.poisson_ratio = 0.3;
  const int base = sim.add_material(m);
  m.name = "block";
  const int block = sim.add_material(m);
  sim.add_body("base", *make_box<2>(Vec<2>(0.01, 0.01), Vec<2>(0.07, 0.02), base), 2, Vec<2>::Zero());
  sim.add_body("block", *make_box<2>(Vec<2>(0.02, 0.025), Vec<2>(0.05, 0.035), block), 2, Vec<2>(2.0, -1e-3));
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == block) p.position[k][1] -= eps, p.initial_position[k][1] -= eps;
  ContactOptions co;
  co.default_pair.law = FrictionLaw::coulomb(0.3);
  co.default_pair.normal = NormalMethod::specified;  // from the base to the block
  co.separation = SeparationMethod::velocity_only;
  co.min_mass_fraction = min_mass_fraction;
  sim.enable_contact(co);
  sim.set_contact_pair(base, block, co.default_pair);
  SliverRun r;
  for (int s = 0; s < 20; ++s) {  // 20 steps: the block moves 0.1 µm down, the fraction stays tiny
    sim.step();
    const ContactStats& c = sim.contact_stats();
    r.guarded += c.guarded, r.contact_nodes += c.contact_nodes, r.sliding += c.sliding_nodes;
    const auto& nodes = sim.nodes();
    const auto& fields = sim.fields();
    // Block mass fraction at nodes both fields reach with more than the empty-node mass (1e-12 of a
    // particle, simulation.hpp), i.e. at the contact nodes.
    const double empty = 1e-12 * p.mass[0];
    for (std::size_t sb = fields[1].first; sb < fields[1].first + fields[1].count; ++sb)
      for (std::size_t sa = fields[0].first; sa < fields[0].first + fields[0].count; ++sa)
        if (sim.slot_nodes()[sa] == sim.slot_nodes()[sb] && nodes.mass[sb] > empty && nodes.mass[sa] > empty)
        {
          const double f = nodes.mass[sb] / (nodes.mass[sa] + nodes.mass[sb]);
          r.min_fraction = std::min(r.min_fraction, f), r.max_fraction = std::max(r.max_fraction, f);
        }
    for (HeatingOrder order : {HeatingOrder::first, HeatingOrder::second})
      for (double x : sim.frictional_work(order)) {
        r.all_finite = r.all_finite && std::isfinite(x);
        r.all_non_negative = r.all_non_negative && x >= 0.0;
      }
  }
  r.work[0] = sim.cumulative_frictional_work(HeatingOrder::first);
  r.work[1] = sim.cumulative_frictional_work(HeatingOrder::second);
  return r;
}

}  // namespace

TEST(FrictionalWork, TinyReducedMassIsGuarded) {
  const SliverRun off = sliver(0.0), on = sliver(ContactOptions{}.min_mass_fraction);
  for (const auto* r : {&off, &on})
    std::printf("[sliver, min_mass_fraction %s] block mass fraction at contact nodes %.1e to %.1e; contact "
                "node-steps %ld, sliding %ld, guarded %ld; work %.3e J (first), %.3e J (second); all finite %d, "
                "all ≥ 0 %d\n",
                r == &off ? "0" : "default 1e-6", r->min_fraction, r->max_fraction, r->contact_nodes, r->sliding,
                r->guarded, r->work[0], r->work[1], r->all_finite, r->all_non_negative);
  ASSERT_LT(off.max_fraction, 1e-8);  // the set-up made its slivers, and only slivers
  EXPECT_GT(off.sliding, 0);          // unguarded, the slivers slide (with a ~1e-9 reduced mass)
  EXPECT_EQ(off.guarded, 0);
  EXPECT_GT(on.guarded, 0);           // guarded by default
  for (const auto* r : {&off, &on}) {
    EXPECT_TRUE(r->all_finite);
    EXPECT_TRUE(r->all_non_negative);
    EXPECT_TRUE(std::isfinite(r->work[0]) && std::isfinite(r->work[1]));
  }
  // A sliver's work scales with its reduced mass: m_red |Δv|² ~ 1e-9 × 3e-6 kg × 4 m²/s² ~ 1e-14 J.
  EXPECT_LT(off.work[1], 1e-9);
  EXPECT_EQ(on.work[1], 0.0);  // the only contact nodes were slivers, all left out
}
