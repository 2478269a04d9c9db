// Spurious frictional heat (issue: heat a user can trust at C = 0.5). Three benchmarks on the
// oscillating block of Nairn et al. 2018 (figure 6, oscillating_block.hpp):
//   held block    the pushers stay still after the preload: all work after it is spurious;
//   pressed block no pushers at all, the block pressed onto its base and left alone: likewise;
//   oscillating   the work of one stick–slide–stick interval against the CFL factor C.
// "Trusted" is the combination the example scenes use: a quasi-static preload (mass-proportional
// damping over the ramp and 0.2 ms more, so the column is at rest when the pushers start),
// displacement separation (position separation lets the compressed interface float apart: with a
// settled preload it reports no friction at all), and a FLIP/PIC blend with τ = 15 µs (30 steps at
// C = 0.5) against FLIP noise. The paper's set-up as test_oscillating_block runs it (no settling,
// position separation, pure FLIP) is run beside it to show what goes wrong there.
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
  v.pic_relaxation_time = 15e-6;
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
    EXPECT_LT(spurious, 0.05 * rubbing) << "C = " << cfl;  // measured 1.4 % and 1.0 %
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
    EXPECT_LT(std::abs(w / ref - 1.0), 0.05) << "C = " << cfl;  // measured +4.1 %, +0.4 %, -1.1 %
  }
}

TEST(SpuriousHeat, PressedBlockCreepMeasured) {
  // Open: the pressed block keeps creeping at a few nodes after the preload (KE ~1e-6 J), so its
  // work does not vanish; measured 26 % of the oscillating block's rubbing work at C = 0.5 and 61 %
  // at C = 0.1 (it grows with the number of steps: a per-step slip). The bound guards against
  // regressions until the creep is understood (docs/contact.md, "Spurious heat").
  OscillatingBlockVariant pressed = trusted();
  pressed.pushers = false;
  const double rubbing = second_order_work(0.5, trusted()), creep = second_order_work(0.5, pressed);
  std::printf("[pressed block, trusted, C = 0.5] spurious %.4f mJ = %.1f %% of the rubbing work %.4f mJ\n",
              1e3 * creep, 100 * creep / rubbing, 1e3 * rubbing);
  EXPECT_LT(creep, 0.35 * rubbing);
  EXPECT_GE(creep, 0.0);
}
