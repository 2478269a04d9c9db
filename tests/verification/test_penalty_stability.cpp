// Stability of penalty contact with Extended B-splines at the usual time step (docs/penalty_contact.md,
// "Stability"). The boundary points move with the nodal velocity the step's stress update uses (MUSL:
// the remapped one). Moved with the pre-remap velocity, the penalty spring and the bodies' elasticity
// were integrated with two different velocities and the loop gained energy at every time step (growth
// per step ∝ Δt²): the stacked bars below blew up at C = 0.5 at three of the six grid offsets
// (contact stress 1.7× and 0×, L1 up to 1e3), and the EBS sliding block blew up at C = 0.5, 0.2
// and 0.1 (the last at 12 ms).
//
// 1. The stacked bars of test_penalty_stacked_bars (Kakouris et al. 2024 §4.1: two 0.3 m bars of 3
//    cells, 4 × 4 particles per cell, frictionless penalty contact, the stack held by a traction on
//    its bottom row, gravity ramped over 50 periods, stress averaged over 4 more) with EBS at C = 0.5
//    instead of the paper's 0.1.
// 2. Nairn's sliding block (sliding_block.hpp; Coulomb μ = 0.2, base the master) with EBS and
//    penalty contact at C = 0.5 through the load ramps, up to the onset of sliding. (The sliding phase
//    with EBS at C = 0.5 still blows up at 10.5 ms, from another cause: docs/penalty_contact.md.)
#include "sliding_block.hpp"

#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

using namespace frictherm;
using namespace frictherm::mechanics;
using namespace frictherm::verification;

namespace {

constexpr double kH = 0.1, kBar = 0.3, kE = 50.5e9, kRho = 2783.0, kG = 9.81, kWidth = 0.4;
constexpr double kStack = 2 * kBar, kContactStress = kRho * kG * kBar;

struct StackResult {
  double force = 0.0;  // mean penalty normal force / (ρ g h_top A)
  double rows = 0.0;   // largest |σ̄ − σ_an| / (ρ g h_top) of the particle rows beside the contact
  double l1 = 0.0;     // eq. 42
};

StackResult stacked_bars(double offset, double cfl) {
  SimulationOptions o;
  o.analysis = Analysis::plane_stress;
  o.shape = ShapeKind::extended_bspline;
  o.scheme = UpdateScheme::musl;
  o.ebs_occupation = 0.75;
  o.cfl = cfl;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(kH, kH), IVec<2>{8, 11}), o);
  Material m;
  m.density = kRho;
  m.youngs_modulus = kE;
  m.poisson_ratio = 0.0;
  m.name = "bottom";
  const int bottom = sim.add_material(m);
  m.name = "top";
  const int top = sim.add_material(m);
  ContactOptions co;
  co.default_pair.method = ContactMethod::penalty;
  co.default_pair.law = FrictionLaw::frictionless();
  sim.enable_contact(co);
  ContactPairSettings pair = co.default_pair;
  pair.penalty.master = bottom;
  sim.set_contact_pair(bottom, top, pair);
  const double x0 = 2 * kH, y0 = 0.2;
  sim.add_body("bottom", *make_box<2>(Vec<2>(x0, y0), Vec<2>(x0 + kWidth, y0 + kBar), bottom), 4, Vec<2>::Zero());
  sim.add_body("top", *make_box<2>(Vec<2>(x0, y0 + kBar), Vec<2>(x0 + kWidth, y0 + kStack), top), 4, Vec<2>::Zero());
  const double c = std::sqrt(kE / kRho), T = 4.0 * kStack / c, t_ramp = 50 * T, t_end = t_ramp + 4 * T;
  const TimeFunction ramp = TimeFunction::ramp(1.0, t_ramp);
  EdgeTraction<2> support;
  support.body = 0;
  support.axis = 1;
  support.upper = false;
  support.traction = Vec<2>(0.0, kRho * kG * kStack);
  support.scale = ramp;
  sim.add_edge_traction(support);
  sim.finalize();
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k) {
    p.position[k][1] += offset;
    p.initial_position[k][1] += offset;
  }
  auto& bp = sim.boundary_points();
  for (std::size_t i = 0; i < bp.size(); ++i) {
    bp.position[i][1] += offset;
    bp.reference_position[i][1] += offset;
  }
  const double top_y = y0 + kStack + offset, contact_y = y0 + kBar + offset;
  std::vector<double> mean(p.size(), 0.0);
  double t_mean = 0.0, force = 0.0;
  StackResult r;
  try {
    while (sim.time() < t_end) {
      const double t = sim.time();
      sim.options().gravity = Vec<3>(0.0, -kG * ramp(t), 0.0);
      const double dt = sim.step(t < t_ramp ? t_ramp - t : t_end - t);
      if (sim.time() > t_ramp) {
        for (std::size_t k = 0; k < p.size(); ++k) mean[k] += p.stress[k](1, 1) * dt;
        force += sim.penalty_contact()->books(0).normal_force * dt;
        t_mean += dt;
      }
    }
  } catch (const SimulationError& e) {
    std::printf("[stacked bars EBS C = %.2f offset %.3f m] blew up: %s\n", cfl, offset, e.what());
    r.force = r.rows = r.l1 = std::numeric_limits<double>::infinity();
    return r;
  }
  double num = 0.0, row_m = 0.0, row_s = 0.0;
  int nm = 0, ns = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double y = p.initial_position[k][1];
    const double err = mean[k] / t_mean + kRho * kG * (top_y - y);
    num += std::fabs(err) * p.volume[k];
    if (y < contact_y && y > contact_y - kH / 4) row_m += err, ++nm;
    if (y > contact_y && y < contact_y + kH / 4) row_s += err, ++ns;
  }
  r.force = force / t_mean / (kContactStress * kWidth);
  r.rows = std::max(std::fabs(row_m / nm), std::fabs(row_s / ns)) / kContactStress;
  r.l1 = num / (kRho * kG * kStack * kWidth * kStack);
  std::printf("[stacked bars EBS C = %.2f offset %.3f m] penalty force %.5f of the top bar's weight, contact rows "
              "%.4f of rho g h_top, L1 (eq. 42) %.2e\n",
              cfl, offset, r.force, r.rows, r.l1);
  return r;
}

}  // namespace

// Measured (C = 0.5): penalty force 1.0000–1.0022 of the weight, contact rows ≤ 0.063, L1 5.8e-2–6.3e-2
// at every offset: the same as at the paper's C = 0.1 (test_penalty_stacked_bars: 0.985–1.021, ≤ 0.11,
// 5.8e-2–6.6e-2). Bounds: the force within 2 % (the 5 % tightened to the C = 0.1 spread), the
// rows below 0.15 and L1 below 0.1 (the C = 0.1 bounds); before the fix three offsets failed all three.
TEST(PenaltyStability, EbsStackedBarsHoldContactStressAtCfl05) {
  for (double off : {0.0, 0.016, 0.033, 0.05, 0.066, 0.083}) {
    const StackResult r = stacked_bars(off, 0.5);
    EXPECT_NEAR(r.force, 1.0, 0.02) << "offset " << off;
    EXPECT_LT(r.rows, 0.15) << "offset " << off;
    EXPECT_LT(r.l1, 0.1) << "offset " << off;
  }
}

// Measured (C = 0.5, the normal load's ramp and the tangential ramp up to sliding, 0–5 ms): every one
// of the 17 bottom points in contact at every step after the first 0.1 ms, the block's mean vertical
// speed at most 9.1e-4 m/s, its kinetic energy at most 4.0e-10 J. Before the fix the block rocked up from 0.6 ms (kinetic energy
// growing tenfold every ~100 steps), lost contact entirely at 1.3 ms and blew up at 6.5 ms. Bounds:
// no step with fewer than 17 contacts after 0.1 ms, |v_y| below 2e-3 m/s.
TEST(PenaltyStability, EbsSlidingBlockRestsQuietlyAtCfl05) {
  using C = SlidingBlockConstants;
  SlidingBlockSetup s;
  s.law = FrictionLaw::coulomb(C::mu);
  s.method = ContactMethod::penalty;
  s.shape = ShapeKind::extended_bspline;
  s.cfl = 0.5;
  int block = 0;
  Simulation<2> sim = make_sliding_block(s, block);
  const double t_end = 5e-3;  // the rigid block starts sliding at 5.38 ms
  long fewest = 1000;
  double vy = 0.0, ke = 0.0;
  ASSERT_NO_THROW({
    while (sim.time() < t_end) {
      sim.step(t_end - sim.time());
      if (sim.time() > 1e-4) fewest = std::min(fewest, sim.contact_stats().penalty_contacts);  // after first touch
      vy = std::max(vy, std::fabs(mean_velocity(sim, block, Vec<2>(0, 1))));
      const auto& p = sim.particles();
      double e = 0.0;
      for (std::size_t k = 0; k < p.size(); ++k)
        if (p.material[k] == block) e += 0.5 * p.mass[k] * p.velocity[k].squaredNorm();
      ke = std::max(ke, e);
    }
  });
  std::printf("[EBS penalty sliding block C = 0.5, 0-5 ms] fewest contacts %ld, max |mean v_y| %.3e m/s, max block "
              "kinetic energy %.3e J\n",
              fewest, vy, ke);
  EXPECT_EQ(fewest, 17);
  EXPECT_LT(vy, 2e-3);
}
