// Integrator factory, options, window handling and statistics (unit).
#include "frictherm/thermal/integrator.hpp"
#include "grids.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace ft = frictherm::thermal;
using thermal_test::make_grid_1d;
using thermal_test::Material;

namespace {

struct Config {
  std::string name;
  std::string linear_solver;
};

std::vector<Config> all_configs() {
  return {{"forward_euler", ""}, {"cvode_bdf", "klu"}, {"cvode_bdf", "pcg"},  {"cvode_adams", ""},
          {"arkode_erk", ""},    {"arkode_dirk", "klu"}, {"arkode_dirk", "pcg"}};
}

std::string label(const Config& c) { return c.name + (c.linear_solver.empty() ? "" : "/" + c.linear_solver); }

}  // namespace

TEST(ThermalIntegrators, UnknownNameListsTheValidOnes) {
  try {
    ft::make_integrator("cvode_bfd");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    for (const auto& n : ft::integrator_names()) EXPECT_NE(msg.find(n), std::string::npos) << msg;
  }
}

TEST(ThermalIntegrators, RejectsBadOptions) {
  ft::IntegratorOptions o;
  o.fe_stability_policy = "hope";
  EXPECT_THROW(ft::make_integrator("forward_euler", o), std::invalid_argument);
  o = {};
  o.linear_solver = "lu";
  EXPECT_THROW(ft::make_integrator("cvode_bdf", o), std::invalid_argument);
  o.linear_solver = "klu";
  EXPECT_THROW(ft::make_integrator("arkode_erk", o), std::invalid_argument);
  o = {};
  o.rtol = 0.0;
  EXPECT_THROW(ft::make_integrator("cvode_bdf", o), std::invalid_argument);
  o = {};
  o.fe_safety = 1.5;
  EXPECT_THROW(ft::make_integrator("forward_euler", o), std::invalid_argument);
}

// No conduction between nodes (K = 0) and a constant source: T = T0 + q t / M exactly, and
// every method integrates a constant derivative exactly (to round-off).
TEST(ThermalIntegrators, EveryIntegratorIntegratesAConstantSource) {
  const int n = 5;
  ft::SparseMatrix k(n, n);
  const Eigen::VectorXd m = Eigen::VectorXd::LinSpaced(n, 1.0, 3.0);
  ft::Problem p(m, k);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(n, -2.0, 5.0);
  p.set_source(q);
  for (const auto& c : all_configs()) {
    ft::IntegratorOptions o;
    o.linear_solver = c.linear_solver;
    auto integ = ft::make_integrator(c.name, o);
    Eigen::VectorXd t = Eigen::VectorXd::Constant(n, 300.0);
    integ->advance(p, t, 0.0, 2.0);
    const Eigen::VectorXd exact = Eigen::VectorXd::Constant(n, 300.0) + 2.0 * q.cwiseQuotient(m);
    EXPECT_LT((t - exact).cwiseAbs().maxCoeff(), 1e-9) << label(c);  // round-off on 300 K
    EXPECT_EQ(integ->name(), c.name);
    EXPECT_GT(integ->stats().steps, 0) << label(c);
    EXPECT_GT(integ->stats().rhs_evals, 0) << label(c);
  }
}

// 6.4.1 stop-time pitfall: many consecutive windows must all succeed, continue without
// re-initialisation, and agree with one long window to the integration tolerance.
TEST(ThermalIntegrators, ConsecutiveWindowsContinueAndMatchOneWindow) {
  const Material mat{2.0e6, 0.5};
  const auto g = make_grid_1d(41, 0.0, 40e-6, mat);
  ft::Problem p = g.problem();
  Eigen::VectorXd t0(g.n);
  for (int i = 0; i < g.n; ++i) t0[i] = 300.0 + 100.0 * std::exp(-std::pow((g.x(i) - 20e-6) / 4e-6, 2));
  const double tend = 2e-4;
  for (const auto& c : all_configs()) {
    if (c.name == "forward_euler") continue;
    ft::IntegratorOptions o;
    o.linear_solver = c.linear_solver;
    o.rtol = 1e-8;
    o.atol = 1e-8;
    auto many = ft::make_integrator(c.name, o);
    Eigen::VectorXd a = t0;
    for (int w = 0; w < 20; ++w) many->advance(p, a, w * tend / 20, (w + 1) * tend / 20);
    EXPECT_EQ(many->stats().reinits, 1) << label(c);
    auto one = ft::make_integrator(c.name, o);
    Eigen::VectorXd b = t0;
    one->advance(p, b, 0.0, tend);
    // Each run's global error is ~10–100 local tolerances rtol·|T| ≈ 1e-8·400 K, so they
    // agree to ~1e-4 K (observed 1.5e-5 K).
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-4) << label(c);

    // An outside change of T (the coupling adds heat) forces a re-init and is honoured.
    const long steps_before = many->stats().steps;
    a[20] += 1.0;
    const double e_before = p.thermal_energy(a);
    many->advance(p, a, tend, 1.1 * tend);
    EXPECT_EQ(many->stats().reinits, 2) << label(c);
    EXPECT_GT(many->stats().steps, steps_before) << label(c);  // counters survive ReInit
    EXPECT_NEAR(p.thermal_energy(a), e_before, 1e-9 * e_before) << label(c);
  }
}

TEST(ThermalIntegrators, ResetStatsAndZeroWindow) {
  const auto g = make_grid_1d(11, 0.0, 1.0, Material{});
  ft::Problem p = g.problem();
  auto integ = ft::make_integrator("cvode_bdf");
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(g.n, 0.0, 1.0);
  integ->advance(p, t, 0.0, 0.01);
  EXPECT_GT(integ->stats().steps, 0);
  integ->reset_stats();
  EXPECT_EQ(integ->stats().steps, 0);
  const Eigen::VectorXd before = t;
  integ->advance(p, t, 0.01, 0.01);  // empty window: nothing happens
  EXPECT_EQ(t, before);
  EXPECT_THROW(integ->advance(p, t, 0.02, 0.01), std::invalid_argument);
  integ->advance(p, t, 0.01, 0.02);
  EXPECT_GT(integ->stats().steps, 0);
  EXPECT_GT(integ->stats().wall_seconds, 0.0);
}
