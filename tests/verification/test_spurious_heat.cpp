// Spurious frictional heat (issue: heat a user can trust at C = 0.5). Three benchmarks on the
// oscillating block of Nairn et al. 2018 (figure 6, oscillating_block.hpp):
//   held block    the pushers stay still after the preload: all work after it is spurious;
//   pressed block no pushers at all, the block pressed onto its base and left alone: likewise;
//   oscillating   the work of one stick–slide–stick interval against the CFL factor C.
// "Trusted" is the combination the example scenes use: a quasi-static preload (mass-proportional
// damping over the ramp and 0.2 ms more, so the column is at rest when the pushers start),
// displacement separation (position separation lets the compressed interface float apart: with a
// settled preload it reports no friction at all), and the USL update with pure FLIP. MUSL (the
// default) makes the corner nodes creep: its second projection and contact pass give the block's
// corner particles a per-step slip at the node just outside each corner, where the Poisson bulge puts
// ~1 % of the node's mass (measured on the pressed block at C = 0.5: 286 % of the rubbing work with
// MUSL, 26 % with MUSL and a FLIP/PIC blend, 0 with USL). The paper's set-up as test_oscillating_block runs it (no
// settling, position separation, pure FLIP, MUSL) is run beside it to show what goes wrong there.
#include "oscillating_block.hpp"

#include <gtest/gtest.h>

#include <cstdio>

using namespace frictherm;
using verification::OscillatingBlock;
using verification::OscillatingBlockVariant;

namespace {

OscillatingBlockVariant trusted() {
  OscillatingBlockVariant v;
  v.settled = true;
  v.separation = mechanics::SeparationMethod::displacement;
  v.scheme = mechanics::UpdateScheme::usl;
  return v;
}

double second_order_work(double cfl, OscillatingBlockVariant v) {
  return OscillatingBlock::run(cfl, mechanics::ShapeKind::ugimp, v).second;
}

}  // namespace

TEST(SpuriousHeat, HeldBlockBelowFivePercentOfRubbingAtHalfCfl) {
  for (double cfl : {0.5, 0.25}) {
    OscillatingBlockVariant held = trusted();
    held.held = true;
    const double rubbing = second_order_work(cfl, trusted()), spurious = second_order_work(cfl, held);
    std::printf("[held block, trusted, C = %g] spurious %.4f mJ, rubbing %.4f mJ: %.1f %%\n", cfl, 1e3 * spurious,
                1e3 * rubbing, 100 * spurious / rubbing);
    EXPECT_LT(spurious, 0.05 * rubbing) << "C = " << cfl;  // measured 0.06 % and 0.1 %
    EXPECT_GE(spurious, 0.0);
  }
  // The paper's set-up: the ringing column and FLIP noise make the held block heat more than the
  // oscillation itself (measured 10.0 mJ against a converged 5.7 mJ of the oscillating block).
  OscillatingBlockVariant paper_held;
  paper_held.held = true;
  const double paper = second_order_work(0.5, paper_held), paper_rubbing = second_order_work(0.5, {});
  std::printf("[held block, paper's set-up, C = 0.5] spurious %.4f mJ, oscillating %.4f mJ\n", 1e3 * paper,
              1e3 * paper_rubbing);
  EXPECT_GT(paper, 0.3 * paper_rubbing);  // measured 54 %
}

TEST(SpuriousHeat, OscillatingBlockWorkAtHalfCflWithinFivePercentOfSmallCfl) {
  // Reference: C = 0.05 (C = 0.025 differs from it by ~1 % in the scene runs of docs/contact.md).
  const double ref = second_order_work(0.05, trusted());
  for (double cfl : {0.5, 0.25, 0.1}) {
    const double w = second_order_work(cfl, trusted());
    std::printf("[oscillating block, trusted] C = %g: W2 = %.4f mJ, %+.2f %% of C = 0.05 (%.4f mJ)\n", cfl, 1e3 * w,
                100 * (w / ref - 1), 1e3 * ref);
    EXPECT_LT(std::abs(w / ref - 1.0), 0.05) << "C = " << cfl;  // measured +0.08 %, +0.5 %, +0.5 %
  }
}

TEST(SpuriousHeat, PressedBlockWorkVanishes) {
  // No pushers: after the preload nothing should rub. Measured with the trusted combination: 0.0000 mJ
  // at C = 0.5, 0.25 and 0.1. Bound: 1 % of the rubbing work (a fifth of the held block's target).
  OscillatingBlockVariant pressed = trusted();
  pressed.pushers = false;
  for (double cfl : {0.5, 0.1}) {
    const double rubbing = second_order_work(cfl, trusted()), creep = second_order_work(cfl, pressed);
    std::printf("[pressed block, trusted, C = %g] spurious %.4f mJ = %.2f %% of the rubbing work %.4f mJ\n", cfl,
                1e3 * creep, 100 * creep / rubbing, 1e3 * rubbing);
    EXPECT_LT(creep, 0.01 * rubbing) << "C = " << cfl;
    EXPECT_GE(creep, 0.0);
  }
  // MUSL with the same preload used to creep at the two nodes just outside the block's corners
  // (9.7 mJ, 286 % of the rubbing work, with pure FLIP): the end-of-step slip of the sliver of block
  // mass there, a small-mass node's velocity. Since the heat's mass floor (issue 31, contact_pair.hpp
  // kHeatMassFloor) it does not: measured 0.0000 mJ. Bound: as the trusted combination, 1 %.
  OscillatingBlockVariant musl = pressed;
  musl.scheme = mechanics::UpdateScheme::musl;
  const double musl_creep = second_order_work(0.5, musl), rubbing = second_order_work(0.5, trusted());
  std::printf("[pressed block, MUSL, C = 0.5] spurious %.4f mJ = %.1f %% of the rubbing work\n", 1e3 * musl_creep,
              100 * musl_creep / rubbing);
  EXPECT_LT(musl_creep, 0.01 * rubbing);
  EXPECT_GE(musl_creep, 0.0);
}
