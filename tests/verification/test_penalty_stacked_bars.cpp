// Two stacked bars under self-weight with penalty contact, EBS against OBS, at six grid offsets
// (Kakouris, Chatzis & Triantafyllou 2024 §4.1, digest §6.1), as 2D strips (ν = 0, plane stress).
//
// Each bar is 0.3 m tall (3 cells of Δh = 0.1 m, 4 × 4 particles per cell, 4 cells wide), the
// bottom one the master. The paper holds the stack with a stiff spring on its bottom point; here an
// upward traction ρ g H (H = 0.6 m) on the bottom particle row balances the weight, as in
// test_ebs_self_weight, so the whole problem moves with the grid offset. Gravity and traction rise
// linearly over 50 periods T = 4H/c (0.028 s, the paper's 200 transit times of the stack) and the
// stress is averaged over 4 more periods. Δt = 0.1 Δt_cr as in the paper. σ_yy(y) = −ρ g (top − y) (eq. 41 with α ≈ 1.6e-7, i.e. linear); at the contact it
// is ρ g h_top = 8190 Pa.
//
// Measured: the stress of the particle rows on both sides of the contact (the paper's "contact
// stress, master top vs slave bottom"), the stack's L1 error (eq. 42) and the penalty force.
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace frictherm::mechanics;

namespace {

constexpr double kH = 0.1, kBar = 0.3, kE = 50.5e9, kRho = 2783.0, kG = 9.81, kWidth = 0.4;
constexpr double kStack = 2 * kBar;
constexpr double kContactStress = kRho * kG * kBar;  // 8190.4 Pa
constexpr double kRampPeriods = 50, kMeanPeriods = 4;

struct StackResult {
  double master_top = 0.0;    // |σ̄ − σ_an| / (ρ g h_top) of the master's top particle row
  double slave_bottom = 0.0;  // same, slave's bottom row
  double mismatch = 0.0;      // |σ̄_master,top − σ̄_slave,bottom| / (ρ g h_top), σ_an subtracted
  double l1 = 0.0;            // eq. 42: Σ |σ − σ_an| V / (|W| l0)
  double force = 0.0;         // mean penalty normal force / (ρ g h_top A)
};

StackResult stack(ShapeKind shape, double offset) {
  SimulationOptions o;
  o.analysis = Analysis::plane_stress;
  o.shape = shape;
  o.scheme = UpdateScheme::musl;
  o.ebs_occupation = 0.75;  // the paper's C_c
  o.cfl = 0.1;              // the paper's Δt = 0.1 Δt_cr (C = 0.5 is tested in test_penalty_stability)
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
  pair.penalty.master = bottom;  // the paper's choice
  sim.set_contact_pair(bottom, top, pair);
  const double x0 = 2 * kH, y0 = 0.2;
  sim.add_body("bottom", *make_box<2>(Vec<2>(x0, y0), Vec<2>(x0 + kWidth, y0 + kBar), bottom), 4, Vec<2>::Zero());
  sim.add_body("top", *make_box<2>(Vec<2>(x0, y0 + kBar), Vec<2>(x0 + kWidth, y0 + kStack), top), 4, Vec<2>::Zero());
  const double c = std::sqrt(kE / kRho), T = 4.0 * kStack / c, t_ramp = kRampPeriods * T, t_end = t_ramp + kMeanPeriods * T;
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
  for (std::size_t k = 0; k < p.size(); ++k) {  // the whole stack moved off the grid by `offset`
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
  StackResult r;
  double num = 0.0, row_m = 0.0, row_s = 0.0;
  int nm = 0, ns = 0;
  const double row = kH / 4;  // particle spacing
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double y = p.initial_position[k][1];
    const double s = mean[k] / t_mean, err = s + kRho * kG * (top_y - y);  // σ − σ_an
    num += std::fabs(err) * p.volume[k];
    if (y < contact_y && y > contact_y - row) row_m += err, ++nm;
    if (y > contact_y && y < contact_y + row) row_s += err, ++ns;
  }
  r.master_top = std::fabs(row_m / nm) / kContactStress;
  r.slave_bottom = std::fabs(row_s / ns) / kContactStress;
  r.mismatch = std::fabs(row_m / nm - row_s / ns) / kContactStress;
  r.l1 = num / (kRho * kG * kStack * kWidth * kStack);  // |W| l0 per unit thickness
  r.force = force / t_mean / (kContactStress * kWidth);
  std::printf("[stacked bars %s offset %.4f m] contact rows: master top %.4f, slave bottom %.4f, mismatch %.4f "
              "(of rho g h_top); L1 (eq. 42) %.2e; penalty force %.5f of the top bar's weight\n",
              to_string(shape), offset, r.master_top, r.slave_bottom, r.mismatch, r.l1, r.force);
  return r;
}

}  // namespace

// Measured (C = 0.1; EBS / OBS over the six offsets):
//   penalty contact stress (mean normal force / A):  0.985–1.021 / 0.994–1.017 of ρ g h_top;
//   stress of the particle rows next to the contact: ≤ 0.11 / up to 0.34 (offsets 0.033 and 0.066,
//     where the plain spline's nodes beside the contact hold a sliver of one bar);
//   L1 error (eq. 42): 5.8e-2–6.6e-2 (flat; the same column without contact gives 3.6e-2–3.9e-2 at
//     this resolution, 3 cells per bar) / 6.6e-2–1.28e-1.
// Bounds: the contact stress within 5 % of ρ g h_top at every offset with EBS (the issue's
// tolerance); EBS's L1 flat across offsets, max/min ≤ 1.3 (the digest suggests 2); OBS's
// offset-dependent error: its worst row error over 2× EBS's and its L1 spread (max/min) above 1.5.
// Time steps of C ≥ 0.2 let a slow instability of EBS with penalty contact grow over tens of periods
// at some offsets (docs/penalty_contact.md), hence the paper's C = 0.1.
TEST(PenaltyStackedBars, EbsContactStressAccurateAtEveryGridOffset) {
  const double offsets[] = {0.0, 0.016, 0.033, 0.05, 0.066, 0.083};  // the paper's, ≈ k Δh/6
  double ebs_l1_min = 1e30, ebs_l1_max = 0.0, obs_l1_min = 1e30, obs_l1_max = 0.0, worst_obs = 0.0, worst_ebs = 0.0;
  for (double off : offsets) {
    const StackResult e = stack(ShapeKind::extended_bspline, off);
    const StackResult q = stack(ShapeKind::quadratic_bspline, off);
    ebs_l1_min = std::min(ebs_l1_min, e.l1);
    ebs_l1_max = std::max(ebs_l1_max, e.l1);
    obs_l1_min = std::min(obs_l1_min, q.l1);
    obs_l1_max = std::max(obs_l1_max, q.l1);
    worst_ebs = std::max({worst_ebs, e.master_top, e.slave_bottom});
    worst_obs = std::max({worst_obs, q.master_top, q.slave_bottom});
    EXPECT_NEAR(e.force, 1.0, 0.05) << "EBS, offset " << off;
    EXPECT_NEAR(q.force, 1.0, 0.05) << "OBS, offset " << off;
    EXPECT_LT(e.master_top, 0.15) << "EBS, offset " << off;
    EXPECT_LT(e.slave_bottom, 0.15) << "EBS, offset " << off;
  }
  std::printf("[stacked bars] worst contact-row error EBS %.4f, OBS %.4f; L1 EBS %.2e..%.2e, OBS %.2e..%.2e\n",
              worst_ebs, worst_obs, ebs_l1_min, ebs_l1_max, obs_l1_min, obs_l1_max);
  EXPECT_LT(ebs_l1_max / ebs_l1_min, 1.3);
  EXPECT_GT(worst_obs, 2.0 * worst_ebs);
  EXPECT_GT(obs_l1_max / obs_l1_min, 1.5);
}
