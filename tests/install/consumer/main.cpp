// Builds against the installed headers and libraries; runs a few MPM steps of a falling block and
// checks the free-fall velocity v = g t (exact for a uniform body force on an unconstrained body).
#include <frictherm/mechanics/simulation.hpp>

#include <cmath>
#include <cstdio>

int main() {
  using namespace frictherm::mechanics;
  SimulationOptions o;
  o.gravity = Vec<3>(0, -9.81, 0);
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}), o);
  Material m;
  m.name = "block";
  m.density = 1000;
  m.youngs_modulus = 1e7;
  m.poisson_ratio = 0.3;
  const int mat = sim.add_material(m);
  sim.add_body("block", *make_box<2>(Vec<2>(0.3, 0.5), Vec<2>(0.7, 0.9), mat), 2, Vec<2>::Zero());
  double t = 0.0;
  for (int k = 0; k < 10; ++k) t += sim.step();
  const double v = sim.particles().velocity[0][1];
  std::printf("consumer: v = %.9g m/s after t = %.6g s (expected %.9g)\n", v, t, -9.81 * t);
  return std::abs(v + 9.81 * t) < 1e-9 ? 0 : 1;
}
