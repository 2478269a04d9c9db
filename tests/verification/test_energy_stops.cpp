// The energy books' two stops (EnergyBalance::contact_normal_work, boundary_stop_work; docs/output.md
// "Energy balance"): the energy the normal contact impulses and the velocity conditions remove,
// booked as the normal analogue of the second-order frictional work (contact_pair.hpp
// normal_stop_work, energy/energy_books.hpp condition_stop_work).
//  * two elastic bars meet head-on through frictionless multimaterial contact, in uniaxial strain;
//  * an elastic bar runs into a fixed face of the grid.
#include <frictherm/mechanics/energy/energy_books.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm::mechanics;

namespace {

struct Books {
  double initial = 0.0, lost = 0.0, normal = 0.0, stop = 0.0, remainder = 0.0, kinetic = 0.0;
};

Books report(const char* what, const Simulation<2>& sim, double C, double h) {
  const EnergyBalance e = sim.energy_balance(HeatingOrder::second);
  Books b;
  b.initial = e.initial, b.lost = e.lost(), b.normal = e.contact_normal_work, b.stop = e.boundary_stop_work;
  b.remainder = e.numerical_dissipation(), b.kinetic = e.kinetic;
  std::printf("[energy stops, %s, C = %g, h = %g mm] initial %.6g J, lost %.6g J, contact_normal_work %.6g J, "
              "boundary_stop_work %.6g J, numerical_dissipation %.4g J (%.2f %% of the lost)\n",
              what, C, 1e3 * h, b.initial, b.lost, b.normal, b.stop, b.remainder, 100 * b.remainder / b.lost);
  return b;
}

// Two bars of 100 mm (ρ 1000, E 1e8, ν 0) at ±V along x between faces that hold v_y = 0, meeting at
// x = 0.12 m; run for time t_end.
Books bars(double C, double h, UpdateScheme scheme, double t_fraction) {
  SimulationOptions o;
  o.cfl = C;
  o.scheme = scheme;
  const double V = 2.0, L = 0.1;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(h, h), IVec<2>{static_cast<int>(std::lround(0.24 / h)), 4}), o);
  Material m;
  m.density = 1000, m.youngs_modulus = 1e8, m.poisson_ratio = 0.0;
  m.name = "a";
  const int a = sim.add_material(m);
  m.name = "b";
  const int b = sim.add_material(m);
  sim.add_body("a", *make_box<2>(Vec<2>(0.12 - L, 0), Vec<2>(0.12, 4 * h), a), 2, Vec<2>(V, 0));
  sim.add_body("b", *make_box<2>(Vec<2>(0.12, 0), Vec<2>(0.12 + L, 4 * h), b), 2, Vec<2>(-V, 0));
  sim.fix_face(FixedFace{1, false, {{false, true, false}}});
  sim.fix_face(FixedFace{1, true, {{false, true, false}}});
  ContactOptions co;
  co.default_pair.law = FrictionLaw::frictionless();
  sim.enable_contact(co);
  const double c = m.p_wave_speed(Analysis::plane_strain);
  const double t_end = t_fraction * L / c;
  while (sim.time() < t_end * (1 - 1e-12)) sim.step(t_end - sim.time());
  return report(scheme == UpdateScheme::usl ? "bars usl" : "bars musl", sim, C, h);
}

// One bar of 100 mm at V toward a wall 1 mm away: the grid's right face holding v_x = 0 (fixed) or a
// rigid block at rest (a velocity condition on the nodes its particles touch, the PBX's walls).
Books wall(double C, double h, UpdateScheme scheme, double t_fraction, bool rigid) {
  SimulationOptions o;
  o.cfl = C;
  o.scheme = scheme;
  const double V = 2.0, L = 0.1, x_wall = 0.12;
  const int cells = static_cast<int>(std::lround((x_wall + (rigid ? 0.01 : 0.0)) / h));
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(h, h), IVec<2>{cells, 4}), o);
  Material m;
  m.density = 1000, m.youngs_modulus = 1e8, m.poisson_ratio = 0.0;
  m.name = "bar";
  const int a = sim.add_material(m);
  sim.add_body("bar", *make_box<2>(Vec<2>(x_wall - L - 0.001, 0), Vec<2>(x_wall - 0.001, 4 * h), a), 2, Vec<2>(V, 0));
  if (rigid) {
    Material w;
    w.name = "wall", w.kind = MaterialKind::rigid, w.density = 1000.0;
    w.rigid_velocity = {TimeFunction::constant(0.0), TimeFunction::constant(0.0)};
    const int mw = sim.add_material(w);
    sim.add_body("wall", *make_box<2>(Vec<2>(x_wall, 0), Vec<2>(x_wall + 0.006, 4 * h), mw), 2, Vec<2>::Zero());
  } else {
    sim.fix_face(FixedFace{0, true, {{true, false, false}}});
  }
  sim.fix_face(FixedFace{1, false, {{false, true, false}}});
  sim.fix_face(FixedFace{1, true, {{false, true, false}}});
  const double c = m.p_wave_speed(Analysis::plane_strain);
  const double t_end = t_fraction * L / c;
  while (sim.time() < t_end * (1 - 1e-12)) sim.step(t_end - sim.time());
  return report(rigid ? (scheme == UpdateScheme::usl ? "rigid wall usl" : "rigid wall musl")
                      : (scheme == UpdateScheme::usl ? "fixed face usl" : "fixed face musl"),
                sim, C, h);
}

}  // namespace

// The stop kernel itself: a node arriving at a wall without force gives up ½ m u²; one resting on it
// under any force gives up nothing; a driven wall's frame is the wall's.
TEST(EnergyStops, ConditionStopWorkIsTheInelasticStopOfTheStartVelocity) {
  const double m = 2e-3, u = 3.0, dt = 1e-7;
  EXPECT_DOUBLE_EQ(condition_stop_work(m, m * u, 0.0, 0.0, dt, m * u), 0.5 * m * u * u);
  EXPECT_EQ(condition_stop_work(m, 0.0, 5e4, 0.0, dt, 0.0), 0.0);             // resting, pressed by 50 kN
  EXPECT_DOUBLE_EQ(condition_stop_work(m, m * (1.0 + u), 0.0, 1.0, dt, m * (1.0 + u)), 0.5 * m * u * u);
  double force = 0.0, stop = 0.0;
  const double work = drive_component(m, m * u, force, 0.0, dt, m * u, stop);  // a fixed rigid wall
  EXPECT_EQ(work, 0.0);  // a wall at rest does no work (rigid_work)
  EXPECT_DOUBLE_EQ(stop, 0.5 * m * u * u);
  EXPECT_DOUBLE_EQ(force, -m * u / dt);  // the stop the particles receive
}

// Frictionless head-on impact of two elastic bars (USL, FLIP), 2.5 transit times 2L/c after the
// start (they have separated). The contact's extrapolated pass stops the approach before the
// momentum update, so the normal impulse the particles receive is mostly the force increment's, and
// the term books what is left of the approach at the start of the momentum update. Measured (h = 2 mm;
// C = 0.5 / 0.25 / 0.1): energy lost 0.1870 / 0.1848 / 0.1829 J of 3.2 J, contact_normal_work
// 0.01842 / 0.01926 / 0.02153 J; at h = 1 mm (C = 0.5, 1.6 J) lost 0.0499 J, contact_normal_work
// 0.00460 J. So the term is 10–12 % of the loss, does not fall with C (+17 % from 0.5 to 0.1), and
// falls with the cell as the loss does (×0.25 and ×0.27 from 2 to 1 mm): it does not close the
// balance (the remainder is 88–91 % of the loss; docs/output.md "Energy balance").
TEST(EnergyStops, FrictionlessBarsImpactBooksTheNormalStop) {
  const Books coarse = bars(0.5, 0.002, UpdateScheme::usl, 2.5);
  const Books small_step = bars(0.1, 0.002, UpdateScheme::usl, 2.5);
  const Books fine = bars(0.5, 0.001, UpdateScheme::usl, 2.5);
  for (const Books& b : {coarse, small_step, fine}) {
    EXPECT_GT(b.normal, 0.0);                 // the normal stop removes energy
    EXPECT_LT(b.normal, 0.5 * b.lost);        // and never more than the bodies lost (measured 9–12 %)
    EXPECT_EQ(b.stop, 0.0);                   // the faces holding v_y = 0 are fixed faces: no stop booked
    EXPECT_NEAR(b.remainder, b.lost - b.normal, 1e-12 * b.initial);  // numerical_dissipation is what is left
  }
  // Independent of the time step within 25 % (measured +17 % from C = 0.5 to 0.1), and falling with
  // the cell (measured ratio 0.25; a term first order in h would give 0.5).
  EXPECT_NEAR(small_step.normal, coarse.normal, 0.25 * coarse.normal);
  EXPECT_LT(fine.normal / coarse.normal, 0.35);
}

// A bar run at 2 m/s into a rigid wall at rest (a velocity condition on the nodes its particles
// touch, as the PBX's walls): the wall does no work, and the stop's booking is most of what the bar
// loses. Measured after 2.5 transits L/c, the bar still against the wall (MUSL): h = 2 mm, C = 0.5
// lost 0.0410 J of 1.6 J, boundary_stop_work 0.0260 J (63 %); C = 0.1 0.0427 / 0.0316 J (74 %);
// h = 1 mm (0.8 J), C = 0.5: 0.00651 / 0.00165 J (25 %). The loss is the same at both C within 4 %
// since the books take the stored energy's half-step lead off (energy_books.hpp, stored_lead; a
// compression wave converts the kinetic energy at P = F V ≈ 10 kW here, ½ dt P ≈ 9 mJ at C = 0.5):
// before, the stored energy booked half a step ahead made the loss 0.0321 J at C = 0.5 and 0.0395 J
// at C = 0.1 (19 % apart), and jump by ±0.01 J whenever a wave front reached an end of the bar.
// The same bar into a fixed face of the grid loses 0.6 % of its energy (USL; MUSL 0.1 %) and books no
// stop: the face zeroes its nodes' force, so the particles never receive a stop there.
TEST(EnergyStops, RigidWallBooksTheStopAndFixedFaceKeepsTheEnergy) {
  double lost[2] = {};
  for (int i = 0; i < 2; ++i) {
    const double C = i == 0 ? 0.5 : 0.1;
    const Books b = wall(C, 0.002, UpdateScheme::musl, 2.5, true);
    EXPECT_GT(b.stop, 0.55 * b.lost) << C;
    EXPECT_LT(b.stop, b.lost) << C;
    EXPECT_LT(std::fabs(b.remainder), 0.45 * b.lost) << C;
    lost[i] = b.lost;
  }
  EXPECT_NEAR(lost[0], lost[1], 0.08 * lost[1]);  // the books' loss, not the step's: measured 4 %
  const Books fine = wall(0.5, 0.001, UpdateScheme::musl, 2.5, true);
  EXPECT_GT(fine.stop, 0.0);
  EXPECT_LT(fine.stop, fine.lost);
  for (UpdateScheme s : {UpdateScheme::usl, UpdateScheme::musl}) {
    const Books face = wall(0.5, 0.002, s, 1.0, false);
    EXPECT_EQ(face.stop, 0.0);
    EXPECT_LT(std::fabs(face.lost), 0.01 * face.initial);  // measured 0.58 % (USL), −0.14 % (MUSL)
  }
}
