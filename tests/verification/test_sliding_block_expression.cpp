// The sliding block of Nairn, Bardenhagen & Smith (2018) under the generalized law of eq 21 written
// as a scene expression ("type": "expression", read by the scene's law parser) against the same law
// built in (FrictionLaw::composite): smooth static → dynamic (μs = 0.35, μd = 0.2, v½ = 0.05 m/s),
// k v_max = 0.3 and S_a = 0.3 N, tangential load R = 1.5 N, at the 2.5 mm cells of the composite
// test in test_sliding_block.cpp. Same law, so the same run up to roundoff: S is computed in another
// order, and the root finder stops at a 1e-14 bracket.
//
// Tolerances. This set-up amplifies roundoff once the block slides fast (the tilting block lifts
// interface nodes off and on, a discontinuous decision): the composite run itself with S_a changed
// by 1e-15 relative ends 1.6e-3 v_max and 2.2e-3 of the work away from the unchanged run (measured).
// So (1) until the block reaches 10 % of its final speed (through the onset of sliding) the two runs
// agree to 1e-6 v_max (measured 6.8e-8), and (2) over the whole run within 5e-3 v_max and 5e-3 of
// the work, the measured roundoff sensitivity with a margin (measured 1.4e-3 and 1.0e-4).
#include "rigid_block_law.hpp"
#include "sliding_block.hpp"

#include <frictherm/coupling/json_reader.hpp>
#include <frictherm/coupling/scene_contact.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

using namespace frictherm;
using namespace frictherm::verification;
using mechanics::FrictionLaw;

namespace {
std::string g17(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}
}  // namespace

TEST(SlidingBlock, ExpressionLawRunsAsTheCompositeLaw) {
  using C = SlidingBlockConstants;
  const double N = C::normal_stress(), k = 0.3 / C::v_max, S_a = 0.3 * N;
  const std::string text = R"({"type": "expression",
      "sliding_traction": "((mu_s*v_half + mu_d*v)/(v_half + v) + k*v)*N + S_a",
      "constants": {"mu_s": 0.35, "mu_d": 0.2, "v_half": 0.05, "k": )" + g17(k) + R"(, "S_a": )" + g17(S_a) + "}}";
  const coupling::Json json = coupling::parse_json_text(text);
  const FrictionLaw expression = coupling::parse_friction_law(coupling::JsonReader(json, "contact.law"));

  SlidingBlockSetup s;
  s.cell = 0.0025;
  s.R = 1.5;
  // The scene defaults for a law with an area term (USL, extent detection). With MUSL and position
  // separation the block floats and tilts; there, with the surface contact area, round-off between
  // the closed form and the root finder grew to 6e-5 of v_max before sliding and 0.6 % by the end.
  s.scheme = mechanics::UpdateScheme::usl;
  s.separation = mechanics::SeparationMethod::extent;
  s.law = FrictionLaw::composite(0.35, 0.2, 0.05, k, S_a);
  const SlidingHistory composite = run_sliding_block(s);
  s.law = expression;
  const SlidingHistory expr = run_sliding_block(s);

  ASSERT_EQ(expr.time.size(), composite.time.size());
  // The law's own rigid block (eq. 48 integrated with its traction, rigid_block_law.hpp).
  const RigidBlockUnderLaw rigid(rigid_solution(0.35, 0.2, k, S_a, 1.5),
                                 smooth_law_traction(N, 0.35, 0.2, 0.05, k, S_a), C::t_final());
  const double v_max = rigid.velocity(C::t_final());
  double dv = 0.0, dv_early = 0.0, dv_rigid = 0.0;
  for (std::size_t i = 0; i < expr.time.size(); ++i) {
    const double d = std::fabs(expr.velocity[i] - composite.velocity[i]) / v_max;
    dv = std::max(dv, d);
    if (composite.velocity[i] < 0.1 * v_max) dv_early = std::max(dv_early, d);
    dv_rigid = std::max(dv_rigid, std::fabs(expr.velocity[i] - rigid.velocity(expr.time[i])) / v_max);
  }
  const double W = composite.work_second.back(), Q = rigid.friction_work(C::t_final());
  const double dW = std::fabs(expr.work_second.back() - W) / W;
  std::printf("[sliding block expression] |v_expr − v_composite|/v_max: %.3g below 0.1 v_max, %.3g over the run; "
              "|W_expr − W_composite|/W = %.3g (W = %.6g J); against the rigid block: velocity %.4f of v_max, work %.4f\n",
              dv_early, dv, dW, W, dv_rigid, std::fabs(expr.work_second.back() - Q) / Q);
  // Before sliding the two differ only where a node sits at its stick/slide threshold and round-off
  // (closed form against root finder, 1e-14) flips it a step apart: measured 3.6e-5 of v_max.
  EXPECT_LT(dv_early, 2e-4);
  EXPECT_LT(dv, 5e-3);
  EXPECT_LT(dW, 5e-3);
  // And so the composite test's bounds against the rigid block (test_sliding_block.cpp) hold.
  // Measured with the scene defaults: 0.56 % of v_max and 0.20 % of the work (against the sharp
  // step's closed form 0.79 % and 2.85 %: that reference's own difference). Bounds: issue 31's 3 %.
  EXPECT_LT(dv_rigid, 0.03);
  EXPECT_LT(std::fabs(expr.work_second.back() - Q) / Q, 0.03);
}
