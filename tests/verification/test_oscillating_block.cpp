// Oscillating block (Nairn, Bardenhagen & Smith 2018, figures 6–7): total frictional work of one
// stick–slide–stick interval against the CFL factor C, first and second order heating.
//
// The paper has no analytic value; it shows that both orders converge to the same work as C → 0 and
// that the second order converges faster. We measure (uGIMP, 2.5 mm cells, pushers bonded to the top
// 5/6 of the block's sides):
//   C      1st order   2nd order
//   0.5    0.0358 J    0.0204 J
//   0.25   0.0160 J    0.0112 J
//   0.1    0.00938 J   0.00853 J
//   0.05   0.00863 J   0.00835 J
//   0.025  0.00837 J   0.00829 J
//   0.0125 0.00829 J   0.00827 J
// so the second order is within 2 % of the converged work from C = 0.05 and the first order from
// C = 0.025 — faster convergence, but not the paper's "C < 0.5 against ten times smaller": our
// pushers are rigid materials bonded to the block, the paper's set-up is not fully specified (see
// docs/contact.md). The test asserts what the paper states qualitatively.
#include "oscillating_block.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using frictherm::verification::OscillatingBlock;

TEST(OscillatingBlock, SecondOrderHeatingConvergesFaster) {
  const double cfl[] = {0.5, 0.25, 0.1, 0.05};
  const OscillatingBlock::Work ref = OscillatingBlock::run(0.025);
  std::printf("[oscillating block] C = 0.025: W1 = %.6g J, W2 = %.6g J (%ld steps)\n", ref.first, ref.second, ref.steps);
  // Both orders reach the same value: the second-order correction W2/2 is O(dt) per sliding step.
  EXPECT_NEAR(ref.first, ref.second, 0.015 * ref.second);
  EXPECT_GT(ref.second, 0.0);
  for (double c : cfl) {
    const OscillatingBlock::Work w = OscillatingBlock::run(c);
    const double e1 = std::fabs(w.first - ref.second) / ref.second, e2 = std::fabs(w.second - ref.second) / ref.second;
    std::printf("[oscillating block] C = %.3g: W1 = %.6g J (error %.1f %%), W2 = %.6g J (error %.1f %%)\n", c, w.first,
                100 * e1, w.second, 100 * e2);
    EXPECT_LT(e2, e1) << "second order must be closer to the converged work at C = " << c;
  }
}
