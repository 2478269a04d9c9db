// Frank-Kamenetskii thermal explosion (issue 5 "How it is checked") and the stiffness of
// Arrhenius runaway (verification).
//
// A slab of half-width a (Dirichlet walls at T0) and a sphere of radius a (surface at T0),
// HMX-like, with zero-order Arrhenius heating ρq·Z·exp(−Θ/T) (Reaction::consume = false: the
// FK theory has no reactant depletion). The critical size a_c is found by bisection with
// CVODE BDF: a run "runs away" when max(T − T0) passes 10 T0²/Θ (θ = 10 in FK units; the stable
// steady branch stays below θ_m ≈ 1.24 / 1.69) before 100 a²/α, and is subcritical otherwise.
// Then δ_c = ρq Z Θ a_c²/(k T0²)·exp(−Θ/T0) must be 0.88 (slab) and 3.32 (sphere) within 5 %.
//
// Tolerance: the classical values are the large-activation-energy limit ε = T0/Θ → 0. Here
// Θ/T0 = 50 (ε = 0.02); the full-Arrhenius critical values are then δ_c(ε) = 0.8975 (slab) and
// 3.3997 (sphere) — computed for this test by shooting on θ'' + (j/x)θ' + δ exp(θ/(1+εθ)) = 0
// (RK4, maximising over θ(0); at ε = 0 it returns 0.87846 and 3.32199). That is +2.0 % and
// +2.4 % from 0.88 / 3.32. Spatial error (101 nodes, second order) ≈ 1e-4, bisection 1e-3,
// so 5 % holds with ≥ 2.5 % margin; the test also checks δ_c against δ_c(ε) within 1 %.
//
// The sphere is the radially symmetric 1D finite-volume form: nodes r_i = i h, shells
// [r_{i−½}, r_{i+½}] of volume (r_{i+½}³ − r_{i−½}³)/3, conductance k r_{i+½}²/h between
// neighbours (the common factor 4π dropped from M, K and Q alike).
#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/reaction.hpp"
#include "grids.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace ft = frictherm::thermal;
using thermal_test::Material;

namespace {

const Material kHmx{1900.0 * 1100.0, 0.45};  // ρc [J/(m³K)], k [W/(m K)]
constexpr double kRho = 1900.0;
const ft::ArrheniusKinetics kKin = ft::hmx_kinetics_rogers1975();
const double kTheta = kKin.activation_temperature;
const double kT0 = kTheta / 50.0;  // ε = T0/Θ = 0.02 (T0 ≈ 530 K)
constexpr int kNodes = 101;

// δ / a² for the FK parameter δ = ρq Z Θ a²/(k T0²) exp(−Θ/T0).
double delta_per_a2() {
  return kRho * kKin.specific_heat_of_reaction * kKin.prefactor * kTheta / (kHmx.k * kT0 * kT0) *
         std::exp(-kTheta / kT0);
}

struct Geometry {
  Eigen::VectorXd mass;
  ft::SparseMatrix k;
  Eigen::VectorXd volume;  // per node [m³ per unit area (slab) or per steradian/… (sphere)]
};

// Half slab [0, a]: adiabatic (symmetry) at x = 0, wall at x = a.
Geometry slab(double a) {
  const auto g = thermal_test::make_grid_1d(kNodes, 0.0, a, kHmx);
  return {g.mass, g.k, g.mass / kHmx.rho_c};
}

Geometry sphere(double a) {
  const double h = a / (kNodes - 1);
  Geometry g;
  g.volume.resize(kNodes);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < kNodes; ++i) {
    const double lo = std::max(0.0, (i - 0.5) * h), hi = std::min(a, (i + 0.5) * h);
    g.volume[i] = (hi * hi * hi - lo * lo * lo) / 3.0;
    if (i + 1 < kNodes) {
      const double c = kHmx.k * hi * hi / h;
      t.emplace_back(i, i, c);
      t.emplace_back(i + 1, i + 1, c);
      t.emplace_back(i, i + 1, -c);
      t.emplace_back(i + 1, i, -c);
    }
  }
  g.mass = kHmx.rho_c * g.volume;
  g.k.resize(kNodes, kNodes);
  g.k.setFromTriplets(t.begin(), t.end());
  return g;
}

ft::Problem reacting_problem(const Geometry& g, bool consume) {
  ft::Problem p(g.mass, g.k);
  p.set_dirichlet(kNodes - 1, kT0);
  p.set_reaction(ft::make_reaction(kKin, kRho * g.volume, consume));
  return p;
}

double runaway_excess() { return 10.0 * kT0 * kT0 / kTheta; }  // θ = 10

// CVODE BDF from uniform T0; true when max T − T0 passes θ = 10 before 100 a²/α. Without
// depletion, T grows without bound once a run has gone away (zero-order heating never stops),
// so a window in which CVODE reaches max_steps (T left unchanged) is retried at half length:
// the state then crosses the threshold inside a shorter window.
bool runs_away(const Geometry& g, double a, ft::IntegratorStats& total) {
  ft::Problem p = reacting_problem(g, false);
  ft::IntegratorOptions o;
  o.rtol = 1e-6;
  o.atol = 1e-4;
  o.max_steps = 2000;
  auto integ = ft::make_integrator("cvode_bdf", o);
  Eigen::VectorXd temp = Eigen::VectorXd::Constant(kNodes, kT0);
  const ft::Reaction& rx = p.reaction();
  const double heating = kRho * kKin.specific_heat_of_reaction / kHmx.rho_c;  // ΔT_ad [K]
  const double tdiff = a * a / kHmx.alpha();
  double t = 0.0, retry = 1.0;
  bool away = false;
  while (!away && t < 100.0 * tdiff) {
    // Windows no longer than half the adiabatic time for θ to grow by one at the hottest node,
    // so a runaway is caught near the threshold.
    const double tmax = temp.maxCoeff();
    const double t_adiabatic = tmax * tmax / (kTheta * heating * rx.rate_constant(tmax));
    const double window = retry * std::min(0.25 * tdiff, 0.5 * t_adiabatic);
    try {
      integ->advance(p, temp, t, t + window);
    } catch (const ft::SolverError& e) {
      if (retry < 1e-6) {
        ADD_FAILURE() << e.what();
        break;
      }
      retry *= 0.5;
      continue;
    }
    retry = 1.0;
    t += window;
    away = temp.maxCoeff() - kT0 > runaway_excess();
  }
  total += integ->stats();
  return away;
}

struct Critical {
  double delta = 0.0;
  int runs = 0;
  ft::IntegratorStats stats;
};

Critical bisect(Geometry (*make)(double), double delta_guess) {
  Critical c;
  const double a_guess = std::sqrt(delta_guess / delta_per_a2());
  double lo = 0.8 * a_guess, hi = 1.25 * a_guess;
  EXPECT_FALSE(runs_away(make(lo), lo, c.stats)) << "lower bracket runs away";
  EXPECT_TRUE(runs_away(make(hi), hi, c.stats)) << "upper bracket does not run away";
  c.runs = 2;
  for (int it = 0; it < 11; ++it) {  // a to 0.45/2^11 ≈ 2e-4 relative
    const double mid = 0.5 * (lo + hi);
    (runs_away(make(mid), mid, c.stats) ? hi : lo) = mid;
    ++c.runs;
  }
  const double a_c = 0.5 * (lo + hi);
  c.delta = delta_per_a2() * a_c * a_c;
  return c;
}

void report(const char* what, const Critical& c, double classical, double finite_eps) {
  std::printf("[ FK ] %s: delta_c = %.4f (classical %.2f: %+.2f %%; eps = 0.02 value %.4f: %+.2f %%), "
              "%d CVODE BDF runs, %ld steps, %ld RHS, %.2f s\n",
              what, c.delta, classical, 100.0 * (c.delta / classical - 1.0), finite_eps,
              100.0 * (c.delta / finite_eps - 1.0), c.runs, c.stats.steps, c.stats.rhs_evals,
              c.stats.wall_seconds);
}

}  // namespace

TEST(FrankKamenetskii, SlabCriticalParameter) {
  const Critical c = bisect(&slab, 0.88);
  report("slab", c, 0.88, 0.8975);
  ::testing::Test::RecordProperty("delta_c_slab", thermal_test::sci(c.delta));
  EXPECT_NEAR(c.delta, 0.88, 0.05 * 0.88);
  EXPECT_NEAR(c.delta, 0.8975, 0.01 * 0.8975);
}

TEST(FrankKamenetskii, SphereCriticalParameter) {
  const Critical c = bisect(&sphere, 3.32);
  report("sphere", c, 3.32, 3.3997);
  ::testing::Test::RecordProperty("delta_c_sphere", thermal_test::sci(c.delta));
  EXPECT_NEAR(c.delta, 3.32, 0.05 * 3.32);
  EXPECT_NEAR(c.delta, 3.3997, 0.01 * 3.3997);
}

// Stiffness of runaway (work–precision, printed): the slab at δ = 1.1 δ_c(ε) with reactant
// consumption (first-order, ΔT_ad = ρq/ρc ≈ 1900 K) from uniform T0 up to t*, the last
// reference sample before θ_max = 3 (past the critical steady state θ_m ≈ 1.24, so committed
// to runaway, but before the blow-up, where a fixed-time comparison becomes ill-conditioned:
// O(1e-6) local errors there shift the ignition time by more than the remaining interval),
// then on through ignition. Robust facts asserted:
// cvode_bdf (rtol 1e-6) reaches t* within 2 % of the temperature rise with ≥ 10× fewer steps than
// forward Euler and arkode_erk (both stability-limited by conduction, h ≲ h²/2α), and after
// ignition (k(T_burnt) ≈ 1e15 1/s) arkode_erk cannot take a step while cvode_bdf goes on.
TEST(FrankKamenetskii, RunawayNeedsAStiffIntegrator) {
  const double a = std::sqrt(1.1 * 0.8975 / delta_per_a2());
  const Geometry g = slab(a);
  ft::Problem p = reacting_problem(g, true);
  const double tdiff = a * a / kHmx.alpha();
  const Eigen::VectorXd t_init = Eigen::VectorXd::Constant(kNodes, kT0);
  const Eigen::VectorXd l_init = Eigen::VectorXd::Zero(kNodes);

  // Reference and t*.
  ft::IntegratorOptions ro;
  ro.rtol = 1e-10;
  ro.atol = 1e-8;
  ro.progress_atol = 1e-12;
  ro.max_steps = 1000000;
  auto ref = ft::make_integrator("cvode_bdf", ro);
  Eigen::VectorXd tr = t_init, lr = l_init, tprev = t_init, lprev = l_init;
  const double dtw = 0.01 * tdiff;
  double t_star = 0.0;
  for (int w = 0; w < 1000; ++w) {
    tprev = tr;
    lprev = lr;
    try {
      ref->advance(p, tr, lr, w * dtw, (w + 1) * dtw);
    } catch (const ft::SolverError&) {
      break;  // (not expected before θ = 3)
    }
    if (tr.maxCoeff() - kT0 > 0.3 * runaway_excess()) break;  // θ = 3
    t_star = (w + 1) * dtw;
  }
  ASSERT_GT(t_star, 0.0);
  const Eigen::VectorXd t_ref = tprev;
  const double rise = t_ref.maxCoeff() - kT0;
  std::printf("[ FK ] runaway slab (delta = 1.1 delta_c, consuming, theta_max = 3): t* = %.4g s = %.3f a^2/alpha, "
              "max T - T0 = %.1f K at t*\n", t_star, t_star / tdiff, rise);
  std::printf("[ FK ] %-18s %8s %10s %10s %10s %12s\n", "integrator", "rtol", "steps", "rhs", "wall_ms",
              "err/rise");

  struct Run {
    std::string name, ls;
    double rtol;
  };
  const std::vector<Run> runs{{"cvode_bdf", "klu", 1e-4},  {"cvode_bdf", "klu", 1e-6},
                              {"cvode_bdf", "pcg", 1e-6},  {"arkode_dirk", "klu", 1e-6},
                              {"arkode_erk", "", 1e-4},
                              {"arkode_erk", "", 1e-6},    {"forward_euler", "", 0.0}};
  long bdf_steps = 0, fe_steps = 0, erk_steps = 0;
  for (const auto& r : runs) {
    ft::IntegratorOptions o;
    o.linear_solver = r.ls;
    o.rtol = r.rtol > 0.0 ? r.rtol : 1e-6;
    o.atol = 1e-6;
    o.max_steps = 2000000;
    auto integ = ft::make_integrator(r.name, o);
    Eigen::VectorXd tt = t_init, ll = l_init;
    integ->advance(p, tt, ll, 0.0, t_star);
    const auto& s = integ->stats();
    const double err = (tt - t_ref).cwiseAbs().maxCoeff() / rise;
    std::printf("[ FK ] %-18s %8.0e %10ld %10ld %10.2f %12.2e\n",
                (r.name + (r.ls.empty() ? "" : "/" + r.ls)).c_str(), r.rtol, s.steps, s.rhs_evals,
                1e3 * s.wall_seconds, err);
    if (r.name == "cvode_bdf" && r.ls == "klu" && r.rtol == 1e-6) {
      bdf_steps = s.steps;
      EXPECT_LT(err, 2e-2);  // observed 7.7e-3
    }
    if (r.name == "forward_euler") fe_steps = s.steps;
    if (r.name == "arkode_erk" && r.rtol == 1e-6) erk_steps = s.steps;
    EXPECT_LT(err, 0.1) << r.name;
  }
  EXPECT_GE(fe_steps, 10 * bdf_steps);
  EXPECT_GE(erk_steps, 10 * bdf_steps);

  // Through ignition: from t* on for 0.5 a²/α.
  const double t_end = t_star + 0.5 * tdiff;
  ft::IntegratorOptions o;
  o.rtol = 1e-6;
  o.atol = 1e-6;
  o.max_steps = 200000;
  auto bdf = ft::make_integrator("cvode_bdf", o);
  Eigen::VectorXd tb = t_ref, lb = lprev;
  bdf->advance(p, tb, lb, t_star, t_end);
  const double kmax = p.reaction().rate_constant(tb.maxCoeff());
  std::printf("[ FK ] through ignition to t* + 0.5 a^2/alpha: cvode_bdf %ld steps, %.2f ms; max T = %.0f K, "
              "max lambda = %.3f, k(max T) = %.2e 1/s\n",
              bdf->stats().steps, 1e3 * bdf->stats().wall_seconds, tb.maxCoeff(), lb.maxCoeff(), kmax);
  EXPECT_GT(lb.maxCoeff(), 0.99);  // the core has burnt
  o.max_steps = 20000;
  auto erk = ft::make_integrator("arkode_erk", o);
  Eigen::VectorXd te = t_ref, le = lprev;
  try {
    erk->advance(p, te, le, t_star, t_end);
    ADD_FAILURE() << "arkode_erk got through ignition in " << erk->stats().steps << " steps";
  } catch (const ft::SolverError& e) {
    std::printf("[ FK ] arkode_erk: %s\n", e.what());
    EXPECT_EQ(e.flag_name(), "ARK_TOO_MUCH_WORK");
  }
}
