// Normals without help: a block sliding down a 30° incline under gravity, the contact normal found
// by the maximum (MVG) or average (AVG) volume gradient of Nairn, Bardenhagen & Smith 2018 §2.3 (no
// specified normal). A rigid block on a rigid incline accelerates at a = g (sin θ − μ cos θ) along it.
//
// Two set-ups, both with the 140 × 25 mm base a rigid material at rest and the 40 × 15 mm elastic block
// of the sliding-block problem on it: (1) an axis-aligned base with gravity turned by θ (the same
// physics, interface on a grid line); (2) the incline turned by θ in the grid with gravity straight
// down, so the interface is a staircase of particles across the cells: the real test of the normals.
// Gravity is g = 1200 m/s² (the problem is linear in g; a large g makes the block slide 2–3 cm,
// several cells, in 10 ms of simulated time instead of 200 ms).
//
// Measured (μ = 0.2 / μ = 0):
//   turned gravity, MVG, 5 mm cells:   +0.02 % / 0.00 %
//   turned gravity, AVG, 5 mm cells:   −5.5 % / −2.2 %; at 2.5 mm cells −1.9 % / −0.8 %. The loss is
//     at the node under the block's downhill lower corner, where AVG mixes the block's end-face
//     gradient (pointing downhill) into the normal, so that node partly acts as a wall; it halves
//     with the cell size. AVG therefore runs at 2.5 mm.
//   turned geometry, specified normal:  0.00 % / 0.00 % (the set-up is right);
//   turned geometry, MVG or AVG: the block does not move at all (|v| < 0.01 m/s after 10 ms instead
//     of 3.9 / 6.0 m/s), at 5, 2.5 and 1.25 mm cells, with 2 or 4 particles per cell, and with
//     position, displacement or velocity-only detection. At the node under the block's downhill
//     corner the staircase base barely reaches (mass fraction 0.09, volume gradient 6 times smaller
//     than the block's), so the block's end face wins MVG: the normal points downhill (n·t = 0.998),
//     the block approaches the base along it and the contact stops it like a wall. Elsewhere the
//     gradients of the particle staircase are up to 15° off the true normal.
//   What we tried (in a patched copy of the library, not here): taking the rigid base's gradient
//     whenever the base is at the node (NairnMPM's RigidBias) frees the block at 5 mm cells but it
//     is 13 % (μ = 0) and 32 % (μ = 0.2) slow, and it sticks again at 2.5 mm; with plain MVG a block
//     with a rounded 15 mm nose instead of the corner slides 37 % slow at 5 mm, 15 % at 1.25 mm. The block's
//     and the base's staircases are cut from the same particle lattice and ride over each other's
//     steps; gradient normals see those steps. Only the specified normal, which ignores them,
//     recovers the rigid-body result, and it is what the paper used for its angled surfaces.
// The turned-geometry case is therefore tested with the specified normal only; the gradient-normal
// failure on particle staircases is a known limitation (docs/contact.md), not asserted here.
#include "test_materials.hpp"

#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace frictherm::mechanics;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 1200.0, kTheta = 30.0 * kPi / 180.0, kEnd = 0.010;

struct Incline {
  bool turned = true;  // true: geometry turned by θ; false: gravity turned by θ
  NormalMethod normal = NormalMethod::max_volume_gradient;
  double mu = 0.2;
  double cell = 0.005;
};

/// Least-squares slope of the block's mean velocity along the incline over [t0, kEnd].
double measured_acceleration(const Incline& c, double* final_velocity) {
  const double cs = std::cos(kTheta), sn = std::sin(kTheta);
  // Unit vectors along the incline (downhill) and of its outward normal.
  const Vec<2> t = c.turned ? Vec<2>(cs, -sn) : Vec<2>(1.0, 0.0);
  const Vec<2> n = c.turned ? Vec<2>(sn, cs) : Vec<2>(0.0, 1.0);
  auto at = [&](double s, double h) { return Vec<2>(s * t + h * n); };  // point s along, h above the base's bottom
  SimulationOptions o;
  o.thickness = 0.001;
  o.gravity = c.turned ? Vec<3>(0.0, -kG, 0.0) : Vec<3>(kG * sn, -kG * cs, 0.0);
  // The base is 140 × 25 mm, the block 40 × 15 mm starting 10 mm from the base's uphill end.
  const Vec<2> lo(-0.010, c.turned ? -0.080 : -0.010), span(c.turned ? 0.150 : 0.160, c.turned ? 0.130 : 0.060);
  const IVec<2> cells{static_cast<int>(std::lround(span[0] / c.cell)), static_cast<int>(std::lround(span[1] / c.cell))};
  Simulation<2> sim(Grid<2>(lo, Vec<2>(c.cell, c.cell), cells), o);
  const Material base_m = frictherm::verification::rigid_at_rest("incline");
  const Material block_m = frictherm::verification::elastic_material("block", 1000.0, 2500e6, 0.33);
  const int base = sim.add_material(base_m), block = sim.add_material(block_m);
  auto quad = [&](double s0, double h0, double s1, double h1, int mat) {
    return make_polygon<2>({at(s0, h0), at(s1, h0), at(s1, h1), at(s0, h1)}, 0.0, 0.0, mat);
  };
  sim.add_body("incline", *quad(0.0, 0.0, 0.140, 0.025, base), 2, Vec<2>::Zero());
  sim.add_body("block", *quad(0.010, 0.025, 0.050, 0.040, block), 2, Vec<2>::Zero());
  ContactOptions co;
  co.default_pair.law = c.mu > 0.0 ? FrictionLaw::coulomb(c.mu) : FrictionLaw::frictionless();
  co.default_pair.normal = c.normal;
  co.default_pair.normal_vector = Vec<3>(n[0], n[1], 0.0);  // specified: from the base to the block
  sim.enable_contact(co);
  sim.set_contact_pair(base, block, co.default_pair);
  std::vector<double> ts, vs;
  auto mean_v = [&] {
    const auto& p = sim.particles();
    double mv = 0.0, m = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.material[k] == block) mv += p.mass[k] * p.velocity[k].dot(t), m += p.mass[k];
    return mv / m;
  };
  const double sample = 1e-4;
  double next = sample;
  while (sim.time() < kEnd * (1 - 1e-12)) {
    sim.step(next - sim.time());
    if (sim.time() >= next * (1 - 1e-12)) {
      ts.push_back(sim.time()), vs.push_back(mean_v());
      next += sample;
    }
  }
  // Fit from 1 ms: the block first settles onto the incline (gravity switched on at t = 0).
  double st = 0, sv = 0, stt = 0, stv = 0, count = 0;
  for (std::size_t k = 0; k < ts.size(); ++k) {
    if (ts[k] < 1e-3) continue;
    st += ts[k], sv += vs[k], stt += ts[k] * ts[k], stv += ts[k] * vs[k], count += 1;
  }
  *final_velocity = vs.back();
  return (count * stv - st * sv) / (count * stt - st * st);
}

void check(const Incline& c) {
  const double expected = kG * (std::sin(kTheta) - c.mu * std::cos(kTheta));
  double v_end = 0.0;
  const double a = measured_acceleration(c, &v_end);
  const char* normal = c.normal == NormalMethod::max_volume_gradient       ? "MVG"
                       : c.normal == NormalMethod::average_volume_gradient ? "AVG"
                                                                           : "specified";
  std::printf("[incline %s, %s, %.1f mm cells, mu = %.1f] acceleration %.2f m/s² vs g(sin θ − μ cos θ) = %.2f: "
              "error %.2f %%; v(10 ms) = %.3f m/s (rigid %.3f)\n",
              c.turned ? "turned geometry" : "turned gravity ", normal, 1e3 * c.cell, c.mu, a, expected,
              100.0 * (a - expected) / expected, v_end, expected * kEnd);
  // The bound: 5 % (the block is elastic and the normal is found from the particles).
  EXPECT_NEAR(a, expected, 0.05 * expected);
}

}  // namespace

TEST(InclineNormals, TurnedGravityMaxVolumeGradient) {
  check({false, NormalMethod::max_volume_gradient, 0.2});
  check({false, NormalMethod::max_volume_gradient, 0.0});
}
TEST(InclineNormals, TurnedGravityAverageVolumeGradient) {
  check({false, NormalMethod::average_volume_gradient, 0.2, 0.0025});
  check({false, NormalMethod::average_volume_gradient, 0.0, 0.0025});
}
TEST(InclineNormals, TurnedGeometrySpecifiedNormal) {
  check({true, NormalMethod::specified, 0.2});
  check({true, NormalMethod::specified, 0.0});
}
