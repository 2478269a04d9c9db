// Penalty node-to-segment contact (Kakouris et al. 2024 §3.5–3.6, App. A): gaps, projection, the
// Coulomb-capped tangential law, momentum of the point and nodal forces, frictional heat.
#include <frictherm/mechanics/penalty_contact.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace frictherm::mechanics;

namespace {

const Grid<2> kGrid(Vec<2>(0, 0), Vec<2>(0.01, 0.01), IVec<2>{40, 30});

// Master (field 0): rectangle [0.05, 0.35] x [0.05, 0.15]. Slave (field 1): rectangle of width 0.1
// whose bottom is at y = 0.15 − pen (pen > 0: penetration), left edge at x0.
BoundaryPoints<2> block_on_base(double pen, double x0 = 0.1, double spacing = 0.005) {
  BoundaryPoints<2> bp;
  bp.add_loop(0, sample_rectangle_boundary(Vec<2>(0.05, 0.05), Vec<2>(0.35, 0.15), spacing), Vec<2>::Constant(0.0025));
  bp.add_loop(1, sample_rectangle_boundary(Vec<2>(x0, 0.15 - pen), Vec<2>(x0 + 0.1, 0.2 - pen), spacing),
              Vec<2>::Constant(0.0025));
  return bp;
}

PenaltyPairSettings pair_settings(double mu, double eps_n = 1e11, double eps_t = 0.0) {
  PenaltyPairSettings s;
  s.master = 0;
  s.slave = 1;
  s.mu = mu;
  s.normal_penalty = eps_n;
  s.tangential_penalty = eps_t;
  return s;
}

Vec<2> sum_forces(const std::vector<Vec<2>>& f, double* abs_sum = nullptr) {
  Vec<2> s = Vec<2>::Zero();
  double a = 0.0;
  for (const auto& v : f) {
    s += v;
    a += v.norm();
  }
  if (abs_sum) *abs_sum = a;
  return s;
}

}  // namespace

TEST(PenaltyContact, ProjectionGapSignAndEndRegions) {
  // Segment along +x: material on its left (y > 0), outward normal (0, −1).
  const Vec<2> x1(0, 0), x2(2, 0);
  auto p = project_onto_segment(Vec<2>(0.5, -0.1), x1, x2);  // outside: separated
  EXPECT_DOUBLE_EQ(p.beta, 0.25);
  EXPECT_DOUBLE_EQ(p.gap, 0.1);
  EXPECT_DOUBLE_EQ(p.e_nor[1], -1.0);
  p = project_onto_segment(Vec<2>(1.5, 0.05), x1, x2);  // inside: penetration is negative (K·28)
  EXPECT_DOUBLE_EQ(p.beta, 0.75);
  EXPECT_DOUBLE_EQ(p.gap, -0.05);
  EXPECT_DOUBLE_EQ(p.distance, 0.05);
  p = project_onto_segment(Vec<2>(-0.3, 0.4), x1, x2);  // before the first end: β < 0, distance to x1
  EXPECT_DOUBLE_EQ(p.beta, -0.15);
  EXPECT_DOUBLE_EQ(p.distance, 0.5);
  p = project_onto_segment(Vec<2>(2.3, -0.4), x1, x2);  // beyond the second end
  EXPECT_DOUBLE_EQ(p.beta, 1.15);
  EXPECT_DOUBLE_EQ(p.distance, 0.5);
  EXPECT_DOUBLE_EQ(p.gap, 0.4);
  p = project_onto_segment(Vec<2>(1, 1), Vec<2>(1, 0), Vec<2>(0, 1));  // inclined, material towards the origin
  EXPECT_NEAR(p.gap, std::sqrt(0.5), 1e-15);
  p = project_onto_segment(Vec<2>(0.25, 0.25), Vec<2>(1, 0), Vec<2>(0, 1));
  EXPECT_NEAR(p.gap, -std::sqrt(0.125), 1e-15);
  EXPECT_NEAR(p.beta, 0.5, 1e-15);
}

TEST(PenaltyContact, GapSignDecidesContact) {
  PenaltyContact<2> pc(kGrid);
  pc.add_pair(pair_settings(0.0));
  pc.compute(block_on_base(-1e-4));
  EXPECT_TRUE(pc.contacts().empty());
  EXPECT_EQ(pc.books(0).normal_force, 0.0);
  const double pen = 2e-5, eps = 1e11;
  const auto pressed = block_on_base(pen);
  pc.compute(pressed);
  // Bottom edge of the slave: 0.1/0.005 + 1 = 21 points inside the master (corners included), each
  // with tributary length 0.005 (corners: half a bottom and half a side segment).
  ASSERT_EQ(pc.contacts().size(), 21u);
  for (const auto& r : pc.contacts()) {
    EXPECT_NEAR(r.gap, -pen, 1e-15);
    // The master's top edge runs −x (counter-clockwise): outward normal (t_y, −t_x) = +y.
    EXPECT_NEAR(r.e_nor[1], 1.0, 1e-12);
    EXPECT_NEAR(r.area, 0.005, 1e-15);
    // K·31 times the tributary area; the gap 0.15 − (0.15 − pen) carries round-off ~ 1e-16 × 0.15 / pen.
    EXPECT_NEAR(r.normal_force, eps * pen * 0.005, 1e-10 * eps * pen * 0.005);
  }
  EXPECT_NEAR(pc.books(0).force_on_slave[1], eps * pen * 0.105, 1e-10 * eps * pen * 0.105);  // pushes the slave out (+y)
  EXPECT_NEAR(pc.books(0).force_on_slave[0], 0.0, 1e-12 * eps * pen * 0.105);
  EXPECT_NEAR(pc.stored_energy(), 0.5 * eps * pen * pen * 0.105, 1e-10 * 0.5 * eps * pen * pen * 0.105);
}

TEST(PenaltyContact, ConvexCornerAndReflexVertex) {
  PenaltyContact<2> pc(kGrid);
  pc.add_pair(pair_settings(0.3));
  {  // slave point just inside the master's corner (0.35, 0.15): nearer to the right edge
    BoundaryPoints<2> bp;
    bp.add_loop(0, sample_rectangle_boundary(Vec<2>(0.05, 0.05), Vec<2>(0.35, 0.15), 0.05), Vec<2>::Constant(0.0025));
    bp.add_loop(1, {{0.349, 0.147}, {0.36, 0.16}, {0.345, 0.17}}, Vec<2>::Constant(0.0025));
    pc.compute(bp);
    ASSERT_EQ(pc.contacts().size(), 1u);
    const auto& r = pc.contacts()[0];
    EXPECT_NEAR(r.gap, -0.001, 1e-15);
    EXPECT_NEAR(r.e_nor[0], 1.0, 1e-15);
    EXPECT_NEAR(r.beta, 0.94, 1e-12);  // on the upper half (0.35, 0.10) → (0.35, 0.15) of the right edge
    EXPECT_FALSE(r.vertex);
    EXPECT_GE(r.beta, 0.0);
    EXPECT_LE(r.beta, 1.0);
    EXPECT_NEAR(sum_forces(pc.point_force()).norm(), 0.0, 1e-9);
  }
  {  // L-shaped master with a reflex vertex at (0.15, 0.10); slave point in its wedge
    BoundaryPoints<2> bp;
    bp.add_loop(0,
                sample_polygon_boundary({{0.05, 0.05}, {0.25, 0.05}, {0.25, 0.10}, {0.15, 0.10}, {0.15, 0.20}, {0.05, 0.20}},
                                        0.05),
                Vec<2>::Constant(0.0025));
    bp.add_loop(1, {{0.148, 0.098}, {0.2, 0.15}, {0.16, 0.18}}, Vec<2>::Constant(0.0025));
    pc.compute(bp);
    ASSERT_EQ(pc.contacts().size(), 1u);
    const auto& r = pc.contacts()[0];
    EXPECT_TRUE(r.vertex);
    EXPECT_NEAR(r.gap, -0.002 * std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(r.e_nor[0], std::sqrt(0.5), 1e-12);  // towards the vertex: out of the master
    EXPECT_NEAR(r.e_nor[1], std::sqrt(0.5), 1e-12);
    const int vtx = r.segment;  // the reaction sits on the vertex alone
    EXPECT_NEAR((bp.position[static_cast<std::size_t>(vtx)] - Vec<2>(0.15, 0.10)).norm(), 0.0, 1e-15);
    EXPECT_NEAR((pc.point_force()[static_cast<std::size_t>(vtx)] + pc.point_force()[static_cast<std::size_t>(r.slave)]).norm(),
                0.0, 1e-9);
    EXPECT_EQ(r.tangential_force, 0.0);  // vertex contacts are frictionless
  }
}

// The tangential law at known numbers: cap μ t_N = 0.5 × 8 = 4 Pa, ε_T = 2 N/m³.
TEST(PenaltyContact, StickSlipSwitchAtTheCap) {
  const double eps = 2.0, cap = 4.0;
  for (TangentialLaw law : {TangentialLaw::return_mapping, TangentialLaw::incremental}) {
    auto u = update_tangential(law, 0.0, 2.0, eps, cap);  // trial exactly at the cap: stick
    EXPECT_FALSE(u.sliding) << to_string(law);
    EXPECT_EQ(u.traction, -4.0);
    EXPECT_EQ(u.slip, 0.0);
    u = update_tangential(law, 0.0, 2.0 * (1 + 1e-12), eps, cap);  // just beyond: slip, capped
    EXPECT_TRUE(u.sliding);
    EXPECT_EQ(u.traction, -4.0);
    u = update_tangential(law, 0.0, 2.5, eps, cap);
    EXPECT_TRUE(u.sliding);
    EXPECT_EQ(u.traction, -4.0);
    EXPECT_DOUBLE_EQ(u.slip, law == TangentialLaw::return_mapping ? 0.5 : 2.5);
    EXPECT_DOUBLE_EQ(u.dissipation, 4.0 * u.slip);  // μ t_N × slip
    u = update_tangential(law, 0.0, -2.5, eps, cap);  // opposite direction: force opposes slip
    EXPECT_EQ(u.traction, 4.0);
    EXPECT_GT(u.dissipation, 0.0);
  }
  // Return mapping accumulates the tangential spring (the law of the brief); K·32 does not.
  auto u = update_tangential(TangentialLaw::return_mapping, -3.0, 0.4, eps, cap);
  EXPECT_FALSE(u.sliding);
  EXPECT_DOUBLE_EQ(u.traction, -3.8);
  u = update_tangential(TangentialLaw::return_mapping, u.traction, 0.4, eps, cap);
  EXPECT_TRUE(u.sliding);
  EXPECT_DOUBLE_EQ(u.slip, 0.4 + (-4.0 + 3.8) / eps);
  u = update_tangential(TangentialLaw::return_mapping, -4.0, -0.5, eps, cap);  // reversal unloads: stick
  EXPECT_FALSE(u.sliding);
  EXPECT_DOUBLE_EQ(u.traction, -3.0);
  u = update_tangential(TangentialLaw::incremental, -3.0, 0.4, eps, cap);
  EXPECT_DOUBLE_EQ(u.traction, -0.8);
  EXPECT_DOUBLE_EQ(u.dissipation, 0.8 * 0.4);  // K·32 stores nothing: its stick work is dissipated
}

// A pressed block moved tangentially by one step: stick below μ t_N/ε_T, slip beyond it.
TEST(PenaltyContact, SlipBeyondCapStickBelow) {
  const double pen = 2e-5, eps_n = 1e11, eps_t = 5e10, mu = 0.4;
  const double u_cap = mu * eps_n * pen / eps_t;  // 1.6e-5 m
  for (double factor : {0.5, 3.0}) {
    PenaltyContact<2> pc(kGrid);
    pc.add_pair(pair_settings(mu, eps_n, eps_t));
    auto bp = block_on_base(pen, 0.1013);
    pc.compute(bp);  // new contacts: no slip history yet
    EXPECT_EQ(pc.books(0).tangential_force, 0.0);
    const double u = factor * u_cap;
    bp.translate_field(1, Vec<2>(u, 0), 1.0);
    pc.compute(bp);
    double area = 0.0;
    for (const auto& r : pc.contacts()) area += r.area;
    const double N = eps_n * pen * area;
    EXPECT_NEAR(pc.books(0).normal_force, N, 1e-9 * N);
    const Vec<2> F = pc.books(0).force_on_slave;
    if (factor < 1) {
      EXPECT_EQ(pc.books(0).sliding, 0);
      EXPECT_NEAR(F[0], -eps_t * u * area, 1e-9 * N);  // elastic tangential spring, opposing +x
      EXPECT_EQ(pc.books(0).heat_step, 0.0);
    } else {
      EXPECT_EQ(pc.books(0).sliding, static_cast<long>(pc.contacts().size()));
      EXPECT_NEAR(F[0], -mu * N, 1e-9 * N);  // Coulomb cap
      for (const auto& r : pc.contacts()) {
        EXPECT_NEAR(r.slip_increment, -u, 1e-10 * u);  // the master's e_tan is −x: slip is signed along it
        EXPECT_NEAR(r.slip, -(u - u_cap), 1e-10 * u);
      }
      EXPECT_NEAR(pc.books(0).heat_step, mu * N * (u - u_cap), 1e-9 * mu * N * u);
    }
  }
}

// Steady sliding across many master segments: heat per step = μ N u, total = μ N × slip, and the
// heat delivered to the nodes equals the books.
TEST(PenaltyContact, SteadySlidingHeatIsMuNTimesSlip) {
  const double pen = 1e-5, eps = 1e11, mu = 0.3, u = 1.3e-3;  // u ≫ μ pen (the elastic pre-slip)
  for (TangentialLaw law : {TangentialLaw::return_mapping, TangentialLaw::incremental})
  for (double dir : {-1.0, 1.0}) {  // −x: onto the next master segments; +x: onto the previous ones
    PenaltyContact<2> pc(kGrid);
    auto s = pair_settings(mu, eps);
    s.law = law;
    pc.add_pair(s);
    auto bp = block_on_base(pen, dir < 0 ? 0.1013 : 0.2013);
    GridWeights<2> w{&kGrid, ShapeKind::quadratic_bspline,
                     {FieldNodes<2>::whole_grid(kGrid), FieldNodes<2>::whole_grid(kGrid, static_cast<int>(kGrid.node_count()))}};
    const int steps = 30;  // 30 × 1.3 mm = 39 mm: each slave point crosses ~8 master segments
    double slip = 0.0, nodal = 0.0, N = 0.0;
    for (int n = 0; n < steps; ++n) {
      pc.compute(bp);
      std::vector<double> heat(kGrid.node_count(), 0.0);
      pc.scatter_heat(bp, w, heat);
      for (double q : heat) nodal += q;
      for (const auto& r : pc.contacts()) slip += std::fabs(r.slip) * r.normal_force;  // Σ N_s |slip_s|
      N = pc.books(0).normal_force;
      if (n >= 2) {
        EXPECT_EQ(pc.books(0).sliding, static_cast<long>(pc.contacts().size())) << n;
        EXPECT_NEAR(pc.books(0).heat_step, mu * N * u, 1e-9 * mu * N * u) << to_string(law) << " step " << n;
        EXPECT_NEAR(pc.books(0).force_on_slave[0], -dir * mu * N, 1e-9 * N);  // opposes the motion
      }
      bp.translate_field(1, Vec<2>(dir * u, 0), 1.0);
    }
    const double expected_slip = law == TangentialLaw::return_mapping ? (steps - 1) * u - mu * pen : (steps - 1) * u;
    EXPECT_NEAR(pc.books(0).heat_total, mu * slip, 1e-12 * pc.books(0).heat_total);
    EXPECT_NEAR(pc.books(0).heat_total, mu * N * expected_slip, 1e-9 * pc.books(0).heat_total) << to_string(law);
    EXPECT_NEAR(nodal, pc.books(0).heat_total, 1e-12 * nodal);
    EXPECT_NEAR(pc.total_heat(), pc.books(0).heat_total, 0.0);
  }
}

// Linear momentum: the point forces of every pair sum to zero, and so do the nodal forces for every
// kernel. Angular momentum: exact for the classical split without friction; K·51's (g/l) P term adds
// a moment −Σ ε_N g² A (digest §4 note).
TEST(PenaltyContact, ForcesSumToZero) {
  const double eps = 1e11;
  for (bool paper_terms : {false, true}) {
    for (double mu : {0.0, 0.5}) {
      PenaltyContact<2> pc(kGrid);
      auto s = pair_settings(mu, eps);
      s.paper_correction_terms = paper_terms;
      pc.add_pair(s);
      BoundaryPoints<2> bp;
      bp.add_loop(0, sample_rectangle_boundary(Vec<2>(0.05, 0.05), Vec<2>(0.35, 0.15), 0.004), Vec<2>::Constant(0.0025));
      bp.add_loop(1, sample_ellipse_boundary(Vec<2>(0.2, 0.177), Vec<2>(0.03, 0.03), 0.0, 0.003), Vec<2>::Constant(0.0025));
      pc.compute(bp);
      bp.translate_field(1, Vec<2>(7e-4, -2e-4), 1.0);
      pc.compute(bp);
      ASSERT_GE(pc.contacts().size(), 5u);
      double abs_sum = 0.0;
      const Vec<2> sum = sum_forces(pc.point_force(), &abs_sum);
      EXPECT_LT(sum.norm(), 1e-15 * abs_sum) << paper_terms << " mu " << mu;
      double torque = 0.0, expected = 0.0;
      for (std::size_t i = 0; i < bp.size(); ++i)
        torque += bp.position[i][0] * pc.point_force()[i][1] - bp.position[i][1] * pc.point_force()[i][0];
      for (const auto& r : pc.contacts()) expected -= paper_terms ? eps * r.gap * r.gap * r.area : 0.0;
      if (mu == 0.0) {
        EXPECT_NEAR(torque, expected, 1e-14 * abs_sum * 0.2) << paper_terms;
      }
      for (ShapeKind kind : {ShapeKind::linear, ShapeKind::ugimp, ShapeKind::quadratic_bspline}) {
        const int n = static_cast<int>(kGrid.node_count());
        GridWeights<2> w{&kGrid, kind, {FieldNodes<2>::whole_grid(kGrid), FieldNodes<2>::whole_grid(kGrid, n)}};
        std::vector<Vec<2>> nodal(2 * kGrid.node_count(), Vec<2>::Zero());
        pc.scatter_forces(bp, w, nodal);
        Vec<2> master = Vec<2>::Zero(), slave = Vec<2>::Zero();
        for (int k = 0; k < n; ++k) {
          master += nodal[static_cast<std::size_t>(k)];
          slave += nodal[static_cast<std::size_t>(n + k)];
        }
        EXPECT_LT((master + slave).norm(), 1e-14 * abs_sum) << to_string(kind);
        EXPECT_LT((slave - pc.books(0).force_on_slave).norm(), 1e-14 * abs_sum) << to_string(kind);
      }
    }
  }
}

// Step 1 (K §3.5, eq. 27): a slave point is a candidate only if its own stencil touches a node where
// the master field has material.
TEST(PenaltyContact, SharedNodesRestrictCandidates) {
  const auto bp = block_on_base(2e-5, 0.1013);
  const int n = static_cast<int>(kGrid.node_count());
  GridWeights<2> w{&kGrid, ShapeKind::linear, {FieldNodes<2>::whole_grid(kGrid), FieldNodes<2>::whole_grid(kGrid, n)}};
  // Master material: nodes at y <= 0.15 only in x < 0.15 (as if the base were shorter).
  const auto present = [&](int field, int node) {
    const Vec<2> x = kGrid.node_position(node);
    return field == 0 && x[1] <= 0.15 + 1e-12 && x[0] >= 0.05 - 1e-12 && x[0] < 0.15;
  };
  PenaltyContact<2> pc(kGrid);
  pc.add_pair(pair_settings(0.0));
  pc.compute(bp, [&](int pair, int i) { return touches_field(bp, i, w, pc.pair(static_cast<std::size_t>(pair)).master, present); });
  ASSERT_FALSE(pc.contacts().empty());
  for (const auto& r : pc.contacts()) EXPECT_LT(bp.position[static_cast<std::size_t>(r.slave)][0], 0.16);
  pc.compute(bp);
  EXPECT_EQ(pc.contacts().size(), 21u);  // without step 1 the whole bottom edge
}

TEST(PenaltyContact, SettingsAreValidated) {
  PenaltyContact<2> pc(kGrid);
  auto s = pair_settings(0.2);
  s.slave = 0;
  EXPECT_THROW(pc.add_pair(s), std::invalid_argument);
  s = pair_settings(-0.1);
  EXPECT_THROW(pc.add_pair(s), std::invalid_argument);
  s = pair_settings(0.1, 0.0);
  EXPECT_THROW(pc.add_pair(s), std::invalid_argument);
  s = pair_settings(0.1);
  EXPECT_EQ(pc.add_pair(s), 0);
  EXPECT_EQ(pc.pair(0).tangential_penalty, pc.pair(0).normal_penalty);  // ε_T defaults to ε_N (K·40)
  EXPECT_EQ(pc.pair(0).search_radius, 0.01);                            // Δh
  EXPECT_DOUBLE_EQ(default_penalty(2e9, 5e9, 0.01), 2e11);              // E/Δh with the smaller E
  EXPECT_DOUBLE_EQ(default_penalty(std::numeric_limits<double>::infinity(), 5e9, 0.01), 5e11);  // rigid master
  EXPECT_THROW(default_penalty(0.0, std::numeric_limits<double>::infinity(), 0.01), std::invalid_argument);
  EXPECT_EQ(tangential_law_from_string("incremental"), TangentialLaw::incremental);
  EXPECT_THROW(tangential_law_from_string("viscous"), std::invalid_argument);
  PenaltyContact<3> pc3(Grid<3>(Vec<3>::Zero(), Vec<3>::Constant(0.1), IVec<3>{2, 2, 2}));
  EXPECT_THROW(pc3.add_pair(s), std::invalid_argument);  // 3D not implemented: says so
}
