// Adhesion with tensile strength (Nairn, Bardenhagen & Smith 2018, §2.9): surfaces detected as
// separated still stick while the elliptical criterion (S_stick/S_a)² + (N/N_a)² ≤ 1 holds (eq. 25),
// and move freely once it is exceeded.
//
// A 40 × 15 mm elastic block bonded to a rigid base at rest (interface on a grid line, 2.5 mm cells)
// is pulled off by a tension spread equally over its particles and ramped slowly (the ramp lasts 65
// wave transits of the block, so the response is quasi-static); the pull on every particle is
// carried to the base by the interface, whose traction is then nearly uniform: N(t) = F(t)/(l b).
// Optionally a shear load, spread over the bottom particle row only (so it makes no overturning
// moment that would tilt the normal traction), ramps with it: S(t) = r N(t).
// Criterion: release when N = 1/√(r²/S_a² + 1/N_a²).
#include "test_materials.hpp"

#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

using namespace frictherm::mechanics;

namespace {

constexpr double kL = 0.040, kH = 0.015, kB = 0.001, kCell = 0.0025, kRamp = 1e-3;
constexpr double kY0 = 0.010;  // the interface, on a grid line

struct PullOff {
  double release = -1.0;      // first time the block's mean upward velocity exceeds 0.1 m/s (s)
  double max_opening = 0.0;   // max mean displacement of the bottom particle row before 0.95 release (m)
  double final_velocity = 0.0;
  double mass = 0.0;          // of the block (kg)
};

/// Tension ramped to N_max over kRamp (N(t) = N_max t/kRamp), shear ramped to r N_max.
PullOff pull(const FrictionLaw& law, double N_max, double r) {
  SimulationOptions o;
  o.thickness = kB;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(kCell, kCell), IVec<2>{32, 20}), o);
  const Material base_m = frictherm::verification::rigid_at_rest("base");
  // ν = 0: with ν = 0.33 the bonded block's lateral contraction concentrates the traction at the
  // interface's ends (we measured 13.5 % above the mean at the end nodes, 2.5 % below it inside) and
  // the interface peels from its ends at N = 0.83 N_a: a real effect, but not the criterion's.
  const Material block_m = frictherm::verification::elastic_material("block", 1000.0, 2500e6, 0.0);
  const int base = sim.add_material(base_m), block = sim.add_material(block_m);
  const double x0 = 0.0125;
  sim.add_body("base", *make_box<2>(Vec<2>(0.005, 0.0), Vec<2>(0.075, kY0), base), 2, Vec<2>::Zero());
  const int blk = sim.add_body("block", *make_box<2>(Vec<2>(x0, kY0), Vec<2>(x0 + kL, kY0 + kH), block), 2,
                               Vec<2>::Zero());
  const double F = N_max * kL * kB;
  PointLoad<2> tension;
  tension.body = blk, tension.use_box = true, tension.box_lo = sim.grid().lo(), tension.box_hi = sim.grid().hi();
  tension.force = Vec<2>(0.0, F), tension.scale = TimeFunction::ramp(1.0, kRamp);
  sim.add_point_load(tension);
  const double row = kY0 + 0.5 * kCell / 2;  // centres of the bottom particle row (2 per cell)
  if (r > 0.0) {
    PointLoad<2> shear = tension;
    shear.box_lo = Vec<2>(0.0, row - 1e-6), shear.box_hi = Vec<2>(0.1, row + 1e-6);
    shear.force = Vec<2>(r * F, 0.0);
    sim.add_point_load(shear);
  }
  ContactOptions co;
  // Eq. 11's area: this test checks the criterion of eq. 25 on a traction that is nearly uniform. With
  // the surface area (the default, exact at the block's end nodes) the shear cases release early
  // (S = N: −12 %, S = N/2: −3.9 %, pure tension unchanged): the end nodes then show the real
  // concentration of normal traction that the shear load's unbalanced σ_xy makes at the block's free
  // corners, which eq. 11's larger end-node area (√(3/8) h b instead of h b / 2) hid.
  co.area = ContactAreaMethod::domain;
  co.default_pair.law = law;
  co.default_pair.normal = NormalMethod::specified;
  co.default_pair.normal_vector = Vec<3>(0.0, 1.0, 0.0);  // from the base to the block
  sim.enable_contact(co);
  sim.set_contact_pair(base, block, co.default_pair);
  const auto& p = sim.particles();
  PullOff out;
  sim.finalize();
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == block) out.mass += p.mass[k];
  std::vector<double> ts, opening;
  while (sim.time() < kRamp) {
    sim.step(kRamp - sim.time());
    double mv = 0.0, m = 0.0, dy = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (p.material[k] != block) continue;
      mv += p.mass[k] * p.velocity[k][1], m += p.mass[k];
      if (std::fabs(p.initial_position[k][1] - row) < 1e-6) dy += p.position[k][1] - p.initial_position[k][1], ++n;
    }
    ts.push_back(sim.time()), opening.push_back(dy / n);
    out.final_velocity = mv / m;
    if (out.release < 0.0 && mv / m > 0.1) out.release = sim.time();
    if (mv / m > 1.0) break;  // released and flying off: stop before the block leaves the grid
  }
  const double until = out.release < 0.0 ? kRamp : 0.95 * out.release;
  for (std::size_t k = 0; k < ts.size() && ts[k] < until; ++k) out.max_opening = std::max(out.max_opening, opening[k]);
  return out;
}

void check(double S_a, double N_a, double r, double tolerance, const char* name) {
  const double N_max = 2.0e6;  // N(t) = N_max t / kRamp
  const double expected = 1.0 / std::sqrt(r * r / (S_a * S_a) + 1.0 / (N_a * N_a));
  const PullOff o = pull(FrictionLaw::adhesion(0.2, S_a, N_a), N_max, r);
  const double N_release = N_max * o.release / kRamp;
  std::printf("[adhesion pull-off %s] released at N = %.4g MPa (S = %.4g MPa) vs criterion %.4g MPa: error %.2f %%; "
              "opening before release %.2e m (%.1e cells)\n",
              name, 1e-6 * N_release, 1e-6 * r * N_release, 1e-6 * expected, 100.0 * (N_release / expected - 1.0),
              o.max_opening, o.max_opening / kCell);
  ASSERT_GT(o.release, 0.0) << name << ": never released";
  EXPECT_NEAR(N_release, expected, tolerance * expected) << name;
  // Stuck: the bottom row stays on the base. Its particles sit a quarter cell above the held
  // interface nodes and move only with the block's elastic stretch: N h/E ~ 1e-6 m at most.
  EXPECT_LT(o.max_opening, 1e-3 * kCell) << name;
}

}  // namespace

TEST(AdhesionTensileStrength, PureTensionReleasesAtNa) {
  // N_a = 1 MPa, S_a = 1 MPa: release at N = N_a. Tolerance 3 %: the 0.1 m/s release mark comes
  // ~2 µs (0.4 % of the load) after the release, the ramped load lags its quasi-static value a
  // little, and the end nodes carry half the load on an eq.-11 area √(3/8) h b instead of h b / 2
  // (they release last). We measured 1.2 %.
  check(1.0e6, 1.0e6, 0.0, 0.03, "pure tension");
}

TEST(AdhesionTensileStrength, ShearAndTensionFollowTheEllipse) {
  // S = N with S_a = N_a = 1 MPa: release at N = S = 1/√2 MPa; S = 0.5 N with S_a = 0.5 MPa,
  // N_a = 1 MPa: release at N = 1/√2 MPa as well, but reached through the shear term.
  // Same 3 % as pure tension (measured 0.3 % and 1.3 %).
  check(1.0e6, 1.0e6, 1.0, 0.03, "S = N");
  check(0.5e6, 1.0e6, 0.5, 0.03, "S = N/2, S_a = N_a/2");
}

TEST(AdhesionTensileStrength, NoTensileStrengthDoesNotHold) {
  // Without N_a the adhesion law acts only in contact: the pulled block flies off from the start,
  // v(t) = F_max t² / (2 m t_ramp), and reaches 0.1 m/s at t = √(0.2 m t_ramp / F_max).
  const double N_max = 2.0e6, F_max = N_max * kL * kB;
  const PullOff o = pull(FrictionLaw::adhesion(0.2, 1.0e6), N_max, 0.0);
  const double expected = std::sqrt(0.2 * o.mass * kRamp / F_max);
  std::printf("[adhesion pull-off, no N_a] 0.1 m/s reached at %.4f ms vs free flight %.4f ms (N = %.3g MPa then)\n",
              1e3 * o.release, 1e3 * expected, 1e-6 * N_max * o.release / kRamp);
  ASSERT_GT(o.release, 0.0);
  // 5 %: the step (0.5 µs) is 1.3 % of the time, and the block's elastic response to the ramp adds
  // a little more.
  EXPECT_NEAR(o.release, expected, 0.05 * expected);
}
