// Normal-stress regularisation of friction (ContactOptions::regularization_*, docs/contact.md,
// "Normal-stress regularisation"). Coulomb-type friction that follows the instantaneous normal
// traction makes a block sliding on an elastic or rigid base vibrate at the grid scale; the one-sided
// contact rectifies the vibration and the whole block floats (the continuum problem's slip-wave
// instability: Adams 1995, Ranjith & Rice 2001; opening waves at high friction, Yastrebov 2015). A
// friction law that sees a lagged normal traction (Prakash–Clifton form, Cochard & Rice 2000) keeps
// the interface closed. Checked on the sliding block of Nairn, Bardenhagen & Smith (2018), figure 2:
//  * Coulomb μ = 0.5 at 2.5 mm: without regularisation the block floats (measured 165 µm); with it
//    the block stays on its base and matches the rigid block;
//  * adhesion (μ = 0.2, S_a = 0.3 N): the velocity error against the rigid block falls with the cell
//    size over 5, 2.5 and 1.25 mm and is within 2 % of v_max at 1.25 mm, the work within 2 %.
#include "sliding_block.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace frictherm;
using namespace frictherm::verification;
using mechanics::FrictionLaw;
using mechanics::SeparationMethod;

namespace {

// L = 2.5 mm and τ = 50 µs: the lag is about 80 steps at the 2.5 mm cells and C = 0.5, short against
// the 13.4 ms of loading and sliding (τ/t_slide < 1 %) and long against the grid-scale vibration period
// (h/c ≈ 1.3 µs). The same physical values at every cell size, so refinement converges to one model.
constexpr double kSlipLength = 0.0025, kTime = 5e-5;

struct Measured {
  double velocity_error, work_error, max_lift;
};

Measured measure(SlidingBlockSetup s, const RigidBlock& r, const char* name) {
  const SlidingHistory h = run_sliding_block(s);
  const double tf = SlidingBlockConstants::t_final(), v_max = r.velocity(tf), Q = r.friction_work(tf);
  Measured m{0.0, std::fabs(h.work_second.back() - Q) / Q, 0.0};
  for (std::size_t k = 0; k < h.time.size(); ++k) {
    m.velocity_error = std::max(m.velocity_error, std::fabs(h.velocity[k] - r.velocity(h.time[k])) / v_max);
    m.max_lift = std::max(m.max_lift, h.lift[k]);
  }
  std::printf("[%s, %.2f mm cells] max |v - v_rigid|/v_max %.4f (own v_max %.2f m/s), work error %.4f, "
              "largest mean lift of the block %.2f um\n",
              name, s.cell * 1e3, m.velocity_error, v_max, m.work_error, m.max_lift * 1e6);
  return m;
}

}  // namespace

TEST(ContactRegularization, HighFrictionBlockStaysOnItsBase) {
  SlidingBlockSetup s;
  s.cell = 0.0025;
  s.law = FrictionLaw::coulomb(0.5);
  const RigidBlock r = rigid_solution(0.5, 0.5, 0.0, 0.0);
  const Measured plain = measure(s, r, "Coulomb 0.5, instantaneous N");
  s.regularization_slip_length = kSlipLength, s.regularization_time = kTime;
  const Measured lagged = measure(s, r, "Coulomb 0.5, lagged N");
  // The block is pressed down by N: its mean lift can only be its elastic rebound, well under 1 µm
  // (the preload compresses block and base by about 1.3 µm). Unregularised it floats by about 165 µm.
  EXPECT_GT(plain.max_lift, 20e-6);
  EXPECT_LT(lagged.max_lift, 1e-6);
  EXPECT_LT(lagged.velocity_error, 0.01);
  EXPECT_LT(lagged.work_error, 0.02);
}

// A rate law, μ = 0.2 + k v with k v_max = 0.5 (figure 3's), under the scene defaults (USL, extent
// detection) with the regularisation. Its friction rises to 0.7 N at the end, and there the interface's
// grid-scale vibration parts a few touching nodes every step (their surfaces move apart while the
// domains still meet). Those nodes keep the friction of their lagged traction: when they lost it
// (the law saw σ̃ only where the pair approached, and σ̃, unlike the instantaneous N, does not make the
// lost impulse up on the next step) the block ran 1.25 / 2.70 / 3.85 % of v_max fast at 5 / 2.5 /
// 1.25 mm with −2.2 / −3.5 / −4.8 % of the work. Measured now 0.71 / 0.82 / 0.83 % and +0.38 / +0.69 /
// +0.98 %; the bound 1.5 % sits between.
TEST(ContactRegularization, RateLawKeepsItsFrictionWhereTouchingSurfacesPart) {
  const double k = 0.5 / SlidingBlockConstants::v_max;
  const RigidBlock r = rigid_solution(0.2, 0.2, k, 0.0);
  for (double cell : {0.005, 0.0025}) {
    SlidingBlockSetup s;
    s.cell = cell;
    s.scheme = mechanics::UpdateScheme::usl;
    s.separation = SeparationMethod::extent;
    s.law = FrictionLaw::linear_velocity(0.2, k);
    s.regularization_slip_length = kSlipLength, s.regularization_time = kTime;
    const Measured m = measure(s, r, "mu = 0.2 + k v, lagged N");
    EXPECT_LT(m.velocity_error, 0.015);
    EXPECT_LT(m.work_error, 0.015);
    EXPECT_LT(m.max_lift, 1e-6);
  }
}

// Both updates: MUSL (the library's default) and USL (what a scene with grid contact gets).
class AdhesionRefinement : public ::testing::TestWithParam<mechanics::UpdateScheme> {};

TEST_P(AdhesionRefinement, AdhesionBlockConvergesWithRefinement) {
  const double S_a = 0.3 * SlidingBlockConstants::normal_stress();
  const RigidBlock r = rigid_solution(0.2, 0.2, 0.0, S_a);
  std::vector<Measured> m;
  for (double cell : {0.005, 0.0025, 0.00125}) {
    SlidingBlockSetup s;
    s.scheme = GetParam();
    s.cell = cell;
    s.separation = SeparationMethod::extent;  // the scene default for a law with an area term
    s.law = FrictionLaw::adhesion(0.2, S_a);
    s.regularization_slip_length = kSlipLength, s.regularization_time = kTime;
    m.push_back(measure(s, r, "adhesion, lagged N"));
  }
  // With the gap-closing stop of extent detection every cell is within 1 % of v_max and of the work
  // (USL 0.31 / 0.13 / 0.19 %, MUSL 0.16 / 0.11 / 0.76 % at 5 / 2.5 / 1.25 mm): the errors no longer
  // fall monotonically, they sit at the interface vibration's scatter. The target is 2 %.
  for (const Measured& x : m) {
    EXPECT_LT(x.velocity_error, 0.01);
    EXPECT_LT(x.work_error, 0.01);
    EXPECT_LT(x.max_lift, 1e-6);
  }
}

INSTANTIATE_TEST_SUITE_P(ContactRegularization, AdhesionRefinement,
                         ::testing::Values(mechanics::UpdateScheme::musl, mechanics::UpdateScheme::usl),
                         [](const auto& param_info) { return std::string(mechanics::to_string(param_info.param)); });
