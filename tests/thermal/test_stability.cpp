// Where explicit methods fail (thermal-notes §2): forward Euler past dt_limit, its guards,
// and CVODE Adams hitting its step limit (unit).
#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/stability.hpp"
#include "grids.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace ft = frictherm::thermal;
using thermal_test::make_grid_1d;
using thermal_test::make_grid_2d;
using thermal_test::Material;

namespace {

const Material kMat{2.09e6, 0.45};  // HMX-like ρc [J/(m³K)] and k [W/(m K)]

// Mass-weighted checkerboard amplitude a in T = T̄ + a·(−1)^i (exact eigenvector, see grids.hpp).
double checkerboard(const Eigen::VectorXd& t, const Eigen::VectorXd& m) {
  double num = 0.0;
  for (Eigen::Index i = 0; i < t.size(); ++i) num += ((i % 2) ? -1.0 : 1.0) * m[i] * t[i];
  return num / m.sum();
}

}  // namespace

TEST(ThermalStability, GershgorinLimitIsExactOnFdGrids) {
  // 1D: λmax = 4α/dx² (checkerboard), so dt_limit = dx²/(2α); 2D: h²/(4α) (thermal-notes §2).
  const auto g1 = make_grid_1d(51, 0.0, 50e-6, kMat);
  const double dt1 = ft::forward_euler_dt_limit(g1.problem());
  EXPECT_NEAR(dt1, g1.dx * g1.dx / (2 * kMat.alpha()), 1e-12 * dt1);
  const auto g2 = make_grid_2d(21, 21, 0.0, 0.0, 1e-6, kMat);
  const double dt2 = ft::forward_euler_dt_limit(g2.problem());
  EXPECT_NEAR(dt2, g2.h * g2.h / (4 * kMat.alpha()), 1e-12 * dt2);
  // Power iteration converges to λmax from below (checkerboard start vector is the top
  // eigenvector here), so its limit is at most 5 % looser, never tighter, than Gershgorin's.
  const double dtp = ft::forward_euler_dt_limit(g2.problem(), "power");
  EXPECT_GE(dtp, dt2 * (1 - 1e-12));
  EXPECT_LE(dtp, dt2 * (1 + 1e-9));  // capped by Gershgorin, which is exact here
}

// The sweep dt/dt_limit ∈ {0.5, 0.99, 1.01, 2, 10} from T = 300 K + 1e-3 K checkerboard.
// Unguarded FE multiplies the checkerboard by (1 − 2r) per step exactly (it is an eigenvector
// with dt·λ = 2r); the guarded (sub-stepping) FE keeps it bounded for every r.
TEST(ThermalStability, ForwardEulerSweepUnguardedGrowsGuardedStaysBounded) {
  const auto g = make_grid_1d(40, 0.0, 39e-6, kMat);
  const ft::Problem p = g.problem();
  const double dt_limit = g.dx * g.dx / (2 * kMat.alpha());
  Eigen::VectorXd t0(g.n);
  for (int i = 0; i < g.n; ++i) t0[i] = 300.0 + ((i % 2) ? -1e-3 : 1e-3);
  const double a0 = checkerboard(t0, g.mass);
  const int steps = 40;
  for (double r : {0.5, 0.99, 1.01, 2.0, 10.0}) {
    ft::IntegratorOptions o;
    o.fe_stability_policy = "unguarded";
    o.fe_max_dt = r * dt_limit;
    auto fe = ft::make_integrator("forward_euler", o);
    Eigen::VectorXd t = t0;
    fe->advance(p, t, 0.0, steps * r * dt_limit);
    EXPECT_EQ(fe->stats().steps, steps);
    const double growth = checkerboard(t, g.mass) / a0;
    const double predicted = std::pow(1.0 - 2.0 * r, steps);
    if (predicted == 0.0) {
      EXPECT_LT(std::abs(growth), 1e-9) << "r = " << r;  // r = 0.5 kills the mode in one step
    } else {
      EXPECT_NEAR(growth / predicted, 1.0, 1e-6) << "r = " << r;  // round-off vs (1−2r)^n
    }
    if (r < 1.0) {
      EXPECT_LE(std::abs(growth), 1.0) << "r = " << r;
    } else {
      EXPECT_GT(std::abs(growth), 2.0) << "r = " << r;  // 1.02^40 = 2.2 at r = 1.01
    }
    EXPECT_NEAR(t.mean(), 300.0, 1e-9 + 1e-3 * std::abs(growth));  // mean carried exactly

    o.fe_stability_policy = "substep";
    auto guarded = ft::make_integrator("forward_euler", o);
    Eigen::VectorXd u = t0;
    guarded->advance(p, u, 0.0, steps * r * dt_limit);
    EXPECT_LE(std::abs(checkerboard(u, g.mass)), std::abs(a0)) << "r = " << r;
    EXPECT_LE((u.array() - 300.0).abs().maxCoeff(), 1e-3 * (1 + 1e-9)) << "r = " << r;
  }
}

TEST(ThermalStability, RefusePolicyThrowsPastTheLimit) {
  const auto g = make_grid_1d(40, 0.0, 39e-6, kMat);
  const ft::Problem p = g.problem();
  const double dt_limit = g.dx * g.dx / (2 * kMat.alpha());
  for (double r : {0.5, 0.99, 1.01, 2.0, 10.0}) {
    ft::IntegratorOptions o;
    o.fe_stability_policy = "refuse";
    o.fe_safety = 1.0;
    auto fe = ft::make_integrator("forward_euler", o);
    Eigen::VectorXd t = Eigen::VectorXd::Constant(g.n, 300.0);
    if (r < 1.0) {
      EXPECT_NO_THROW(fe->advance(p, t, 0.0, r * dt_limit));
      continue;
    }
    const Eigen::VectorXd before = t;
    try {
      fe->advance(p, t, 0.0, r * dt_limit);
      FAIL() << "no exception at r = " << r;
    } catch (const ft::StabilityError& e) {
      EXPECT_NE(std::string(e.what()).find("stability limit"), std::string::npos) << e.what();
      EXPECT_NEAR(e.dt_limit(), dt_limit, 1e-12 * dt_limit);
      EXPECT_NEAR(e.dt(), r * dt_limit, 1e-12 * dt_limit);
    }
    EXPECT_EQ(t, before);  // state untouched
  }
}

TEST(ThermalStability, UnguardedBlowUpIsReportedNotSilent) {
  const auto g = make_grid_1d(40, 0.0, 39e-6, kMat);
  const double dt_limit = g.dx * g.dx / (2 * kMat.alpha());
  ft::IntegratorOptions o;
  o.fe_stability_policy = "unguarded";
  o.fe_max_dt = 10 * dt_limit;  // 19^n overflows after ~240 steps
  auto fe = ft::make_integrator("forward_euler", o);
  Eigen::VectorXd t(g.n);
  for (int i = 0; i < g.n; ++i) t[i] = 300.0 + ((i % 2) ? -1.0 : 1.0);
  EXPECT_THROW(fe->advance(g.problem(), t, 0.0, 400 * 10 * dt_limit), ft::StabilityError);
  EXPECT_TRUE(t.allFinite());
}

TEST(ThermalStability, CvodeAdamsHitsItsStepLimitWithAClearError) {
  const auto g = make_grid_1d(50, 0.0, 49e-6, kMat);
  const ft::Problem p = g.problem();
  const double dt_limit = g.dx * g.dx / (2 * kMat.alpha());
  ft::IntegratorOptions o;
  o.max_steps = 50;
  auto adams = ft::make_integrator("cvode_adams", o);
  Eigen::VectorXd t(g.n);
  for (int i = 0; i < g.n; ++i) t[i] = 300.0 + 50.0 * std::sin(0.3 * i);
  const Eigen::VectorXd before = t;
  try {
    adams->advance(p, t, 0.0, 1000 * dt_limit);  // stability-limited: ≫ 50 steps needed
    FAIL() << "no exception";
  } catch (const ft::SolverError& e) {
    const std::string msg = e.what();
    RecordProperty("message", msg);
    EXPECT_EQ(e.flag_name(), "CV_TOO_MUCH_WORK");
    EXPECT_NE(msg.find("CV_TOO_MUCH_WORK"), std::string::npos) << msg;
    EXPECT_NE(msg.find("max_steps = 50"), std::string::npos) << msg;
    EXPECT_NE(msg.find("mxstep"), std::string::npos) << msg;  // SUNDIALS' own message
  }
  EXPECT_EQ(t, before);
  EXPECT_EQ(adams->stats().steps, 50);
  // cvode_bdf takes the same window comfortably.
  o.max_steps = 500;
  auto bdf = ft::make_integrator("cvode_bdf", o);
  EXPECT_NO_THROW(bdf->advance(p, t, 0.0, 1000 * dt_limit));
  EXPECT_LT(bdf->stats().steps, 500);
}

// Forward Euler sub-steps a window to its stability limit, at most max_steps of them: a window that
// needs more (a conductivity of 1e12 W/mK in a scene: 3e7 sub-steps per mechanics step, a run that
// never ends) is refused before any sub-step, however many it would need.
TEST(ThermalStability, ForwardEulerRefusesWindowsBeyondMaxSteps) {
  const auto g = make_grid_1d(40, 0.0, 39e-6, kMat);
  const ft::Problem p = g.problem();
  const double dt_limit = g.dx * g.dx / (2 * kMat.alpha());
  ft::IntegratorOptions o;
  o.max_steps = 100;  // fe_safety 0.9: 90 dt_limit fit in 100 sub-steps
  auto fe = ft::make_integrator("forward_euler", o);
  Eigen::VectorXd t(g.n);
  for (int i = 0; i < g.n; ++i) t[i] = 300.0 + 50.0 * std::sin(0.3 * i);
  EXPECT_NO_THROW(fe->advance(p, t, 0.0, 89.0 * dt_limit));
  EXPECT_EQ(fe->stats().steps, 99);
  const Eigen::VectorXd before = t;
  for (double windows : {91.0, 1e6, 1e30}) {
    try {
      fe->advance(p, t, 0.0, windows * dt_limit);
      FAIL() << "no exception for " << windows << " dt_limit";
    } catch (const ft::StabilityError& e) {
      EXPECT_NE(std::string(e.what()).find("more than max_steps = 100"), std::string::npos) << e.what();
    }
    EXPECT_EQ(t, before);  // state untouched
  }
  EXPECT_EQ(fe->stats().steps, 99);  // not one sub-step taken by the refused windows
}
