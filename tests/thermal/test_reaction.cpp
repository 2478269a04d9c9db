// Arrhenius reaction heat: API, guards, and the energy invariant with reactant consumption
// for every integrator (unit).
#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/reaction.hpp"
#include "grids.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace ft = frictherm::thermal;
using thermal_test::make_grid_1d;
using thermal_test::Material;

namespace {

// 1D HMX-like bar, 21 nodes over 20 µm, adiabatic; explosive on nodes 5..15 only (Q = 0 on
// the "binder" elsewhere), a 1000 K hot spot in the middle; moderate kinetics so that the
// hot spot ignites within the window and every integrator finishes quickly.
struct Bar {
  thermal_test::Grid1D g = make_grid_1d(21, 0.0, 20e-6, Material{2.09e6, 0.45});
  Eigen::VectorXd t0, heat;
  Bar() {
    t0 = Eigen::VectorXd::Constant(g.n, 300.0);
    heat = Eigen::VectorXd::Zero(g.n);
    for (int i = 5; i <= 15; ++i) heat[i] = 1900.0 * 2.09e6 * g.mass[i] / 2.09e6;  // ρq·V
    for (int i = 9; i <= 11; ++i) t0[i] = 1000.0;
  }
  ft::Reaction reaction(bool consume) const {
    ft::Reaction r;
    r.heat = heat;
    r.prefactor = 1e9;
    r.activation_temperature = 1e4;
    r.consume = consume;
    return r;
  }
};

}  // namespace

TEST(ThermalReaction, ValidationAndEvaluation) {
  Bar b;
  ft::Problem p = b.g.problem();
  const auto rev = p.revision();
  ft::Reaction r = b.reaction(true);
  r.heat[3] = -1.0;
  EXPECT_THROW(p.set_reaction(r), std::invalid_argument);
  r = b.reaction(true);
  r.prefactor = 0.0;
  EXPECT_THROW(p.set_reaction(r), std::invalid_argument);
  r = b.reaction(true);
  r.heat.resize(3);
  EXPECT_THROW(p.set_reaction(r), std::invalid_argument);
  p.set_reaction(b.reaction(true));
  EXPECT_NE(p.revision(), rev);
  EXPECT_TRUE(p.reaction_consumes());
  Eigen::VectorXd lam = Eigen::VectorXd::Constant(b.g.n, 0.25), w(b.g.n), w0(b.g.n), pw(b.g.n);
  p.reaction_power(b.t0, lam, pw);
  EXPECT_DOUBLE_EQ(pw[10], b.heat[10] * 0.75 * 1e9 * std::exp(-10.0));
  EXPECT_EQ(pw[2], 0.0);  // no explosive
  p.heat_rate(0.0, b.t0, lam, w);
  p.transport_heat_rate(0.0, b.t0, w0);
  EXPECT_LT((w - w0 - pw).cwiseAbs().maxCoeff(), 1e-12 * pw.cwiseAbs().maxCoeff());
  lam[4] = 1.5;
  EXPECT_THROW(p.check_progress(lam), std::invalid_argument);
  const auto kin = ft::hmx_kinetics_rogers1975();
  EXPECT_NEAR(kin.activation_temperature, 26520.0, 5.0);
  EXPECT_NEAR(kin.specific_heat_of_reaction, 2.092e6, 1e3);
}

TEST(ThermalReaction, ConsumingReactionNeedsTheProgress) {
  Bar b;
  ft::Problem p = b.g.problem();
  p.set_reaction(b.reaction(true));
  auto integ = ft::make_integrator("cvode_bdf");
  Eigen::VectorXd t = b.t0;
  EXPECT_THROW(integ->advance(p, t, 0.0, 1e-6), std::invalid_argument);
  p.set_reaction(b.reaction(false));  // zero-order: λ = 0 is implied
  EXPECT_NO_THROW(integ->advance(p, t, 0.0, 1e-6));
}

// Σ M_i T_i − Σ Q_i λ_i is invariant (adiabatic, no sources): linear in the state, so every
// RK / linear multistep method keeps it when its solves are exact.
TEST(ThermalReaction, EveryIntegratorConservesEnergyThroughIgnition) {
  Bar b;
  ft::Problem p = b.g.problem();
  p.set_reaction(b.reaction(true));
  const double window = 2e-5;  // ≈ 9 conduction FE limits; the hot spot burns out
  struct Case {
    std::string name, ls;
    bool exact;
  };
  const std::vector<Case> cases{{"forward_euler", "", true}, {"cvode_bdf", "klu", true},
                                {"cvode_bdf", "pcg", false},  {"cvode_adams", "", true},
                                {"arkode_erk", "", true},     {"arkode_dirk", "klu", true},
                                {"arkode_dirk", "pcg", false}};
  ft::IntegratorOptions ro;
  ro.rtol = 1e-10;
  ro.atol = 1e-8;
  ro.progress_atol = 1e-12;
  ro.max_steps = 1000000;
  auto ref = ft::make_integrator("cvode_bdf", ro);
  Eigen::VectorXd tr = b.t0, lr = Eigen::VectorXd::Zero(b.g.n);
  ref->advance(p, tr, lr, 0.0, window);
  ASSERT_GT(lr[10], 0.99) << "the hot spot should burn out";
  const double e0 = p.thermal_energy(b.t0);
  for (const auto& c : cases) {
    ft::IntegratorOptions o;
    o.linear_solver = c.ls;
    o.rtol = 1e-7;
    o.atol = 1e-4;
    o.max_steps = 1000000;
    auto integ = ft::make_integrator(c.name, o);
    Eigen::VectorXd t = b.t0, lam = Eigen::VectorXd::Zero(b.g.n);
    integ->advance(p, t, lam, 0.0, window / 2);
    integ->advance(p, t, lam, window / 2, window);
    const std::string label = c.name + (c.ls.empty() ? "" : "/" + c.ls);
    const double released = p.released_heat(lam);
    // FE (exponential reaction update): round-off. SUNDIALS: λ is clamped to [0, 1] on
    // return, which moves the books by Q·(overshoot), at the solver-tolerance level (exact
    // solves) or the Krylov tolerance (pcg/GMRES).
    const double tol = c.name == "forward_euler" ? 1e-11 * e0 : (c.exact ? 1e-6 : 1e-4) * b.heat.sum();
    EXPECT_NEAR(p.thermal_energy(t) - released, e0, tol) << label;
    // FE is first order at its stability-limited step through a ~1900 K ignition.
    EXPECT_LT((t - tr).cwiseAbs().maxCoeff(), c.name == "forward_euler" ? 100.0 : 2.0) << label;
    EXPECT_LT((lam - lr).cwiseAbs().maxCoeff(), 1e-2) << label;
    for (int i = 0; i < b.g.n; ++i) {
      if (b.heat[i] == 0.0) {
        EXPECT_EQ(lam[i], 0.0) << label << " node " << i;
      }
    }
  }
}
