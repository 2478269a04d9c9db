// Static and dynamic friction, μs = 0.4 and μd = 0.2 (Nairn, Bardenhagen & Smith 2018, §2.8, §3 and
// figure 4) on the sliding block of figure 2 (the load stays sized for μ = 0.2 Coulomb, v_max =
// 31.6 m/s; with μs = 0.4 sliding starts later and the rigid solution accounts for it):
//   - the naive law (stick test with μs, slide with μd) starts sliding early: the known failure;
//   - the smooth law of eq. 42 with v½ = 0.05 m/s follows the rigid static/dynamic block (its β term);
//   - with v½ = 1000 m/s it is μ = 0.4 Coulomb.
#include "rigid_block_law.hpp"
#include "sliding_block.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm;
using namespace frictherm::verification;
using mechanics::FrictionLaw;

namespace {

struct Result {
  double velocity_error;  // max |v − v_rigid| / v_max
  double onset;           // first sample with v > 1 % of v_max (s)
  double rigid_onset;     // where the rigid solution reaches 1 % of v_max (s)
};

template <class Reference>
Result run(const FrictionLaw& law, const Reference& r, const char* name, double cell = 0.005) {
  using C = SlidingBlockConstants;
  SlidingBlockSetup s;
  s.law = law;
  s.cell = cell;
  const SlidingHistory h = run_sliding_block(s);
  Result out{0.0, C::t_final(), r.onset()};
  for (std::size_t k = 0; k < h.time.size(); ++k) {
    out.velocity_error = std::max(out.velocity_error, std::fabs(h.velocity[k] - r.velocity(h.time[k])) / C::v_max);
    if (out.onset == C::t_final() && h.velocity[k] > 0.01 * C::v_max) out.onset = h.time[k];
  }
  while (r.velocity(out.rigid_onset) < 0.01 * C::v_max) out.rigid_onset += 1e-7;
  const double slide = C::t_final() - r.onset();
  std::printf("[static/dynamic %s] max |v − v_rigid|/v_max = %.4f; onset %.4f ms vs rigid %.4f ms "
              "(%+.3f of the rigid sliding time); final v %.3f m/s (rigid %.3f)\n",
              name, out.velocity_error, 1e3 * out.onset, 1e3 * out.rigid_onset, (out.onset - out.rigid_onset) / slide,
              h.velocity.back(), r.velocity(C::t_final()));
  return out;
}

}  // namespace

TEST(StaticDynamicFriction, NaiveLawStartsSlidingEarly) {
  using C = SlidingBlockConstants;
  const RigidBlock r = rigid_solution(0.4, 0.2, 0.0, 0.0);
  const Result naive = run(FrictionLaw::static_dynamic(0.4, 0.2), r, "naive");
  // The paper's known failure (§3, "sliding started earlier than predicted by static conditions").
  // The rigid onset is t_i = t2 + 0.4 ts (μ = 0.2 would give t2 + 0.2 ts). We measured the naive onset
  // 0.085 ts (0.14 of the rigid sliding time) early. We require at least 0.05 ts: five velocity
  // samples, and 3.5 times the 2 % of the sliding time within which the Coulomb and smooth laws find
  // their onset, so the failure is not noise. Its velocity then misses the rigid solution by more
  // than the 3 % the smooth law meets.
  const double ts = C::t_final() - 0.25 * C::t_final();
  std::printf("[static/dynamic naive] onset earlier than the rigid one by %.3f ts (the μ = 0.2 onset is 0.200 ts "
              "earlier)\n",
              (naive.rigid_onset - naive.onset) / ts);
  EXPECT_LT(naive.onset, naive.rigid_onset - 0.05 * ts);
  EXPECT_GT(naive.velocity_error, 0.03);
}

TEST(StaticDynamicFriction, SmoothLawWithSmallHalfSpeedMatchesRigidStaticDynamic) {
  // Figure 4: v½ = 0.05 m/s "matches very well" the rigid static/dynamic solution. Bound: the
  // issue's 3 % of v_max (the kink at onset makes this case harder than Coulomb's 2 %).
  const Result smooth = run(FrictionLaw::smooth_static_dynamic(0.4, 0.2, 0.05), rigid_solution(0.4, 0.2, 0.0, 0.0),
                            "smooth v½ = 0.05 m/s");
  EXPECT_LT(smooth.velocity_error, 0.03);
}

TEST(StaticDynamicFriction, SmoothLawWithLargeHalfSpeedIsCoulombMuStatic) {
  // v½ = 1000 m/s: μ stays within (0.4 − 0.2)·v/(v½ + v) < 0.007 of μs up to 31.6 m/s, so the block
  // follows μ = 0.4 Coulomb within the 3 % of v_max.
  const Result smooth = run(FrictionLaw::smooth_static_dynamic(0.4, 0.2, 1000.0), rigid_solution(0.4, 0.4, 0.0, 0.0),
                            "smooth v½ = 1000 m/s");
  EXPECT_LT(smooth.velocity_error, 0.03);
}

// v½ = 1 m/s, between the two limits: the coefficient falls from μs to μd over the block's first
// metres per second, so neither closed form is the block's motion (the sharp μs → μd step ends 11 %
// faster). Against its own rigid block (eq. 48 integrated with eq. 42's traction, rigid_block_law.hpp)
// measured 0.09 % / 0.05 % of v_max at 5 / 2.5 mm; against the sharp step 9.5 %, the law's difference.
// Bound: the 3 % at both cells.
TEST(StaticDynamicFriction, SmoothLawWithUnitHalfSpeedMatchesItsRigidBlock) {
  using C = SlidingBlockConstants;
  const RigidBlock loads = rigid_solution(0.4, 0.2, 0.0, 0.0);
  const RigidBlockUnderLaw exact(loads, smooth_law_traction(C::normal_stress(), 0.4, 0.2, 1.0), C::t_final());
  for (double cell : {0.005, 0.0025}) {
    const Result smooth = run(FrictionLaw::smooth_static_dynamic(0.4, 0.2, 1.0), exact, "smooth v½ = 1 m/s", cell);
    EXPECT_LT(smooth.velocity_error, 0.03) << "cell " << cell;
  }
}
