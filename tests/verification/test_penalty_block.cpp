// Penalty contact driven by two rigidly moving bodies (no MPM step): a rigid block (translation only)
// pressed on a fixed rigid plane by its weight W, then pushed sideways by a force P.
//   * pressed: the normal penalty force balances the load, N = W, at the penetration W/(ε_N A);
//   * P = 0.4 μ W (ramped): the return-mapping law sticks (no slip, no heat, displacement elastic);
//     the law of K·32 as printed cannot hold a static tangential load and creeps at the speed where
//     ε_T |Δg_T| A = P, v = P/(ε_T A Δt) (the reason return mapping is the default);
//   * P = 2 μ W: the block slides with a = (P − μ W)/m, the tangential force is μ N and the heat is
//     μ N × slip; the work of P equals kinetic energy + heat + stored penalty energy.
// The block is integrated with symplectic Euler; a critical vertical dashpot settles the normal
// oscillation (it acts on the vertical velocity only and does no work on the horizontal motion).
#include <frictherm/mechanics/penalty_contact.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace frictherm::mechanics;

namespace {

struct BlockRun {
  double x = 0, y = 0, vx = 0, vy = 0;  // block displacement and velocity
  double max_abs_ft = 0, max_x = 0;
  long sliding_steps = 0;
};

constexpr double kRho = 2000, kE = 1e9, kMu = 0.3, kG = 9.81, kH = 0.01;
constexpr double kMass = kRho * 0.1 * 0.05;  // block 0.1 m x 0.05 m, thickness 1 m: 10 kg
constexpr double kW = kMass * kG;

class PenaltyBlock : public ::testing::Test {
 protected:
  void SetUp() override {
    bp_.add_loop(0, sample_rectangle_boundary(Vec<2>(0.02, 0.02), Vec<2>(0.58, 0.10), 0.005), Vec<2>::Constant(kH / 4));
    bp_.add_loop(1, sample_rectangle_boundary(Vec<2>(0.10, 0.10), Vec<2>(0.20, 0.15), 0.005), Vec<2>::Constant(kH / 4));
  }
  PenaltyContact<2> make(TangentialLaw law) {
    PenaltyContact<2> pc(grid_);
    PenaltyPairSettings s;
    s.master = 0;
    s.slave = 1;
    s.mu = kMu;
    s.normal_penalty = default_penalty(kE, kE, kH);  // K·40: E/Δh
    s.law = law;
    pc.add_pair(s);
    return pc;
  }
  // Advances `steps` steps with horizontal push P(step) and returns after the last one.
  template <class Push>
  void run(PenaltyContact<2>& pc, BlockRun& b, long steps, Push&& P) {
    for (long n = 0; n < steps; ++n) {
      pc.compute(bp_);
      const Vec<2> F = pc.books(0).force_on_slave;
      const double c = 2.0 * kMass * omega_;  // critical vertical damping
      b.vx += dt_ * (F[0] + P(n)) / kMass;
      b.vy += dt_ * (F[1] - kW - c * b.vy) / kMass;
      b.x += dt_ * b.vx;
      b.y += dt_ * b.vy;
      bp_.translate_field(1, Vec<2>(b.vx, b.vy), dt_);
      b.max_abs_ft = std::max(b.max_abs_ft, std::fabs(F[0]));
      b.max_x = std::max(b.max_x, std::fabs(b.x));
      if (pc.books(0).sliding > 0) ++b.sliding_steps;
    }
  }
  const Grid<2> grid_{Vec<2>(0, 0), Vec<2>(kH, kH), IVec<2>{60, 20}};
  BoundaryPoints<2> bp_;
  // Contact stiffness ε_N A with A = 21 points x 5 mm x 1 m (corners carry half a side segment).
  const double k_ = kE / kH * 0.105;
  const double omega_ = std::sqrt(k_ / kMass);
  const double dt_ = 0.05 / omega_;
};

TEST_F(PenaltyBlock, PressedStickAndSlide) {
  PenaltyContact<2> pc = make(TangentialLaw::return_mapping);
  BlockRun b;
  run(pc, b, 3000, [](long) { return 0.0; });  // ω t = 150: the normal oscillation has died out
  const double N = pc.books(0).normal_force;
  EXPECT_NEAR(N, kW, 1e-6 * kW);
  EXPECT_NEAR(-b.y, kW / k_, 1e-6 * kW / k_);  // penetration W/(ε_N A)
  EXPECT_EQ(pc.books(0).active, 21);

  // Stick: P ramped to 0.4 μ W over 2000 steps (ω T = 100), then held 2000 steps.
  const double P1 = 0.4 * kMu * kW;
  BlockRun s;
  s.vy = b.vy;
  run(pc, s, 4000, [&](long n) { return P1 * std::min(1.0, n / 2000.0); });
  EXPECT_EQ(s.sliding_steps, 0);
  EXPECT_EQ(pc.books(0).heat_total, 0.0);
  EXPECT_LE(s.max_abs_ft, kMu * kW);
  EXPECT_LT(s.max_x, 1.1 * P1 / k_);  // elastic tangential spring only (ε_T = ε_N), small overshoot
  EXPECT_NEAR(pc.books(0).force_on_slave[0], -P1, 0.05 * P1);

  // Slide: P = 2 μ W for 20 000 steps.
  const double P2 = 2.0 * kMu * kW;
  BlockRun d;
  d.vx = s.vx;
  d.vy = s.vy;
  const double x0 = s.x, v0 = s.vx, e0 = pc.stored_energy(), ke0 = 0.5 * kMass * (s.vx * s.vx + s.vy * s.vy);
  const long steps = 20000;
  double heat = 0.0, slip_work = 0.0;
  for (long n = 0; n < steps; ++n) {
    run(pc, d, 1, [&](long) { return P2; });
    heat += pc.books(0).heat_step;
    for (const auto& r : pc.contacts()) slip_work += kMu * r.normal_force * std::fabs(r.slip);
    if (n > 100) {  // past the stick-to-slip transient (ω t = 5)
      EXPECT_EQ(pc.books(0).sliding, 21) << n;
      ASSERT_NEAR(-pc.books(0).force_on_slave[0], kMu * pc.books(0).normal_force, 1e-9 * kW) << n;
    }
  }
  const double T = steps * dt_;
  const double v_exact = v0 + (P2 - kMu * kW) / kMass * T;
  EXPECT_NEAR(d.vx, v_exact, 2e-3 * v_exact);
  EXPECT_NEAR(pc.books(0).normal_force, kW, 1e-6 * kW);
  const double dx = d.x - x0;
  EXPECT_NEAR(heat, slip_work, 1e-12 * heat);  // heat = μ N × slip, point by point
  EXPECT_NEAR(heat, kMu * kW * dx, 2e-3 * heat);  // ... = μ W × block displacement
  const double ke1 = 0.5 * kMass * (d.vx * d.vx + d.vy * d.vy);
  EXPECT_NEAR(P2 * dx, (ke1 - ke0) + heat + (pc.stored_energy() - e0), 2e-3 * P2 * dx);
  RecordProperty("slide_velocity_rel_error", std::to_string(d.vx / v_exact - 1));
  RecordProperty("heat_over_muWdx", std::to_string(heat / (kMu * kW * dx)));
  std::printf("slide: v %.6g (exact %.6g, rel %.2e); heat %.6g J = %.8f mu W dx; energy residual %.2e\n", d.vx, v_exact,
              d.vx / v_exact - 1, heat, heat / (kMu * kW * dx),
              (P2 * dx - (ke1 - ke0) - heat - (pc.stored_energy() - e0)) / (P2 * dx));
}

TEST_F(PenaltyBlock, PaperTangentialLawCreepsUnderStaticLoad) {
  PenaltyContact<2> pc = make(TangentialLaw::incremental);
  BlockRun b;
  run(pc, b, 3000, [](long) { return 0.0; });
  const double P1 = 0.4 * kMu * kW;
  BlockRun s;
  s.vy = b.vy;
  run(pc, s, 6000, [&](long) { return P1; });
  // Terminal creep speed where the per-step tangential penalty force balances P: ε_T v Δt A = P.
  const double v_creep = P1 / (k_ * dt_);
  EXPECT_NEAR(s.vx, v_creep, 1e-3 * v_creep);
  EXPECT_EQ(s.sliding_steps, 0);  // it never reaches the cap, yet it moves
  EXPECT_GT(pc.books(0).heat_total, 0.0);
  std::printf("incremental law: creep %.4g m/s (predicted %.4g)\n", s.vx, v_creep);
}

}  // namespace
