// Rigid materials as velocity boundary conditions (Material::rigid_boundary, rigid_controls): a rigid
// plate overlapping the left part of a block prescribes only the x velocity of the nodes it touches,
// under gravity in −y. The block must follow the plate in x and fall freely in y (the y direction is
// not prescribed), with and without multimaterial contact.
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm::mechanics;

namespace {

void check(bool contact) {
  SimulationOptions o;
  o.gravity = Vec<3>(0, -100, 0);
  const double h = 0.002;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(h, h), IVec<2>{30, 30}), o);
  Material m;
  m.name = "block", m.density = 1000, m.youngs_modulus = 1e7, m.poisson_ratio = 0.3;
  Material plate;
  plate.name = "plate", plate.kind = MaterialKind::rigid, plate.density = 1000;
  plate.rigid_velocity = {TimeFunction::constant(0.5), TimeFunction::constant(0.0)};
  plate.rigid_boundary = true;
  plate.rigid_controls = {{true, false, false}};
  const int pm = sim.add_material(plate), bm = sim.add_material(m);
  sim.add_body("plate", *make_box<2>(Vec<2>(0.010, 0.030), Vec<2>(0.014, 0.040), pm), 2, Vec<2>::Zero());
  sim.add_body("block", *make_box<2>(Vec<2>(0.014, 0.030), Vec<2>(0.040, 0.040), bm), 2, Vec<2>::Zero());
  if (contact) {
    ContactOptions co;
    co.default_pair.law = FrictionLaw::frictionless();
    sim.enable_contact(co);
  }
  const double T = 0.01;
  while (sim.time() < T * (1 - 1e-12)) sim.step(T - sim.time());
  const auto& p = sim.particles();
  double vy = 0.0, mass = 0.0, vx_driven = 0.0, n_driven = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (p.material[k] != bm) continue;
    vy += p.mass[k] * p.velocity[k][1], mass += p.mass[k];
    if (p.initial_position[k][0] < 0.0165) vx_driven += p.velocity[k][0], n_driven += 1;  // first particle column
  }
  vy /= mass, vx_driven /= n_driven;
  std::printf("[rigid boundary, contact %d] block v_y = %.5f m/s (free fall %.5f), driven column v_x = %.4f m/s (plate 0.5)\n",
              static_cast<int>(contact), vy, -100 * T, vx_driven);
  // y is not prescribed: the whole block falls freely, to round-off of the FLIP update.
  EXPECT_NEAR(vy, -100 * T, 1e-9);
  // x is prescribed on the nodes the plate touches: the block's first column moves with it. Its uGIMP
  // stencil also reads undriven nodes to its right, which lead or lag with the compression waves
  // running through the block (measured +2.3 %); 5 %.
  EXPECT_NEAR(vx_driven, 0.5, 0.025);
}

}  // namespace

TEST(RigidBoundary, PrescribesOnlyTheChosenComponentWithoutContact) { check(false); }
TEST(RigidBoundary, PrescribesOnlyTheChosenComponentWithContact) { check(true); }
