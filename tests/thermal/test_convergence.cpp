// Temporal convergence against the exact semi-discrete solution of the eigenmode problem
// (sin(πx/L) e^{−λ_h t}, see test_analytic_1d.cpp), so no spatial error enters (verification).
#include "frictherm/thermal/integrator.hpp"
#include "grids.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace ft = frictherm::thermal;
using thermal_test::make_grid_1d;
using thermal_test::Material;

namespace {

const Material kMat{2.09e6, 0.45};

struct Mode {
  double len = 40e-6;
  thermal_test::Grid1D g = make_grid_1d(41, 0.0, 40e-6, kMat);
  ft::Problem p = g.problem();
  double lam_h = 4 * kMat.alpha() / (g.dx * g.dx) * std::pow(std::sin(M_PI * g.dx / (2 * len)), 2);
  Mode() {
    p.set_dirichlet(0, 0.0);
    p.set_dirichlet(g.n - 1, 0.0);
  }
  Eigen::VectorXd initial() const {
    Eigen::VectorXd t(g.n);
    for (int i = 0; i < g.n; ++i) t[i] = std::sin(M_PI * g.x(i) / len);
    return t;
  }
  double error(const Eigen::VectorXd& t, double time) const {
    return (t - initial() * std::exp(-lam_h * time)).cwiseAbs().maxCoeff();
  }
};

}  // namespace

// FE error ∝ dt: halving dt halves the error (observed order within 0.1 of 1).
TEST(ThermalConvergence, ForwardEulerIsFirstOrder) {
  Mode m;
  const double t_end = 1.0 / m.lam_h;
  const double dt_limit = m.g.dx * m.g.dx / (2 * kMat.alpha());
  double prev = 0.0;
  for (int k = 0; k < 4; ++k) {
    ft::IntegratorOptions o;
    o.fe_max_dt = 0.4 * dt_limit / std::pow(2.0, k);
    auto fe = ft::make_integrator("forward_euler", o);
    Eigen::VectorXd t = m.initial();
    fe->advance(m.p, t, 0.0, t_end);
    const double err = m.error(t, t_end);
    if (k > 0) {
      const double order = std::log2(prev / err);
      RecordProperty("order_" + std::to_string(k), thermal_test::sci(order));
      EXPECT_NEAR(order, 1.0, 0.1) << "dt = " << o.fe_max_dt;
    }
    prev = err;
  }
}

// Adaptive SUNDIALS methods: the global error follows the tolerance. Bound err ≤ 30·tol
// (global error accumulates local errors over the steps) and at least a 100× error drop
// for a 10⁴× tighter tolerance (error ∝ tol^{p/(p+1)} for an order-p controller).
TEST(ThermalConvergence, SundialsIntegratorsConvergeToTolerance) {
  Mode m;
  const double t_end = 1.0 / m.lam_h;
  for (const auto& [name, ls] : {std::pair<std::string, std::string>{"cvode_bdf", "klu"}, {"cvode_bdf", "pcg"},
                                 {"cvode_adams", ""}, {"arkode_erk", ""}, {"arkode_dirk", "klu"},
                                 {"arkode_dirk", "pcg"}}) {
    double err_loose = 0.0, err_tight = 0.0;
    for (double tol : {1e-4, 1e-6, 1e-8}) {
      ft::IntegratorOptions o;
      o.rtol = tol;
      o.atol = tol;  // amplitude 1 K
      o.linear_solver = ls;
      auto integ = ft::make_integrator(name, o);
      Eigen::VectorXd t = m.initial();
      integ->advance(m.p, t, 0.0, t_end);
      const double err = m.error(t, t_end);
      RecordProperty("err_" + name + ls + "_" + thermal_test::sci(tol), thermal_test::sci(err));
      EXPECT_LT(err, 30 * tol) << name << "/" << ls << " tol " << tol;
      if (tol == 1e-4) err_loose = err;
      if (tol == 1e-8) err_tight = err;
    }
    EXPECT_LT(err_tight, err_loose / 100) << name << "/" << ls;
  }
}
