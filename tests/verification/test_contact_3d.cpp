// Multimaterial contact in 3D: two elastic blocks collide obliquely with Coulomb friction (MVG
// normals, position separation). Checks what holds without an analytic solution: total momentum is
// conserved (contact exchanges are equal and opposite, eq. 18), the blocks really exchange momentum,
// the contact area term (no thickness in 3D, eq. 11) gives sliding nodes, and the mechanics pays for
// the heat: the frictional work at either order is at most the mechanical energy the blocks lost.
//
// The energy lost is measured after the blocks have separated, as the initial kinetic energy less the
// mean of kinetic + strain energy over 80 µs of free flight (about one period 2L/c = 76 µs of the
// blocks' first mode): the sum at a single step swings by up to 1.6e-3 J from step to step in free
// flight (the velocities and stresses of a step are staggered in time), a tenth of what is lost.
// Before the heat's mass floor (contact_pair.hpp, kHeatMassFloor) the work was 0.023 J (second
// order) and 0.035 J (first order) against 0.0177 J lost (docs/contact.md, "Frictional work in impacts").
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstdio>

using namespace frictherm::mechanics;

namespace {

// The two blocks on a 40 × 28 × 20 mm grid of cell h (MUSL, C = 0.4): block a moves right and up,
// block b left; they meet on the plane x = 0.02 with a shear velocity.
Simulation<3> oblique_blocks(double h) {
  SimulationOptions o;
  o.cfl = 0.4;
  const IVec<3> cells{static_cast<int>(std::lround(0.04 / h)), static_cast<int>(std::lround(0.028 / h)),
                      static_cast<int>(std::lround(0.02 / h))};
  Simulation<3> sim(Grid<3>(Vec<3>(0, 0, 0), Vec<3>(h, h, h), cells), o);
  Material m;
  m.density = 1000, m.youngs_modulus = 1e8, m.poisson_ratio = 0.3;
  m.name = "a";
  const int a = sim.add_material(m);
  m.name = "b";
  const int b = sim.add_material(m);
  sim.add_body("a", *make_box<3>(Vec<3>(0.006, 0.008, 0.006), Vec<3>(0.020, 0.018, 0.014), a), 2, Vec<3>(20, 8, 0));
  sim.add_body("b", *make_box<3>(Vec<3>(0.020, 0.010, 0.006), Vec<3>(0.034, 0.020, 0.014), b), 2, Vec<3>(-20, -4, 0));
  return sim;
}

}  // namespace

TEST(Contact3D, ObliqueCollisionConservesMomentumWithFiniteHeat) {
  const double h = 0.002;
  Simulation<3> sim = oblique_blocks(h);
  const int a = 0;  // the first material (block b is material 1)
  ContactOptions co;
  co.default_pair.law = FrictionLaw::coulomb(0.3);
  sim.enable_contact(co);
  const auto& p = sim.particles();
  auto momentum = [&] {
    Vec<3> P = Vec<3>::Zero();
    double scale = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) P += p.mass[k] * p.velocity[k], scale += p.mass[k] * p.velocity[k].norm();
    return std::make_pair(P, scale);
  };
  sim.finalize();
  const auto [P0, scale] = momentum();
  const double ke0 = sim.kinetic_energy(), se0 = sim.strain_energy();
  auto body_momentum = [&](int mat) {
    Vec<3> P = Vec<3>::Zero();
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.material[k] == mat) P += p.mass[k] * p.velocity[k];
    return P;
  };
  const Vec<3> Pa0 = body_momentum(a);
  long sliding = 0;
  double drift = 0.0;
  // Mean of kinetic + strain energy and of the books' remainder over the free flight after the impact.
  const double t_free = 260e-6, t_end = 340e-6;
  double e_free = 0.0, remainder_free = 0.0;
  long free_steps = 0, contact_in_free = 0;
  while (sim.time() < t_end) {  // the impact lasts about 250 µs (contact nodes until then)
    sim.step();
    drift = std::max(drift, (momentum().first - P0).norm() / scale);
    sliding += sim.contact_stats().sliding_nodes;
    for (HeatingOrder order : {HeatingOrder::first, HeatingOrder::second})
      for (double w : sim.frictional_work(order)) ASSERT_TRUE(std::isfinite(w) && w >= 0.0);
    if (sim.time() > t_free) {
      const EnergyBalance e = sim.energy_balance(HeatingOrder::second);
      e_free += e.kinetic + e.stored;
      remainder_free += e.numerical_dissipation();
      contact_in_free += sim.contact_stats().contact_nodes;
      ++free_steps;
    }
  }
  ASSERT_GT(free_steps, 20);
  e_free /= static_cast<double>(free_steps);
  remainder_free /= static_cast<double>(free_steps);
  const double exchanged = (body_momentum(a) - Pa0).norm() / Pa0.norm();
  const double w1 = sim.cumulative_frictional_work(HeatingOrder::first);
  const double w2 = sim.cumulative_frictional_work(HeatingOrder::second);
  const double lost = ke0 + se0 - e_free;
  const EnergyBalance books = sim.energy_balance(HeatingOrder::second);
  std::printf("[contact 3D] momentum drift %.2e of sum m|v|, exchanged %.2f of block a's momentum, %ld sliding "
              "node-steps, friction work %.4g J (first order %.4g J), KE0 %.4g J, energy lost (mean over the "
              "free flight) %.4g J: W2/lost %.3f, W1/lost %.3f, mean remainder %.4g J\n",
              drift, exchanged, sliding, w2, w1, ke0, lost, w2 / lost, w1 / lost, remainder_free);
  // Contact changes are equal and opposite at every node; the only loss is the force on nodes lighter
  // than 1e-12 of a particle (docs/contact.md, known limitations: measured up to 2.5e-10 in 2D).
  EXPECT_LT(drift, 1e-9);
  EXPECT_GT(exchanged, 0.3);  // the collision happened
  EXPECT_GT(sliding, 0);
  EXPECT_GT(w2, 0.0);
  EXPECT_EQ(contact_in_free, 0);  // the blocks had separated: the mean is over free flight
  // The books: no loads and no rigid bodies, so what was lost is the start's energy less the end's.
  EXPECT_EQ(books.initial, ke0 + se0);
  EXPECT_EQ(books.external_work + books.rigid_work + books.damping_work + books.plastic_work, 0.0);
  EXPECT_EQ(books.friction_work, w2);
  // The heat is paid for: at either order at most the energy lost (1 %: the mean's own spread, the
  // step-to-step swing of 1.6e-3 J averaged over ≥ 40 steps of a periodic motion). Measured 0.78 and 0.81.
  EXPECT_LE(w2, 1.01 * lost);
  EXPECT_LE(w1, 1.01 * lost);
  // What the friction does not account for is the scheme's own loss (the normal contact stops the
  // approach at the nodes inelastically): not negative. Measured +0.004 J.
  EXPECT_GE(remainder_free, -0.01 * lost);
}

namespace {

struct ImpactEnergy {
  double initial = 0.0, lost = 0.0, w1 = 0.0, w2 = 0.0;
  long contact_in_free = 0;
};

// The set-up above at cell size h (MUSL, position separation, C = 0.4): the energy lost is the initial
// kinetic energy less the mean of kinetic + strain energy over the free flight (260–340 µs).
ImpactEnergy oblique_impact(double h, const FrictionLaw& law, double light_touch_fraction, double sliver_fraction = 0.0) {
  Simulation<3> sim = oblique_blocks(h);
  ContactOptions co;
  co.default_pair.law = law;
  co.light_touch_fraction = light_touch_fraction;
  co.sliver_fraction = sliver_fraction;
  sim.enable_contact(co);
  sim.finalize();
  ImpactEnergy r;
  r.initial = sim.kinetic_energy() + sim.strain_energy();
  double e_free = 0.0;
  long free_steps = 0;
  while (sim.time() < 340e-6) {
    sim.step();
    if (sim.time() > 260e-6) {
      e_free += sim.kinetic_energy() + sim.strain_energy();
      r.contact_in_free += sim.contact_stats().contact_nodes;
      ++free_steps;
    }
  }
  r.lost = r.initial - e_free / static_cast<double>(std::max(free_steps, 1L));
  r.w1 = sim.cumulative_frictional_work(HeatingOrder::first);
  r.w2 = sim.cumulative_frictional_work(HeatingOrder::second);
  return r;
}

}  // namespace

// Where MUSL's frictionless impact gains energy (docs/contact.md, "Where the frictionless impact
// creates energy"): at nodes where one block reaches only with the tails of its particles' shape
// functions, the position test (eq. 8) calls the pair separated and leaves the light field to its own
// stress's push into the other block. Measured at 1 mm cells, C = 0.4 (blocks start with 0.493 J):
// gained 6.25 mJ (1.27 %) without light_touch_fraction, 1.45 mJ (0.29 %) with 0.03. The bound, 0.5 %
// of the initial energy, is three times the mean's own spread (the single-step swing of 1.6e-3 J
// averaged over 80 steps of a periodic motion is under 0.1 %) and fails without the option.
TEST(Contact3D, LightTouchKeepsTheFrictionlessImpactFromGainingEnergy) {
  const ImpactEnergy r = oblique_impact(0.001, FrictionLaw::frictionless(), 0.03);
  std::printf("[contact 3D, 1 mm, frictionless, light touch 0.03] energy lost %.4g J of %.4g J (%.2f %%)\n", r.lost,
              r.initial, 100.0 * r.lost / r.initial);
  EXPECT_EQ(r.contact_in_free, 0);  // the mean is over free flight
  EXPECT_GT(r.lost, -0.005 * r.initial);
}

// Issue 31's check at 1 mm cells: the frictional work at either order is at most the energy lost
// (1 %, as above). It holds with light_touch_fraction 0.03 (no energy gained at the light nodes) and
// sliver_fraction 0.03 (no friction where a material holds under 3 % of the node's mass, the nodes
// the heat's mass floor is about). Measured: lost 6.80 mJ, W2 5.69 mJ (0.84), W1 6.77 mJ (0.996).
// Without them W2 / W1 are 7.03 / 8.20 mJ against 6.64 mJ lost; with light_touch_fraction alone
// 7.87 / 8.29 against 7.62; with sliver_fraction alone 5.34 / 6.47 against 5.02 (docs/contact.md).
TEST(Contact3D, HeatIsPaidForAtOneMillimetreWithLightTouchAndSlivers) {
  const ImpactEnergy r = oblique_impact(0.001, FrictionLaw::coulomb(0.3), 0.03, 0.03);
  std::printf("[contact 3D, 1 mm, mu 0.3, light touch and slivers 0.03] energy lost %.4g J, W2 %.4g J (%.3f), "
              "W1 %.4g J (%.3f)\n", r.lost, r.w2, r.w2 / r.lost, r.w1, r.w1 / r.lost);
  EXPECT_EQ(r.contact_in_free, 0);
  EXPECT_GT(r.w2, 0.0);
  EXPECT_LE(r.w2, 1.01 * r.lost);
  EXPECT_LE(r.w1, 1.01 * r.lost);
}
