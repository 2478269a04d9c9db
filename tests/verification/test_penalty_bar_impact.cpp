// Longitudinal impact of two identical elastic bars (Kakouris, Chatzis & Triantafyllou 2024 §4.2 with
// equal lengths; digest §6.2), as 2D strips (ν = 0, plane stress). The left bar hits the right one,
// at rest, with v0. 1D wave theory (d'Alembert): the interface moves at v0/2 and a compressive wave
// σ = −ρ c v0/2 runs into both bars; it reflects as a release from the free far ends, and when both
// releases reach the interface at t = 2L/c the contact force drops to zero: the left bar stops, the
// right one leaves with v0 (velocities swapped). While in contact the right bar's momentum grows
// linearly, P_r(t) = σ A t, so its rate is the contact force.
//
// The same scene runs with penalty contact (EBS and the plain quadratic B-spline, OBS) and with
// multimaterial contact (Nairn 2018): contact force plateau, separation time, final velocities,
// total momentum and total energy (kinetic + strain + penalty springs).
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

using namespace frictherm::mechanics;

namespace {

constexpr double kL = 0.5, kH = 0.005, kE = 1e8, kRho = 1000.0, kV0 = 1.0;
const double kC = std::sqrt(kE / kRho);
constexpr double kWidth = 4 * kH;  // strip height (m); thickness 1 m, so A = kWidth m²

struct ImpactResult {
  double plateau = 0.0;        // mean contact force over 0.2–1.8 L/c over σ_exact A
  double stress_left = 0.0, stress_right = 0.0;  // mean σ_xx 0.1–0.4 L from the interface at 0.6 L/c, over σ_exact
  double separation = 0.0;     // last time the contact force exceeds 5 % of σ A, over 2L/c
  double v_left = 0.0, v_right = 0.0;  // mean velocities at the end, over v0
  double momentum = 0.0;       // max |P − P0| / (M v0)
  double energy = 0.0;         // max |E − E0| / E0 over the run
  double energy_end = 0.0;     // (E − E0) / E0 at the end
};

ImpactResult impact(ContactMethod method, ShapeKind shape) {
  SimulationOptions o;
  o.analysis = Analysis::plane_stress;
  o.shape = shape;
  o.scheme = UpdateScheme::musl;
  o.cfl = 0.4;
  const int cells_x = static_cast<int>(std::lround(2 * kL / kH)) + 8;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(kH, kH), IVec<2>{cells_x, 8}), o);
  Material m;
  m.density = kRho;
  m.youngs_modulus = kE;
  m.poisson_ratio = 0.0;
  m.name = "left";
  const int left = sim.add_material(m);
  m.name = "right";
  const int right = sim.add_material(m);
  ContactOptions co;
  co.default_pair.law = FrictionLaw::frictionless();
  co.default_pair.method = method;
  co.default_pair.normal = NormalMethod::specified;
  co.default_pair.normal_vector = Vec<3>(1, 0, 0);
  // Multimaterial: the displacement form of the separation (eqs. 9–10), natural for bodies that touch
  // at the start. The position form's 0.8 h correction (eq. 8) is sized for linear/uGIMP extents;
  // with the quadratic B-spline it reports separation early here (measured: force plateau 0.83,
  // striker left at 0.19 v0).
  co.separation = SeparationMethod::displacement;
  sim.enable_contact(co);
  ContactPairSettings pair = co.default_pair;
  pair.penalty.master = left;
  sim.set_contact_pair(left, right, pair);
  const double x0 = 2 * kH, xc = x0 + kL;  // the bars touch at xc
  sim.add_body("left", *make_box<2>(Vec<2>(x0, 2 * kH), Vec<2>(xc, 6 * kH), left), 2, Vec<2>(kV0, 0));
  sim.add_body("right", *make_box<2>(Vec<2>(xc, 2 * kH), Vec<2>(xc + kL, 6 * kH), right), 2, Vec<2>::Zero());
  sim.finalize();

  const auto& p = sim.particles();
  double M = 0.0, Mr = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    M += p.mass[k];
    if (p.material[k] == right) Mr += p.mass[k];
  }
  auto momentum = [&](int mat) {
    double P = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.material[k] == mat) P += p.mass[k] * p.velocity[k][0];
    return P;
  };
  auto energy = [&] {
    const PenaltyContact<2>* pc = sim.penalty_contact();
    return sim.kinetic_energy() + sim.strain_energy() + (pc ? pc->stored_energy() : 0.0);
  };
  const double s_exact = kRho * kC * kV0 / 2.0, F_exact = s_exact * kWidth;
  const double P0 = momentum(left) + momentum(right), E0 = energy();
  const double t_transit = kL / kC, t_end = 2.6 * t_transit;
  ImpactResult r;
  double force_sum = 0.0, force_time = 0.0;
  bool sampled = false;
  while (sim.time() < t_end) {
    const double Pr = momentum(right);
    const double target = sim.time() < 0.6 * t_transit ? 0.6 * t_transit : t_end;
    const double dt = sim.step(target - sim.time());
    const double F = (momentum(right) - Pr) / dt;  // the only force on the right bar
    const double tm = sim.time() - 0.5 * dt;
    if (tm > 0.2 * t_transit && tm < 1.8 * t_transit) force_sum += F * dt, force_time += dt;
    if (F > 0.05 * F_exact) r.separation = sim.time() / (2 * t_transit);
    r.momentum = std::max(r.momentum, std::fabs(momentum(left) + momentum(right) - P0) / (M * kV0));
    r.energy = std::max(r.energy, std::fabs(energy() - E0) / E0);
    if (!sampled && sim.time() >= 0.6 * t_transit * (1 - 1e-12)) {
      sampled = true;
      double sl = 0.0, sr = 0.0;
      int nl = 0, nr = 0;
      for (std::size_t k = 0; k < p.size(); ++k) {
        const double d = p.initial_position[k][0] - xc;
        if (d < -0.1 * kL && d > -0.4 * kL) sl += p.stress[k](0, 0), ++nl;
        if (d > 0.1 * kL && d < 0.4 * kL) sr += p.stress[k](0, 0), ++nr;
      }
      r.stress_left = -sl / nl / s_exact;
      r.stress_right = -sr / nr / s_exact;
    }
  }
  r.plateau = force_sum / force_time / F_exact;
  r.v_left = momentum(left) / (M - Mr) / kV0;
  r.v_right = momentum(right) / Mr / kV0;
  r.energy_end = (energy() - E0) / E0;
  std::printf("[bar impact %s %s] contact force plateau %.4f, stress plateau left %.4f right %.4f (of rho c v0/2); "
              "separation at %.4f x 2L/c; final v left %.4f right %.4f (of v0); max |dP|/(M v0) %.1e; "
              "energy max drift %.4f, at end %+.4f\n",
              to_string(method), to_string(shape), r.plateau, r.stress_left, r.stress_right, r.separation, r.v_left,
              r.v_right, r.momentum, r.energy, r.energy_end);
  return r;
}

}  // namespace

// Bounds (measured in brackets: penalty EBS / penalty OBS / multimaterial OBS):
//  * contact force plateau within 3 % of ρ c v0/2 A (1.000 / 1.000 / 1.000), the particles' stress
//    plateau at 0.6 L/c within 3 % (1.001 / 0.998 / 0.999): the digest's 5 % for the paper's case,
//    tightened since a 100-cell bar leaves the plateau flat to a few 0.1 %;
//  * separation within 3 % of 2L/c (1.018 / 1.026 / 1.012): the release fronts are smeared over a few
//    cells, h/L = 1 %;
//  * final velocities within 0.02 v0 of the swap (0.009 / 0.007 / 0.012 left behind);
//  * total momentum to round-off: the penalty point forces cancel exactly and so do their nodal
//    images; bound steps × particles × 1.1e-16 ≈ 3e-10 (measured 1.7e-14 / 3e-12 / 1.7e-14);
//  * total energy, kinetic + strain + penalty springs, within 2 % at every step (0.4 % / 0.9 % /
//    0.2 %): MUSL with FLIP is not exactly conservative, and the penalty springs ring after contact.
TEST(PenaltyBarImpact, MatchesWaveSolutionForBothContactMethods) {
  struct Case {
    ContactMethod method;
    ShapeKind shape;
  };
  for (const Case c : {Case{ContactMethod::penalty, ShapeKind::extended_bspline},
                       Case{ContactMethod::penalty, ShapeKind::quadratic_bspline},
                       Case{ContactMethod::multimaterial, ShapeKind::quadratic_bspline}}) {
    const ImpactResult r = impact(c.method, c.shape);
    const std::string what = std::string(to_string(c.method)) + " " + to_string(c.shape);
    EXPECT_NEAR(r.plateau, 1.0, 0.03) << what;
    EXPECT_NEAR(r.stress_left, 1.0, 0.03) << what;
    EXPECT_NEAR(r.stress_right, 1.0, 0.03) << what;
    EXPECT_NEAR(r.separation, 1.0, 0.03) << what;
    EXPECT_LT(std::fabs(r.v_left), 0.02) << what;
    EXPECT_NEAR(r.v_right, 1.0, 0.02) << what;
    EXPECT_LT(r.momentum, 3e-10) << what;
    EXPECT_LT(r.energy, 0.02) << what;
  }
}
