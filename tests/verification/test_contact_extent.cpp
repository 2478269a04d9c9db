// Extent separation (contact_extents.cpp, docs/contact.md "Contact detection"): contact decided from the
// gap between the particle domains along the normal, with slivers kept from interpenetrating but given
// no friction. Checked on the sliding block of Nairn, Bardenhagen & Smith (2018), figure 2:
//  * under the preload alone the block is in static equilibrium, so every particle row carries
//    σ_yy = −N; with position separation the bottom rows do not (a sliver of the block's field at the
//    node row below the interface falls below min_mass_fraction, is dropped, and its a = f/m strains
//    the bottom row: tensile row 0, over-compressed row 1, worse at finer cells);
//  * adhesion sliding against the rigid-block solution at two resolutions.
#include "sliding_block.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace frictherm;
using namespace frictherm::verification;
using mechanics::FrictionLaw;
using mechanics::SeparationMethod;
using mechanics::IVec;
using mechanics::SimulationOptions;
using mechanics::Vec;

namespace {

// Mean σ_yy of the block's bottom particle row (k = 0) and the row above it (k = 1), 2 particles per cell.
std::vector<double> bottom_row_stress(const mechanics::Simulation<2>& sim, int block, double cell) {
  const auto& p = sim.particles();
  double ymin = 1e300;
  for (std::size_t q = 0; q < p.size(); ++q)
    if (p.material[q] == block) ymin = std::min(ymin, p.position[q][1]);
  std::vector<double> sum(2, 0.0), count(2, 0.0);
  for (std::size_t q = 0; q < p.size(); ++q) {
    if (p.material[q] != block) continue;
    const double row = (p.position[q][1] - ymin) / (0.5 * cell);
    for (int k = 0; k < 2; ++k)
      if (std::fabs(row - k) < 0.25) sum[static_cast<std::size_t>(k)] += p.stress[q](1, 1), ++count[static_cast<std::size_t>(k)];
  }
  return {sum[0] / count[0], sum[1] / count[1]};
}

// Largest |σ_yy/N + 1| of the two bottom rows after the normal ramp (t1 = tf/4) and a further 0.3 ms.
double preload_row_error(SeparationMethod separation, double cell) {
  using C = SlidingBlockConstants;
  SlidingBlockSetup s;
  s.cell = cell;
  s.separation = separation;
  s.law = FrictionLaw::coulomb(0.2);
  int block = 0;
  mechanics::Simulation<2> sim = make_sliding_block(s, block);
  const double t_end = 0.25 * C::t_final() + 3e-4;  // the tangential load starts at tf/4 from zero
  while (sim.time() < t_end) sim.step(t_end - sim.time());
  const std::vector<double> rows = bottom_row_stress(sim, block, cell);
  const double N = C::normal_stress();
  std::printf("[preload, %s, %.2f mm cells] bottom rows sigma_yy %.1f, %.1f kPa (applied -%.1f kPa)\n",
              separation == SeparationMethod::extent ? "extent" : "position", cell * 1e3, rows[0] / 1e3,
              rows[1] / 1e3, N / 1e3);
  return std::max(std::fabs(rows[0] / N + 1.0), std::fabs(rows[1] / N + 1.0));
}

}  // namespace

// Static equilibrium under the preload: the ramp (3.4 ms) is 300 times the block's wave transit time,
// so the rows carry −N to within the small dynamic residue; 3 % allows for it. Two resolutions: the
// sliver that breaks position separation shrinks with the cell while its damage grows.
TEST(ExtentSeparation, PreloadedInterfaceRowsCarryTheAppliedPressure) {
  for (double cell : {0.005, 0.0025}) EXPECT_LT(preload_row_error(SeparationMethod::extent, cell), 0.03) << cell;
  // Position separation at 2.5 mm, for the record (measured: row 0 about −125 kPa, row 1 −168 kPa and
  // drifting apart); not asserted, it documents why extent exists.
  preload_row_error(SeparationMethod::position, 0.0025);
}

// Adhesion (μ = 0.2, S_a = 0.3 N, R = 1) with extent detection against the rigid block, errors relative to
// its own v_max. With eq. 11's contact area it was 3.9 % / 2.0 % of v_max and −3.4 % / −1.7 % of the work
// at 5 / 2.5 mm, first order in h (the area of the block's two end nodes); with the surface area (the
// default, docs/contact.md "Contact area") measured 0.24 % / 0.10 % and 0.08 % / 0.09 %: both levels are
// at the noise of the rigid-block comparison, so they are bounded, not ordered. Bounds: 1 % of v_max
// and of the work (four times the 5 mm velocity error; a quarter of eq. 11's).
TEST(ExtentSeparation, AdhesionBlockAtTwoResolutions) {
  using C = SlidingBlockConstants;
  const double S_a = 0.3 * C::normal_stress();
  const RigidBlock r = rigid_solution(0.2, 0.2, 0.0, S_a);
  const double tf = C::t_final(), v_max = r.velocity(tf), Q = r.friction_work(tf);
  std::vector<double> velocity_error, work_error;
  for (double cell : {0.005, 0.0025}) {
    SlidingBlockSetup s;
    s.cell = cell;
    s.separation = SeparationMethod::extent;
    s.law = FrictionLaw::adhesion(0.2, S_a);
    const SlidingHistory h = run_sliding_block(s);
    double e = 0.0;
    for (std::size_t k = 0; k < h.time.size(); ++k) e = std::max(e, std::fabs(h.velocity[k] - r.velocity(h.time[k])) / v_max);
    velocity_error.push_back(e);
    work_error.push_back(std::fabs(h.work_second.back() - Q) / Q);
    std::printf("[adhesion, extent, %.2f mm cells] max |v - v_rigid|/v_max %.4f (v_max %.2f m/s), work %.5g J vs %.5g J\n",
                cell * 1e3, e, v_max, h.work_second.back(), Q);
  }
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_LT(velocity_error[i], 0.01) << i;
    EXPECT_LT(work_error[i], 0.01) << i;
  }
}


// Issue 31: a sliding interface held closed. Extent detection lets an open gap close within the step
// (the stop keeps the approach g/dt) instead of stopping the surfaces anywhere inside the tolerance
// band, which held them up to 0.01 h⊥ apart; under sliding the grid-scale vibration then pumped the
// Coulomb block (μ = 0.2, the paper's 5 mm cells) up to 17 µm above its compressed position (and the
// composite law's by 35 µm). Pressed by N, the block's mean sits 1.3 µm below its start and rises by
// its elastic (Poisson) response to the push, 0.43 µm at the end: a closed interface keeps the block's
// mean lift, averaged over 1 ms (the interface's vertical vibration swings it by ±2 µm at 10–30 m/s),
// below its start. The bound, 0.5 µm above the start, leaves 1.8 µm for the elastic response and fails
// for the old stop (17 µm) and for position separation (19 µm).
TEST(ExtentSeparation, SlidingInterfaceStaysClosed) {
  SlidingBlockSetup s;
  s.scheme = mechanics::UpdateScheme::usl;  // the scene default
  s.separation = SeparationMethod::extent;  // the scene default for every law
  s.law = FrictionLaw::coulomb(0.2);
  const SlidingHistory h = run_sliding_block(s);
  const RigidBlock r = rigid_solution(0.2, 0.2, 0.0, 0.0);
  const double tf = SlidingBlockConstants::t_final(), window = 1e-3, t1 = 0.25 * tf;
  double worst = -1.0, velocity_error = 0.0;
  for (std::size_t k = 0; k < h.time.size(); ++k) {
    velocity_error = std::max(velocity_error, std::fabs(h.velocity[k] - r.velocity(h.time[k])) / r.velocity(tf));
    if (h.time[k] < t1 || h.time[k] + window > h.time.back()) continue;
    double sum = 0.0;
    int count = 0;
    for (std::size_t j = k; j < h.time.size() && h.time[j] < h.time[k] + window; ++j) sum += h.lift[j], ++count;
    worst = std::max(worst, sum / count);
  }
  std::printf("[Coulomb 0.2, extent, 5 mm] largest 1 ms mean lift above the start %.2f um, velocity error %.4f\n",
              worst * 1e6, velocity_error);
  EXPECT_LT(worst, 0.5e-6);
  EXPECT_LT(velocity_error, 0.005);
}

namespace {

// Two elastic blocks of equal height (10 mm, E 1e8, ν 0.3, 2 × 2 particles per cell, uGIMP, USL),
// A at V = 5 m/s towards B at rest across a gap of half a cell, frictionless, extent detection, no
// gravity and no faces held. Returns B's particle momentum along x at time t.
double resting_block_momentum(double h, double t) {
  SimulationOptions o;
  o.cfl = 0.5;
  o.scheme = mechanics::UpdateScheme::usl;
  o.shape = mechanics::ShapeKind::ugimp;
  mechanics::Simulation<2> sim(mechanics::Grid<2>(Vec<2>(0, 0), Vec<2>(h, h), IVec<2>{static_cast<int>(std::lround(0.04 / h)),
                                                                                      static_cast<int>(std::lround(0.02 / h))}),
                               o);
  mechanics::Material m;
  m.density = 1000, m.youngs_modulus = 1e8, m.poisson_ratio = 0.3;
  m.name = "a";
  const int a = sim.add_material(m);
  m.name = "b";
  const int b = sim.add_material(m);
  const double gap = 0.5 * h, face = 0.015;
  sim.add_body("A", *mechanics::make_box<2>(Vec<2>(0.005, 0.005), Vec<2>(face - gap, 0.015), a), 2, Vec<2>(5.0, 0));
  sim.add_body("B", *mechanics::make_box<2>(Vec<2>(face, 0.005), Vec<2>(0.025, 0.015), b), 2, Vec<2>::Zero());
  mechanics::ContactOptions co;
  co.separation = SeparationMethod::extent;
  co.default_pair.law = FrictionLaw::frictionless();
  sim.enable_contact(co);
  while (sim.time() < t * (1 - 1e-12)) sim.step(t - sim.time());
  const auto& p = sim.particles();
  double momentum = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == b) momentum += p.mass[k] * p.velocity[k][0];
  return momentum;
}

}  // namespace

// Bodies apart do not interact. At the blocks' facing corners the normal leans about 45°, and the
// particle domains' projections on it overlap across the open gap, so the normal's gap alone called
// the corner nodes touching: B moved from the first step (0.049 m/s after 20 µs at 1 mm cells, and
// the impact then lost 38 % of the kinetic energy instead of 18 %). The x axis separates the domains
// there (contact_extent.hpp extent_axis_gap), so B stays exactly at rest until A's face arrives,
// g / V = 100 µs at 1 mm cells; checked at 90 % of that, at two cells.
TEST(ExtentSeparation, CornersFacingAcrossAnOpenGapDoNotTouch) {
  for (double h : {0.001, 0.0005}) {
    const double t_close = 0.5 * h / 5.0;
    const double momentum = resting_block_momentum(h, 0.9 * t_close);
    std::printf("[corners across a gap, %.2f mm cells] B's momentum at 0.9 g/V: %.3g kg m/s\n", h * 1e3, momentum);
    EXPECT_EQ(momentum, 0.0) << h;
  }
}
