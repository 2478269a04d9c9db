// Figure 9 of Nairn, Bardenhagen & Smith (2018) on a small specimen: the total frictional work of
// one fixed PBX microstructure compacted to 20 % strain, against the CFL factor C, first and second
// order heating. The paper's finding: both converge to the same work as C → 0 and the second order
// converges faster. The specimen is examples/pbx_microstructure_small.json (60 × 60 µm, 13 HMX grains
// in binder, walls, top wall at 3.07 m/s) loaded for 3.9 µs (12 µm, 20 % of its height); the full
// 240 µm specimen is examples/pbx_compaction.json with examples/pbx_figures.py --cfl-sweep.
//
// Measured (J per metre of thickness; the reference is the second order at C = 0.05; frictionless
// velocity-boundary walls, contact min_mass_fraction 0.02 and extent separation as in the scene):
//   C      W1        W2        error W1   error W2
//   1      0.0669    0.0472     180 %       98 %
//   0.5    0.0382    0.0313      60 %       31 %
//   0.25   0.0280    0.0249      17 %      4.1 %
//   0.1    0.0250    0.0232     4.7 %      2.8 %
//   0.05   0.0252    0.0239
// (displacement separation, the scene's choice before issue 31: 240 / 128, 117 / 60, 24 / 5.8,
// 3.2 / 6.2 %; the same findings.)
// Below C = 0.25 both orders sit within a few per cent of each other and of the reference (the
// run-to-run scatter of this partly chaotic compaction); above it the second order is the closer one,
// by a factor two to four: the paper's finding, second-order heating is accurate at a larger C.
// Asserted: the gap between the orders shrinks at every halving of C; for C ≥ 0.25 the second order
// is the closer one; at C = 0.25 the second order is within 10 % and the first order is not; at
// C = 0.1 both are within 10 %.
#include <frictherm/coupling/scene.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

using namespace frictherm;

namespace {

struct Work {
  double first = 0.0, second = 0.0;
  long steps = 0;
  double plastic = 0.0, lost = 0.0;  // the energy books (EnergyBalance): plastic work, energy the bodies lost
};

/// The small specimen compacted for 3.9 µs at CFL factor `cfl`, with `overrides` on top.
Work run(double cfl, std::vector<coupling::SceneOverride> overrides = {}) {
  const std::string path = std::string(FRICTHERM_SOURCE_DIR) + "/examples/pbx_microstructure_small.json";
  overrides.push_back({"solver.cfl", std::to_string(cfl)});
  overrides.push_back({"run.end_time", "3.9e-6"});
  const coupling::Scene scene = coupling::load_scene(path, overrides);
  auto sim = coupling::build_simulation<2>(scene);
  const double end = scene.end_time;
  while (sim->time() < end * (1 - 1e-12)) sim->step(end - sim->time());
  const mechanics::EnergyBalance e = sim->energy_balance(mechanics::HeatingOrder::second);
  return {sim->cumulative_frictional_work(mechanics::HeatingOrder::first),
          sim->cumulative_frictional_work(mechanics::HeatingOrder::second), sim->step_count(), e.plastic_work,
          e.lost()};
}

}  // namespace

TEST(PbxCompaction, SecondOrderHeatingConvergesFasterWithC) {
  // The paper's update (MUSL-like: NairnMPM's default projects the updated velocities again) with
  // pure FLIP, as measured above; the example scene's combination is tested below.
  const auto run = [](double c) {
    return ::run(c, {{"solver.scheme", "\"musl\""}, {"solver.pic_relaxation_time", "null"}});
  };
  const double smallest = 0.05;
  const Work ref = run(smallest);
  std::printf("[pbx cfl] C = %.3g: W1 = %.6g J, W2 = %.6g J (%ld steps)\n", smallest, ref.first, ref.second, ref.steps);
  ASSERT_GT(ref.second, 0.0) << "grains must slide";
  double last_gap = std::fabs(ref.first - ref.second);
  for (const double c : {0.1, 0.25, 0.5, 1.0}) {  // growing C: the orders drift apart
    const Work w = run(c);
    const double e1 = std::fabs(w.first - ref.second) / ref.second, e2 = std::fabs(w.second - ref.second) / ref.second;
    const double gap = std::fabs(w.first - w.second);
    std::printf("[pbx cfl] C = %.3g: W1 = %.6g J (error %.1f %%), W2 = %.6g J (error %.1f %%), %ld steps\n", c, w.first,
                100 * e1, w.second, 100 * e2, w.steps);
    EXPECT_GT(gap, last_gap) << "the orders must approach each other as C falls";
    last_gap = gap;
    if (c >= 0.25) {
      EXPECT_LT(e2, e1) << "second order must be closer to the converged work at C = " << c;
    }
    if (c == 0.25) {
      EXPECT_LT(e2, 0.10) << "second order within 10 % at C = 0.25";
      EXPECT_GT(e1, 0.10) << "first order still more than 10 % off at C = 0.25";
    }
    if (c == 0.1) {
      EXPECT_LT(std::max(e1, e2), 0.10) << "both orders within 10 % at C = 0.1";
    }
  }
}

// The target on the example's own combination (USL, FLIP/PIC blend τ = 30 ns): over five
// packings, the median second-order work at C = 0.5 within 10 % of its value at C = 0.1. Measured
// (J/m), extent separation: C = 0.5 median 0.0150, C = 0.1 median 0.0163 (−7.9 %; displacement
// separation 0.0138 against 0.0151, −8.3 %); MUSL with pure FLIP gives +68 %, the
// work growing linearly with C (docs/transfer.md). The seeds scatter the work by ±15 %, so one seed
// alone would not show the trend.
// Each run is also held to a reference of its own that a smaller C cannot share an error with, the
// mechanical energy books: the frictional heat (second order) plus the plastic work never exceeds
// the energy the bodies lost (walls' and piston's work less kinetic and stored energy; EnergyBalance),
// within 1 % of it. Measured (3 Dec, 4 µm cells): (W2 + plastic) / lost 0.72–0.87 over the packings
// at C = 0.5 and 0.1; the rest is the normal contact's stops and the scheme's numerical dissipation.
TEST(PbxCompaction, MedianWorkOfFivePackingsAtHalfCflWithinTenPercentOfSmallCfl) {
  std::vector<double> half, small;
  for (const int seed : {2018, 1, 2, 3, 4}) {
    const coupling::SceneOverride packing{"bodies[0].shape.seed", std::to_string(seed)};
    for (const double c : {0.5, 0.1}) {
      const Work w = run(c, {packing});
      (c == 0.5 ? half : small).push_back(w.second);
      std::printf("[pbx seeds] seed %d, C = %.2g: W2 = %.5g J/m, plastic %.5g J/m, energy lost %.5g J/m, "
                  "(W2 + plastic) / lost = %.3f\n",
                  seed, c, w.second, w.plastic, w.lost, (w.second + w.plastic) / w.lost);
      ASSERT_GT(w.second, 0.0) << "grains must slide";
      EXPECT_LE(w.second + w.plastic, 1.01 * w.lost) << "heat beyond the energy lost, seed " << seed << ", C = " << c;
    }
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + 2, v.end());
    return v[2];
  };
  const double ratio = median(half) / median(small);
  std::printf("[pbx seeds] median W2 at C = 0.5 is %+.1f %% of C = 0.1\n", 100 * (ratio - 1));
  EXPECT_LT(std::fabs(ratio - 1.0), 0.10);
}

// The contact passes run their nodes in parallel (per-thread stats and pair books, summed in thread
// order). The full 240 µm specimen (15,376 particles, thousands of contact nodes among 55 grains)
// gives the same frictional work and momentum on one and two threads, up to the round-off the
// particle-to-grid reduction order introduces.
TEST(PbxCompaction, ContactPassesGiveTheSameWorkOnOneAndTwoThreads) {
  const std::string path = std::string(FRICTHERM_SOURCE_DIR) + "/examples/pbx_compaction.json";
  const coupling::Scene scene = coupling::load_scene(path, {{"run.end_time", "1e-7"}});
  struct Result {
    double w1, w2, px, py;
    long contact_nodes;
  };
  auto run_with = [&](int threads) {
    omp_set_num_threads(threads);
    auto sim = coupling::build_simulation<2>(scene);
    long contact_nodes = 0;
    for (int s = 0; s < 100; ++s) {
      sim->step();
      contact_nodes = std::max(contact_nodes, sim->contact_stats().contact_nodes);
    }
    const auto& p = sim->particles();
    double px = 0.0, py = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) px += p.mass[k] * p.velocity[k][0], py += p.mass[k] * p.velocity[k][1];
    return Result{sim->cumulative_frictional_work(mechanics::HeatingOrder::first),
                  sim->cumulative_frictional_work(mechanics::HeatingOrder::second), px, py, contact_nodes};
  };
  const Result one = run_with(1), two = run_with(2);
  omp_set_num_threads(omp_get_num_procs());
  std::printf("[pbx threads] contact nodes %ld; W2 %.12g vs %.12g J\n", one.contact_nodes, one.w2, two.w2);
  ASSERT_GT(one.contact_nodes, 256) << "the parallel contact path must be exercised";
  ASSERT_GT(one.w2, 0.0);
  EXPECT_NEAR(two.w1, one.w1, 1e-9 * one.w1);
  EXPECT_NEAR(two.w2, one.w2, 1e-9 * one.w2);
  const double scale = std::hypot(one.px, one.py) + 1e-30;
  EXPECT_NEAR(two.px, one.px, 1e-9 * scale);
  EXPECT_NEAR(two.py, one.py, 1e-9 * scale);
}
