// Σ_i M_i T_i changes exactly by the heat added (thermal-notes §4 invariant) (unit).
// With adiabatic edges K has zero row and column sums, so 1ᵀM f = Σ(q + f): every RK and
// linear multistep method carries this linear invariant exactly when its solves are exact
// (FE, ERK, Adams fixed point, Newton with KLU); Krylov solves leave a drift at the level of
// the linear-solver tolerance.
#include "frictherm/thermal/integrator.hpp"
#include "grids.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace ft = frictherm::thermal;
using thermal_test::make_grid_2d;
using thermal_test::Material;

namespace {

struct Case {
  std::string name, linear_solver;
  bool exact;  // round-off: |ΔE − Q| ≤ 1e-12·E0; else tolerance level: ≤ 1e-4·Q
};

// Round-off bound: E0 = Σ M T ≈ 300 K·ΣM carries ε ≈ 1e-16 per operation over ≲ 1e3
// accumulated steps/iterations, so 1e-12·E0 (Q itself is only ~1e-6·E0 here).
double allowed(bool exact, double e0, double q) { return exact ? 1e-12 * std::abs(e0) : 1e-4 * std::abs(q); }

struct Field2D {
  thermal_test::Grid2D g = make_grid_2d(16, 16, 0.0, 0.0, 1e-6, Material{2.09e6, 0.45});
  Eigen::VectorXd t0;
  Field2D() {
    t0.resize(g.size());
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) t0[g.id(i, j)] = 300.0 + 40.0 * std::sin(1.3 * i) * std::cos(0.7 * j);
  }
};

}  // namespace

TEST(ThermalConservation, EnergyChangesByTheHeatAdded) {
  Field2D s;
  ft::Problem p = s.g.problem();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(s.g.size());
  q[s.g.id(5, 7)] = 2e-3;    // W per m depth: a hot spot
  q[s.g.id(10, 3)] = -5e-4;  // and a sink
  p.set_source(q);
  for (int j = 0; j < s.g.ny; ++j) p.add_flux(s.g.id(0, j), 1e-4);  // flux through the left edge
  const double power = q.sum() + 1e-4 * s.g.ny;
  const double window = 2e-5;  // ≈ 8 FE stability limits (h²/4α = 2.3e-6 s)
  // PCG: the Newton correction's CG residual (CVODE epslin 0.05 × the local error test)
  // may drift by tolerance level, bounded by 1e-4·Q at rtol 1e-5 (observed here: round-off,
  // since M^{1/2}1 is an eigenvector of I − γJ with eigenvalue 1 for adiabatic K).
  const std::vector<Case> cases{{"forward_euler", "", true}, {"cvode_bdf", "klu", true},
                                {"arkode_dirk", "klu", true}, {"cvode_adams", "", true},
                                {"arkode_erk", "", true},     {"cvode_bdf", "pcg", false},
                                {"arkode_dirk", "pcg", false}};
  for (const auto& c : cases) {
    ft::IntegratorOptions o;
    o.linear_solver = c.linear_solver;
    o.rtol = 1e-5;
    o.atol = 1e-5;
    auto integ = ft::make_integrator(c.name, o);
    Eigen::VectorXd t = s.t0;
    const double e0 = p.thermal_energy(t);
    for (int w = 0; w < 3; ++w) integ->advance(p, t, w * window, (w + 1) * window);
    const double added = power * 3 * window;
    RecordProperty("dE_minus_Q_over_E0_" + c.name + c.linear_solver, thermal_test::sci((p.thermal_energy(t) - e0 - added) / e0));
    RecordProperty("dE_minus_Q_over_Q_" + c.name + c.linear_solver, thermal_test::sci((p.thermal_energy(t) - e0 - added) / added));
    EXPECT_NEAR(p.thermal_energy(t) - e0, added, allowed(c.exact, e0, added)) << c.name << "/" << c.linear_solver;
  }
}

// A source ramped linearly over the window: FE samples q at sub-step midpoints (exact for a
// linear q), so FE closes to round-off; BDF integrates the quadratic E(t) exactly from
// order 2 on, but its first order-1 steps do not, so cvode_bdf/klu closes to tolerance level.
TEST(ThermalConservation, LinearRampDeliversTheWindowEnergy) {
  Field2D s;
  ft::Problem p = s.g.problem();
  const double window = 2e-5;
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(s.g.size()), q1 = q0;
  q0[s.g.id(8, 8)] = 1e-3;
  q1[s.g.id(8, 8)] = 5e-3;
  q1[s.g.id(2, 12)] = 2e-3;
  p.set_source_ramp(q0, q1, 0.0, window);
  const double added = 0.5 * (q0.sum() + q1.sum()) * window;  // ∫ Σ q dt
  for (const auto& [name, exact] : {std::pair<std::string, bool>{"forward_euler", true}, {"cvode_bdf", false}}) {
    ft::IntegratorOptions o;
    o.rtol = 1e-8;
    o.atol = 1e-8;
    auto integ = ft::make_integrator(name, o);
    Eigen::VectorXd t = s.t0;
    const double e0 = p.thermal_energy(t);
    integ->advance(p, t, 0.0, window);
    RecordProperty("dE_minus_Q_over_E0_" + name, thermal_test::sci((p.thermal_energy(t) - e0 - added) / e0));
    RecordProperty("dE_minus_Q_over_Q_" + name, thermal_test::sci((p.thermal_energy(t) - e0 - added) / added));
    EXPECT_NEAR(p.thermal_energy(t) - e0, added, allowed(exact, e0, added)) << name;
  }
}

// Convection to an ambient: the energy change equals ∫ Σ hA (T_inf − T) dt; at steady state
// with no source the field relaxes to T_inf everywhere.
TEST(ThermalConservation, ConvectionRelaxesToAmbient) {
  Field2D s;
  ft::Problem p = s.g.problem();
  for (int i = 0; i < s.g.nx; ++i) p.add_convection(s.g.id(i, s.g.ny - 1), 1e5 * s.g.h, 250.0);  // h = 1e5 W/(m²K)
  auto integ = ft::make_integrator("cvode_bdf");
  Eigen::VectorXd t = s.t0;
  integ->advance(p, t, 0.0, 1.0);  // ≫ ρcL²/k ≈ 1e-3 s and ρcL/h ≈ 3e-4 s
  EXPECT_LT((t.array() - 250.0).abs().maxCoeff(), 1e-4);
}
