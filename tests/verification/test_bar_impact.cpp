// Two identical elastic bars meeting head-on at ±v0 in one velocity field. 1D wave theory: the
// interface stops, and a compressive wave of stress σ = −ρ c v0 runs into each bar at c = √(E/ρ)
// (ν = 0, plane stress). Momentum (zero in total) stays zero.
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm::mechanics;

namespace {

struct ImpactResult {
  double plateau_left = 0.0, plateau_right = 0.0;  // mean σ_xx behind the wave fronts
  double max_momentum = 0.0;                      // max |P| / (M v0)
};

ImpactResult impact(ShapeKind shape, UpdateScheme scheme) {
  const double L = 0.5, h = 0.01, E = 1e8, rho = 1000.0, v0 = 1.0;
  SimulationOptions o;
  o.analysis = Analysis::plane_stress;
  o.shape = shape;
  o.scheme = scheme;
  o.cfl = 0.4;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(h, h), IVec<2>{110, 6}), o);
  Material m;
  m.name = "bar";
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = 0.0;
  const int mat = sim.add_material(m);
  const double x0 = 0.05, xc = x0 + L;  // the bars touch at xc
  sim.add_body("left", *make_box<2>(Vec<2>(x0, 2 * h), Vec<2>(xc, 4 * h), mat), 2, Vec<2>(v0, 0));
  sim.add_body("right", *make_box<2>(Vec<2>(xc, 2 * h), Vec<2>(xc + L, 4 * h), mat), 2, Vec<2>(-v0, 0));
  const double c = std::sqrt(E / rho);
  double M = 0.0;
  for (double mp : sim.particles().mass) M += mp;
  ImpactResult r;
  const double t_end = 0.6 * L / c;  // waves have run 0.6 L; no reflection has come back yet
  while (sim.time() < t_end) {
    sim.step(t_end - sim.time());
    r.max_momentum = std::max(r.max_momentum, sim.linear_momentum().norm() / (M * v0));
  }
  // Mean σ_xx between 0.1 L and 0.4 L from the interface, away from the front and from the
  // single-field interface cell.
  const auto& p = sim.particles();
  double sl = 0.0, sr = 0.0;
  int nl = 0, nr = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double d = p.initial_position[k][0] - xc;
    if (d < -0.1 * L && d > -0.4 * L) sl += p.stress[k](0, 0), ++nl;
    if (d > 0.1 * L && d < 0.4 * L) sr += p.stress[k](0, 0), ++nr;
  }
  r.plateau_left = sl / nl;
  r.plateau_right = sr / nr;
  const double s_exact = -rho * c * v0;
  std::printf("[bar impact %s %s] plateau left %.5g Pa, right %.5g Pa, exact %.5g Pa (errors %.2f %%, %.2f %%); "
              "max |P|/(M v0) = %.1e\n",
              to_string(shape), to_string(scheme), r.plateau_left, r.plateau_right, s_exact,
              100 * (r.plateau_left / s_exact - 1), 100 * (r.plateau_right / s_exact - 1), r.max_momentum);
  return r;
}

}  // namespace

// Tolerance 5 % (the issue's): the plateau is flat in 1D theory; MPM adds oscillations behind the
// front (Gibbs-like, decaying over a few cells), which averaging over 0.3 L = 15 cells removes to
// well under that. Momentum starts at exactly zero by symmetry and must stay at round-off.
TEST(BarImpact, StressPlateauMatchesRhoCV) {
  for (ShapeKind s : {ShapeKind::ugimp, ShapeKind::quadratic_bspline, ShapeKind::linear}) {
    const ImpactResult r = impact(s, UpdateScheme::musl);
    const double s_exact = -1000.0 * std::sqrt(1e8 / 1000.0) * 1.0;
    EXPECT_NEAR(r.plateau_left, s_exact, 0.05 * std::abs(s_exact)) << to_string(s);
    EXPECT_NEAR(r.plateau_right, s_exact, 0.05 * std::abs(s_exact)) << to_string(s);
    EXPECT_LT(r.max_momentum, 1e-12) << to_string(s);
  }
}

TEST(BarImpact, StressPlateauUsfAndUsl) {
  for (UpdateScheme u : {UpdateScheme::usf, UpdateScheme::usl}) {
    const ImpactResult r = impact(ShapeKind::ugimp, u);
    const double s_exact = -1000.0 * std::sqrt(1e8 / 1000.0);
    EXPECT_NEAR(r.plateau_left, s_exact, 0.05 * std::abs(s_exact)) << to_string(u);
    EXPECT_LT(r.max_momentum, 1e-12) << to_string(u);
  }
}
