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
#include "stacked_bars.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

using namespace frictherm::mechanics;
using frictherm::verification::run_stacked_bars;
using frictherm::verification::StackedBarsResult;

namespace {

StackedBarsResult stack(ShapeKind shape, double offset) {
  const StackedBarsResult r = run_stacked_bars(shape, offset, 0.1);  // the paper's Δt = 0.1 Δt_cr
  std::printf("[stacked bars %s offset %.4f m] contact rows: master top %.4f, slave bottom %.4f, mismatch %.4f "
              "(of rho g h_top); L1 (eq. 42) %.2e; penalty force %.5f of the top bar's weight%s%s\n",
              to_string(shape), offset, r.master_top, r.slave_bottom, r.mismatch, r.l1, r.force,
              r.failure.empty() ? "" : "; blew up: ", r.failure.c_str());
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
    const StackedBarsResult e = stack(ShapeKind::extended_bspline, off);
    const StackedBarsResult q = stack(ShapeKind::quadratic_bspline, off);
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
