// Simulation set-up: guards on bad input, time step, material grouping, boundary conditions.
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace frictherm::mechanics;

namespace {
Material elastic(const std::string& name, double rho, double E, double nu) {
  Material m;
  m.name = name;
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  return m;
}
Grid<2> grid2() { return Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}); }
}  // namespace

TEST(SimulationSetup, RejectsBadMaterialsAndOptions) {
  Simulation<2> sim(grid2());
  EXPECT_THROW(sim.add_material(elastic("a", 0.0, 1e6, 0.3)), std::invalid_argument);
  EXPECT_THROW(sim.add_material(elastic("a", -1.0, 1e6, 0.3)), std::invalid_argument);
  EXPECT_THROW(sim.add_material(elastic("a", 1.0, 1e6, 0.5)), std::invalid_argument);
  EXPECT_THROW(sim.add_material(elastic("a", 1.0, 0.0, 0.3)), std::invalid_argument);
  SimulationOptions o;
  o.cfl = 0.0;
  EXPECT_THROW(Simulation<2>(grid2(), o), std::invalid_argument);
  o.cfl = 1.5;
  EXPECT_THROW(Simulation<2>(grid2(), o), std::invalid_argument);
  SimulationOptions ps;
  ps.analysis = Analysis::plane_stress;
  Simulation<2> sim_ps(grid2(), ps);
  Material nh = elastic("nh", 1000, 1e6, 0.3);
  nh.kind = MaterialKind::neo_hookean;
  EXPECT_THROW(sim_ps.add_material(nh), std::invalid_argument);
}

TEST(SimulationSetup, TimeStepFollowsCflAndParticleSpeed) {
  SimulationOptions o;
  o.cfl = 0.4;
  Simulation<2> sim(grid2(), o);
  const int m = sim.add_material(elastic("a", 1000, 1e7, 0.0));
  sim.add_body("b", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.6, 0.6), m), 2, Vec<2>(30.0, 40.0));
  const double c = std::sqrt(1e7 / 1000.0);  // nu = 0: lambda + 2 mu = E
  EXPECT_NEAR(sim.stable_time_step(), 0.4 * 0.1 / (c + 50.0), 1e-15);
}

TEST(SimulationSetup, FinalizeGroupsParticlesByMaterial) {
  Simulation<2> sim(grid2());
  const int a = sim.add_material(elastic("a", 1000, 1e7, 0.3));
  const int b = sim.add_material(elastic("b", 2000, 1e7, 0.3));
  sim.add_body("first", *make_box<2>(Vec<2>(0.1, 0.1), Vec<2>(0.3, 0.3), b), 2, Vec<2>::Zero());
  sim.add_body("second", *make_box<2>(Vec<2>(0.5, 0.5), Vec<2>(0.7, 0.7), a), 2, Vec<2>::Zero());
  sim.finalize();
  const auto& mat = sim.particles().material;
  EXPECT_TRUE(std::is_sorted(mat.begin(), mat.end()));
  for (std::size_t k = 0; k < mat.size(); ++k) EXPECT_EQ(sim.particles().body[k], mat[k] == a ? 1 : 0);
}

TEST(SimulationSetup, FixedFaceHoldsNodesAndGravityPullsFreeBody) {
  // A block resting on a fixed floor under gravity: the floor nodes never move, so after a few steps
  // the block's bottom layer has (almost) no vertical velocity while a free copy falls at g t.
  SimulationOptions o;
  o.gravity = Vec<3>(0, -10.0, 0);
  Simulation<2> held(grid2(), o), free_fall(grid2(), o);
  for (Simulation<2>* s : {&held, &free_fall}) {
    const int m = s->add_material(elastic("a", 1000, 1e7, 0.3));
    s->add_body("b", *make_box<2>(Vec<2>(0.3, 0.0), Vec<2>(0.7, 0.4), m), 2, Vec<2>::Zero());
  }
  held.fix_face(FixedFace{1, false, {{true, true, true}}});
  double t = 0.0;
  for (int k = 0; k < 20; ++k) {
    held.step();
    t += free_fall.step();
  }
  // Free body: every particle falls at exactly −g t (uniform body force, no stress develops).
  for (const auto& v : free_fall.particles().velocity) EXPECT_NEAR(v[1], -10.0 * t, 1e-9 * 10.0 * t + 1e-12);
  EXPECT_LT(std::abs(held.linear_momentum()[1]), 0.5 * std::abs(free_fall.linear_momentum()[1]));
}

TEST(SimulationSetup, PointLoadAndTractionResolve) {
  SimulationOptions o;
  o.thickness = 0.02;
  Simulation<2> sim(grid2(), o);
  const int m = sim.add_material(elastic("a", 1000, 1e7, 0.3));
  const int body = sim.add_body("b", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.6, 0.4), m), 2, Vec<2>::Zero());
  EdgeTraction<2> tr;
  tr.body = body;
  tr.axis = 0;
  tr.upper = true;
  tr.traction = Vec<2>(1e5, 0);
  sim.add_edge_traction(tr);
  // Total force of a traction = traction * face length * thickness; after one step of dt the
  // body's momentum is that force times dt (nothing else acts).
  const double dt = sim.step();
  const double F = 1e5 * 0.2 * 0.02;
  EXPECT_NEAR(sim.linear_momentum()[0], F * dt, 1e-9 * F * dt);
  PointLoad<2> pl;
  pl.body = body;
  pl.point = Vec<2>(0.2, 0.2);
  pl.force = Vec<2>(0, -3.0);
  sim.add_point_load(pl);
  const double dt2 = sim.step();
  EXPECT_NEAR(sim.linear_momentum()[1], -3.0 * dt2, 1e-9 * 3.0 * dt2);
}

TEST(SimulationSetup, ParticleLeavingGridStopsWithMessage) {
  Simulation<2> sim(grid2());
  const int m = sim.add_material(elastic("a", 1000, 1e7, 0.3));
  sim.add_body("runaway", *make_box<2>(Vec<2>(0.8, 0.4), Vec<2>(0.98, 0.6), m), 2, Vec<2>(200.0, 0.0));
  try {
    for (int k = 0; k < 1000; ++k) sim.step();
    FAIL() << "expected a SimulationError";
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("left the grid"), std::string::npos) << msg;
    EXPECT_NE(msg.find("runaway"), std::string::npos) << msg;
    EXPECT_GE(e.particle(), 0);
    EXPECT_GT(e.step(), 0);
  }
}
