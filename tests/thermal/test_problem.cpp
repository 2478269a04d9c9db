// thermal::Problem validation and right-hand side (unit).
#include "grids.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace ft = frictherm::thermal;
using thermal_test::make_grid_1d;
using thermal_test::Material;

namespace {

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no exception>";
}

ft::SparseMatrix dense_to_sparse(const Eigen::MatrixXd& a) { return a.sparseView(); }

}  // namespace

TEST(ThermalProblem, RejectsNonPositiveMass) {
  const auto g = make_grid_1d(4, 0.0, 1.0, Material{});
  Eigen::VectorXd m = g.mass;
  m[1] = -1.0;
  const auto msg = message_of([&] { ft::Problem p(m, g.k); });
  EXPECT_NE(msg.find("M[1]"), std::string::npos) << msg;
  m[1] = 0.0;
  EXPECT_THROW(ft::Problem(m, g.k), std::invalid_argument);
}

TEST(ThermalProblem, RejectsSizeMismatchAsymmetryAndNegativeDiagonal) {
  const auto g = make_grid_1d(4, 0.0, 1.0, Material{});
  const Eigen::VectorXd m3 = g.mass.head(3);
  EXPECT_NE(message_of([&] { ft::Problem p(m3, g.k); }).find("size mismatch"), std::string::npos);

  Eigen::MatrixXd a = Eigen::MatrixXd(g.k);
  a(0, 1) = -2.0;  // K(0,1) != K(1,0)
  const auto msg = message_of([&] { ft::Problem p(g.mass, dense_to_sparse(a)); });
  EXPECT_NE(msg.find("not symmetric"), std::string::npos) << msg;

  a = -Eigen::MatrixXd(g.k);
  EXPECT_NE(message_of([&] { ft::Problem p(g.mass, dense_to_sparse(a)); }).find("< 0"), std::string::npos);

  // A diagonal below zero by round-off only (a node whose particles all conduct nothing: the row sums
  // of its neighbours' entries leave ±1e-35 or so) passes; beyond 1e-12 of max |K| it is refused.
  const double kmax = Eigen::MatrixXd(g.k).cwiseAbs().maxCoeff();
  a = Eigen::MatrixXd(g.k);
  a(0, 0) = -1e-14 * kmax, a(0, 1) = a(1, 0) = 0.0;
  EXPECT_NO_THROW(ft::Problem(g.mass, dense_to_sparse(a)));
  a(0, 0) = -1e-9 * kmax;
  EXPECT_NE(message_of([&] { ft::Problem p(g.mass, dense_to_sparse(a)); }).find("< 0"), std::string::npos);
}

// The symmetry sweep (one pass with a cursor per row) against every kind of one-sided entry: an upper
// entry without its mirror, a lower one without its mirror (first and last in its row), and a mirror
// pair that differs; a symmetric matrix with the same pattern passes.
TEST(ThermalProblem, SymmetrySweepFindsEveryOneSidedEntry) {
  const auto g = make_grid_1d(6, 0.0, 1.0, Material{});
  Eigen::MatrixXd sym = Eigen::MatrixXd(g.k);
  sym(0, 4) = sym(4, 0) = -0.25;  // a symmetric far pair: passes
  sym(0, 0) += 0.25, sym(4, 4) += 0.25;
  EXPECT_NO_THROW(ft::Problem(g.mass, dense_to_sparse(sym)));
  const struct {
    int r, c;
  } one_sided[] = {{0, 3}, {3, 0}, {5, 1}, {1, 5}, {2, 5}, {5, 2}};
  for (const auto& e : one_sided) {
    Eigen::MatrixXd a = sym;
    a(e.r, e.c) = -0.5;  // its mirror stays 0
    const std::string msg = message_of([&] { ft::Problem p(g.mass, dense_to_sparse(a)); });
    EXPECT_NE(msg.find("not symmetric"), std::string::npos) << e.r << "," << e.c << ": " << msg;
    EXPECT_NE(msg.find("0.5"), std::string::npos) << msg;  // the difference named
  }
  Eigen::MatrixXd a = sym;
  a(4, 0) = -0.25 * (1.0 + 1e-9);  // a mirror pair that differs by more than 1e-12 of max |K|
  EXPECT_NE(message_of([&] { ft::Problem p(g.mass, dense_to_sparse(a)); }).find("not symmetric"), std::string::npos);
  a(4, 0) = -0.25 * (1.0 + 1e-14);  // within the tolerance
  EXPECT_NO_THROW(ft::Problem(g.mass, dense_to_sparse(a)));
}

TEST(ThermalProblem, RejectsBadNodesSourcesAndStates) {
  auto p = make_grid_1d(4, 0.0, 1.0, Material{}).problem();
  EXPECT_THROW(p.set_dirichlet(4, 1.0), std::invalid_argument);
  EXPECT_THROW(p.add_flux(-1, 1.0), std::invalid_argument);
  EXPECT_THROW(p.add_convection(0, -1.0, 300.0), std::invalid_argument);
  EXPECT_THROW(p.set_source(Eigen::VectorXd::Ones(3)), std::invalid_argument);
  EXPECT_THROW(p.set_source_ramp(Eigen::VectorXd::Ones(4), Eigen::VectorXd::Ones(4), 1.0, 1.0),
               std::invalid_argument);
  Eigen::VectorXd t = Eigen::VectorXd::Zero(4);
  t[2] = std::nan("");
  EXPECT_THROW(p.check_state(t), std::invalid_argument);
  EXPECT_THROW(p.check_state(Eigen::VectorXd::Zero(5)), std::invalid_argument);
}

TEST(ThermalProblem, HeatRateHasEveryTerm) {
  // 3 nodes, dx = 1, ρc = 1: lumped M = (0.5, 1, 0.5), conductance 1 between neighbours.
  const auto g = make_grid_1d(3, 0.0, 2.0, Material{1.0, 1.0});
  ft::Problem p = g.problem();
  p.set_source(Eigen::Vector3d(1.0, 0.0, 0.0));
  p.add_flux(1, 2.0);
  p.add_convection(2, 0.5, 10.0);
  const Eigen::Vector3d temp(1.0, 2.0, 4.0);
  Eigen::VectorXd w(3);
  p.heat_rate(0.0, temp, w);
  // w = −K T + q + f + hA (T_inf − T), by hand:
  EXPECT_DOUBLE_EQ(w[0], -(1.0 - 2.0) + 1.0);
  EXPECT_DOUBLE_EQ(w[1], -(-1.0 + 2.0 * 2.0 - 4.0) + 2.0);
  EXPECT_DOUBLE_EQ(w[2], -(-2.0 + 4.0) + 0.5 * (10.0 - 4.0));
  EXPECT_DOUBLE_EQ(p.boundary_and_source_power(0.0, temp), 1.0 + 2.0 + 3.0);
  Eigen::VectorXd f(3);
  p.rhs(0.0, temp, f);
  EXPECT_DOUBLE_EQ(f[1], w[1] / 1.0);  // M_1 = 1
  EXPECT_DOUBLE_EQ(f[0], w[0] / 0.5);  // M_0 = 0.5
  p.set_dirichlet(0, 7.0);
  p.heat_rate(0.0, temp, w);
  EXPECT_EQ(w[0], 0.0);  // fixed node: dT/dt = 0
  Eigen::VectorXd t2 = temp;
  p.apply_dirichlet(t2);
  EXPECT_EQ(t2[0], 7.0);
}

TEST(ThermalProblem, SourceRampIsLinearAndClamped) {
  auto p = make_grid_1d(2, 0.0, 1.0, Material{}).problem();
  p.set_source_ramp(Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(3.0, 4.0), 10.0, 12.0);
  EXPECT_DOUBLE_EQ(p.source(11.0)[0], 2.0);  // q0 + (t−t0)/(t1−t0)(q1−q0)
  EXPECT_DOUBLE_EQ(p.source(11.5)[1], 3.0);
  EXPECT_DOUBLE_EQ(p.source(5.0)[0], 1.0);   // held at q0 before the window
  EXPECT_DOUBLE_EQ(p.source(20.0)[1], 4.0);  // and at q1 after it
}

TEST(ThermalProblem, RevisionTracksOperatorChangesOnly) {
  auto p = make_grid_1d(3, 0.0, 1.0, Material{}).problem();
  const auto r0 = p.revision();
  p.set_source(Eigen::VectorXd::Ones(3));
  EXPECT_EQ(p.revision(), r0);  // sources do not change the Jacobian
  p.add_convection(1, 1.0, 0.0);
  EXPECT_NE(p.revision(), r0);
  const auto q = make_grid_1d(3, 0.0, 1.0, Material{}).problem();
  EXPECT_NE(q.revision(), p.revision());  // unique across objects
}

// reset() in the old object's storage is the same as a new Problem: every source, boundary, fixed node
// and reaction of the old one gone, the new M and K in force (heat rate bitwise that of a fresh
// Problem), a new revision, and the constructor's checks (a non-symmetric K is refused by name).
TEST(ThermalProblem, ResetEqualsAFreshProblem) {
  const auto a = make_grid_1d(4, 0.0, 1.0, Material{});
  const auto b = make_grid_1d(4, 0.0, 3.0, Material{2.0, 0.5});
  ft::Problem p(a.mass, a.k);
  p.set_source(Eigen::VectorXd::Ones(4));
  p.add_flux(1, 2.0);
  p.add_convection(2, 0.5, 10.0);
  p.set_dirichlet(3, 7.0);
  ft::Reaction rx;
  rx.heat = Eigen::VectorXd::Constant(4, 1e3);
  rx.prefactor = 1e10;
  rx.activation_temperature = 1e4;
  p.set_reaction(rx);
  const auto r0 = p.revision();

  p.reset(b.mass, b.k);
  const ft::Problem fresh(b.mass, b.k);
  EXPECT_NE(p.revision(), r0);
  EXPECT_FALSE(p.has_source());
  EXPECT_FALSE(p.has_reaction());
  EXPECT_TRUE(p.dirichlet_nodes().empty());
  EXPECT_FALSE(p.is_dirichlet(3));
  EXPECT_EQ(p.flux().cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(p.convection_coefficients().cwiseAbs().maxCoeff(), 0.0);
  const Eigen::Vector4d temp(300.0, 310.0, 305.0, 900.0);
  Eigen::VectorXd w(4), w_fresh(4);
  p.heat_rate(0.0, temp, w);
  fresh.heat_rate(0.0, temp, w_fresh);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(w[i], w_fresh[i]) << i;
  EXPECT_NE(w.cwiseAbs().maxCoeff(), 0.0);  // K of b acts: the temperatures differ

  Eigen::MatrixXd bad = Eigen::MatrixXd(b.k);
  bad(0, 1) = -5.0;
  const auto msg = message_of([&] { p.reset(b.mass, dense_to_sparse(bad)); });
  EXPECT_NE(msg.find("not symmetric"), std::string::npos) << msg;
}
