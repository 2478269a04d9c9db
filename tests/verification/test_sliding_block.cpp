// Sliding block (Nairn, Bardenhagen & Smith 2018, figures 2, 3 and 5): the MPM block's mean velocity
// and the total frictional work against the rigid-block solution (appendix eqs. 46–54).
#include "rigid_block_law.hpp"
#include "sliding_block.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm;
using namespace frictherm::verification;
using mechanics::FrictionLaw;

namespace {

struct Comparison {
  double velocity_error = 0.0;  // max |v_MPM − v_rigid| / v_max over the samples, v_max = the case's own rigid v(tf)
  double onset_error = 0.0;     // |t_onset,MPM − t_onset,rigid| / sliding time
  double work_error = 0.0;      // |W_MPM − Q| / Q at tf
  double work_order_gap = 0.0;  // |W2nd − W1st| / Q at tf
};

// `Reference`: RigidBlock (the closed forms) or RigidBlockUnderLaw (any law, integrated).
template <class Reference>
Comparison compare(const SlidingHistory& h, const Reference& r, const char* name) {
  using C = SlidingBlockConstants;
  Comparison c;
  const double tf = C::t_final(), ti = r.onset();
  // Errors relative to the case's own scale: the rigid block's final (largest) speed, not the
  // Coulomb case's 31.6 m/s, which would make slower laws' errors look smaller.
  const double v_max = r.velocity(tf);
  double onset = tf;
  for (std::size_t k = 0; k < h.time.size(); ++k) {
    c.velocity_error = std::max(c.velocity_error, std::fabs(h.velocity[k] - r.velocity(h.time[k])) / v_max);
    if (onset == tf && h.velocity[k] > 0.01 * v_max) onset = h.time[k];
  }
  // Onset: where the rigid solution reaches 1 % of v_max, compared with the MPM crossing.
  double rigid_onset = ti;
  while (r.velocity(rigid_onset) < 0.01 * v_max) rigid_onset += 1e-7;
  c.onset_error = std::fabs(onset - rigid_onset) / (tf - ti);
  const double Q = r.friction_work(tf);
  c.work_error = std::fabs(h.work_second.back() - Q) / Q;
  c.work_order_gap = std::fabs(h.work_second.back() - h.work_first.back()) / Q;
  std::printf("[sliding block %s] max |v − v_rigid|/v_max = %.4f (own v_max %.2f m/s), onset error %.4f of the sliding time, "
              "friction work %.5g J (first order %.5g J) vs rigid %.5g J: error %.4f; final v %.3f m/s (rigid %.3f)\n",
              name, c.velocity_error, v_max, c.onset_error, h.work_second.back(), h.work_first.back(), Q, c.work_error,
              h.velocity.back(), r.velocity(tf));
  return c;
}

}  // namespace

TEST(SlidingBlock, RigidSolutionMatchesQuadrature) {
  // Eqs. 50 and 53–54 against a trapezoid integration of dv/dt = α T + β − γ v and of (S_slide) v.
  for (double k : {0.0, 0.5 / 31.6}) {
    RigidBlock r = rigid_solution(0.3, 0.2, k, 0.05 * SlidingBlockConstants::normal_stress());
    const double ti = r.onset(), tf = SlidingBlockConstants::t_final();
    const int n = 200000;
    const double dt = (tf - ti) / n;
    double v = 0.0, q = 0.0;
    for (int i = 0; i < n; ++i) {
      const double T = i * dt;
      auto acc = [&](double TT, double vv) { return r.alpha() * TT + r.beta() - r.gamma() * vv; };
      const double k1 = acc(T, v), k2 = acc(T + 0.5 * dt, v + 0.5 * dt * k1), k3 = acc(T + 0.5 * dt, v + 0.5 * dt * k2),
                   k4 = acc(T + dt, v + dt * k3);
      const double v_new = v + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
      auto power = [&](double vv) { return r.l * r.b * ((r.mu_d + r.k * vv) * r.N + r.S_a) * vv; };
      q += 0.5 * dt * (power(v) + power(v_new));
      v = v_new;
    }
    EXPECT_NEAR(v, r.velocity(tf), 1e-9 * r.velocity(tf)) << "k = " << k;
    // Trapezoid error ~ (tf − ti)^3/n^2 |P''|: far below 1e-8 relative here.
    EXPECT_NEAR(q, r.friction_work(tf), 1e-8 * q) << "k = " << k;
  }
}

TEST(SlidingBlock, IntegratedRigidBlockMatchesTheClosedForms) {
  // RigidBlockUnderLaw (eq. 48 integrated with the law's own traction) against eqs. 47, 50 and 53–54
  // where those apply: Coulomb, a velocity term, adhesion, and all three; 1e-8 of the final speed
  // and of the work (the integration's tolerance is 1e-12, the table's interpolation 1e-9).
  using C = SlidingBlockConstants;
  const double N = C::normal_stress(), tf = C::t_final();
  for (const auto& [k, S_a] : {std::pair{0.0, 0.0}, std::pair{0.5 / C::v_max, 0.0}, std::pair{0.0, 0.3 * N},
                               std::pair{0.3 / C::v_max, 0.3 * N}}) {
    const RigidBlock r = rigid_solution(0.2, 0.2, k, S_a, 1.5);
    const RigidBlockUnderLaw ode(r, [&](double v) { return (0.2 + k * v) * N + S_a; }, tf);
    EXPECT_NEAR(ode.onset(), r.onset(), 1e-12 * tf);
    for (double f : {0.3, 0.6, 0.9, 1.0}) {
      const double t = r.onset() + f * (tf - r.onset());
      EXPECT_NEAR(ode.velocity(t), r.velocity(t), 1e-8 * r.velocity(tf)) << "k " << k << " S_a " << S_a;
      EXPECT_NEAR(ode.friction_work(t), r.friction_work(t), 1e-8 * r.friction_work(tf)) << "k " << k << " S_a " << S_a;
    }
  }
}

TEST(SlidingBlock, CoulombMatchesRigidBlock) {
  SlidingBlockSetup s;
  s.law = FrictionLaw::coulomb(0.2);
  const Comparison c = compare(run_sliding_block(s), rigid_solution(0.2, 0.2, 0.0, 0.0), "coulomb");
  EXPECT_LT(c.velocity_error, 0.02);
  EXPECT_LT(c.onset_error, 0.02);
  EXPECT_LT(c.work_error, 0.03);
}

TEST(SlidingBlock, LinearVelocityDependenceMatchesRigidBlock) {
  const double k = 0.5 / SlidingBlockConstants::v_max;  // k v_max = 0.5
  SlidingBlockSetup s;
  s.law = FrictionLaw::linear_velocity(0.2, k);
  const Comparison c = compare(run_sliding_block(s), rigid_solution(0.2, 0.2, k, 0.0), "linear velocity");
  EXPECT_LT(c.velocity_error, 0.02);
  EXPECT_LT(c.onset_error, 0.02);
  EXPECT_LT(c.work_error, 0.03);
}

TEST(SlidingBlock, AdhesionMatchesRigidBlock) {
  // Unlike the Coulomb term, the adhesion term S_a A_c depends on the contact area of every node. At
  // the paper's 5 mm cells eq. 11 overestimates the area of the two nodes under the block's ends
  // (√(3/8) h t instead of h t / 2): the adhesive strength is 2.8 % too large, sliding starts about
  // 70 µs late and the velocity error is 4.3 % of v_max (measured through the scene, first order in h:
  // 2.1 % at 2.5 mm). The surface area (ContactAreaMethod::surface, the default: ∫_Γ S_i dA from the
  // volume gradients, which sums to the true area) removes it; measured 0.24 % / 0.09 % / 0.17 % at
  // 5 / 2.5 / 1.25 mm. Bounds: 1 % (four times the measured error, a quarter of eq. 11's).
  const double S_a = 0.3 * SlidingBlockConstants::normal_stress();
  SlidingBlockSetup s;
  s.scheme = mechanics::UpdateScheme::usl;          // what a scene with grid contact gets
  s.separation = mechanics::SeparationMethod::extent;  // the scene default for a law with an area term
  s.law = FrictionLaw::adhesion(0.2, S_a);
  const RigidBlock r = rigid_solution(0.2, 0.2, 0.0, S_a);
  const Comparison c = compare(run_sliding_block(s), r, "adhesion, surface area, 5 mm");
  EXPECT_LT(c.velocity_error, 0.01);
  EXPECT_LT(c.onset_error, 0.02);  // the onset mark (first sample above a speed threshold): 1.8 % with either area
  EXPECT_LT(c.work_error, 0.01);
  s.area = mechanics::ContactAreaMethod::domain;  // eq. 11: the end nodes' excess shows
  const Comparison d = compare(run_sliding_block(s), r, "adhesion, eq. 11 area, 5 mm");
  EXPECT_GT(d.velocity_error, 2.0 * c.velocity_error);
}

// The generalized law of eq 21 written as one composite law (FrictionLaw::composite, scene type
// "composite"): smooth static → dynamic (μs = 0.35, μd = 0.2, v½ = 0.05 m/s), a velocity coefficient
// (k v_max = 0.3 with the Coulomb case's v_max) and adhesion S_a = 0.3 N, under a tangential load
// R = 1.5 N, against its own rigid block (RigidBlockUnderLaw: eq. 48 integrated with the law's
// traction). The closed forms' sharp static → dynamic step is not that block: it ends 0.8 % faster
// and with 2.4 % more work, because the smooth coefficient stays above μd for the first metres per
// second of sliding.
TEST(SlidingBlock, CompositeLawMatchesRigidBlock) {
  using C = SlidingBlockConstants;
  const double N = C::normal_stress(), k = 0.3 / C::v_max, S_a = 0.3 * N;
  SlidingBlockSetup s;
  s.cell = 0.0025;  // adhesion needs 2.5 mm cells (test AdhesionMatchesRigidBlock)
  s.R = 1.5;
  s.law = FrictionLaw::composite(0.35, 0.2, 0.05, k, S_a);
  const RigidBlockUnderLaw exact(rigid_solution(0.35, 0.2, k, S_a, 1.5),
                                 smooth_law_traction(N, 0.35, 0.2, 0.05, k, S_a), C::t_final());
  const Comparison c = compare(run_sliding_block(s), exact, "composite, position separation");
  // MUSL with position separation, the paper's set-up: measured 5.1 % of v_max and 4.9 % of the work
  // (the target is 3 %). The law itself is exact (tests/mechanics/test_friction.cpp); the
  // loss is contact detection: with k v and S_a the faster, tilting block lifts off some interface
  // nodes, which then carry neither term (docs/contact.md, "Known limitations"). Extent detection,
  // every scene's default, removes it (next test). These bounds guard the position detection's state.
  EXPECT_LT(c.velocity_error, 0.07);
  EXPECT_LT(c.work_error, 0.07);
}

// The same composite law with extent detection (docs/contact.md, "Contact detection"): interface nodes
// whose particle domains touch keep the law's area term S_a A_c even in a step where they move apart,
// so the adhesion part acts on the whole contact area as in the rigid solution.
TEST(SlidingBlock, CompositeLawWithExtentDetectionMatchesRigidBlock) {
  using C = SlidingBlockConstants;
  const double N = C::normal_stress(), k = 0.3 / C::v_max, S_a = 0.3 * N;
  SlidingBlockSetup s;
  s.cell = 0.0025;
  s.R = 1.5;
  s.separation = mechanics::SeparationMethod::extent;
  s.law = FrictionLaw::composite(0.35, 0.2, 0.05, k, S_a);
  const RigidBlockUnderLaw exact(rigid_solution(0.35, 0.2, k, S_a, 1.5),
                                 smooth_law_traction(N, 0.35, 0.2, 0.05, k, S_a), C::t_final());
  // Measured 0.61 % of v_max and 0.16 % of the work (against the sharp step's closed form 0.76 % and
  // 2.2 %: the reference's own difference). Bounds: issue 31's 3 % for velocity and work.
  const Comparison c = compare(run_sliding_block(s), exact, "composite, extent");
  EXPECT_LT(c.velocity_error, 0.03);
  EXPECT_LT(c.work_error, 0.03);
  // USL, what a scene with grid contact gets unless it names a scheme: the same target.
  s.scheme = mechanics::UpdateScheme::usl;
  const Comparison u = compare(run_sliding_block(s), exact, "composite, extent, USL");
  EXPECT_LT(u.velocity_error, 0.03);
  EXPECT_LT(u.work_error, 0.03);
}

// The laws that are steep at low sliding speed (the composite law with v½ = 0.05 m/s, R = 1) drift from
// their rigid block as the cell shrinks on the paper's block (E = 2.5 GPa; scene defaults, work +2.00 /
// +2.88 / +3.06 % at 5 / 2.5 / 1.25 mm). The drift is the block's compliance, not the friction
// algorithm: with both bodies ten times stiffer (closer to the rigid block the reference assumes) the
// same runs give +0.11 / +0.39 / −0.16 % (three times stiffer: +0.38 / +0.59 % at 5 / 2.5 mm), the
// velocity within 0.3 % of v_max, and the error no longer grows (docs/contact.md, "Friction laws on
// a compliant block"). Bound 1 %: the stiff block's scatter is under 0.4 %, the compliant one's 2–3 %.
TEST(SlidingBlock, LowSpeedSteepLawOnAStiffBlockMatchesItsRigidBlock) {
  using C = SlidingBlockConstants;
  const double N = C::normal_stress(), k = 0.3 / C::v_max, S_a = 0.3 * N;
  const RigidBlockUnderLaw exact(rigid_solution(0.35, 0.2, k, S_a), smooth_law_traction(N, 0.35, 0.2, 0.05, k, S_a),
                                 C::t_final());
  for (double cell : {0.005, 0.0025}) {
    SlidingBlockSetup s;
    s.cell = cell;
    s.scheme = mechanics::UpdateScheme::usl;
    s.separation = mechanics::SeparationMethod::extent;
    s.law = FrictionLaw::composite(0.35, 0.2, 0.05, k, S_a);
    s.stiffness_scale = 10.0;
    const Comparison c = compare(run_sliding_block(s), exact, "composite, R = 1, E x 10");
    EXPECT_LT(c.velocity_error, 0.01);
    EXPECT_LT(c.work_error, 0.01);
  }
}
