// Loads in a decomposed run (issue 32, step 1): `mpirun -n 2 frictherm run` against `frictherm run` on
// scenes with point loads, tractions and mass-proportional damping, which the decomposed step applies
// with the serial kernels (mechanics/include/frictherm/mechanics/loads/grid_loads.hpp):
//   * a free block under a traction cut in two by the rank split, a point load and damping
//     (tests/coupling/scenes/decomposed_loaded_block.json), on 4 and 2 ranks: every series column of
//     the decomposed run within 1e-9 of the serial column's scale, and on the serial and 2-rank runs
//     the impulse balance of each step,
//     P^{n+1} = P^n + dt (F(t_n) − c P^n) with F the total applied load (a traction counted twice
//     or once on each rank's half would break it by the half's force);
//   * the pressed block (examples/pressed_block.json: a traction ramped onto a block on a fixed base,
//     damped, Coulomb contact with displacement separation) and the sliding block
//     (examples/sliding_block.json: two tractions, Coulomb contact) cut to their first steps: the
//     series within 1e-9 of each column's scale.
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "mpirun_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using ::testing::HasSubstr;
using frictherm::test::Result;
using frictherm::test::shell;

namespace {

using MpirunLoads = frictherm::test::MpirunCompare;

// The free block: the decomposed run is the serial run to round-off, and both keep the impulse balance.
TEST_F(MpirunLoads, LoadedFreeBlockMatchesSerialAndTheImpulseBalance) {
  for (const int ranks : {4, 2}) {  // 4: the top layer over more ranks; the checks below read the 2-rank run
    run_both("tests/coupling/scenes/decomposed_loaded_block.json", "", ranks);
    std::printf("  %d ranks:\n", ranks);
    // 1e-9: the decomposed step is the serial arithmetic with its nodal sums split between the ranks
    // (another summation order: relative differences of a few ε per step, carried by the elastic
    // waves of ~60 steps; measured ≤ 5.4e-15), far below any error of a load on the wrong nodes.
    for (const char* c : {"time", "dt", "kinetic_energy", "momentum_x", "momentum_y", "external_work", "damping_work"})
      expect_same_column(c, 1e-9);
  }
  // The loads of the scene (docs/scenes.md): the traction on the top layer, 48 particles 0.5 mm wide
  // and 1 mm thick (area 2.4e-5 m²), and the point load ramped over 20 us; damping c on every node.
  const double area = 0.024 * 0.001, c = 2e4, ramp = 2e-5;
  const double traction[2] = {2e6, -2e6}, point[2] = {-40.0, 10.0};
  for (const char* file : {"serial.h5", "split.h5"}) {
    const std::vector<double> t = column(file, "time"), dt = column(file, "dt");
    const std::vector<double> P[2] = {column(file, "momentum_x"), column(file, "momentum_y")};
    ASSERT_GT(t.size(), 40u) << file << ": a row every step";
    // Each step's nodal forces sum to the applied load: Σ_i f_i^int = 0 and Σ_i S_ip = 1, and the FLIP
    // update hands the particles Σ_i m_i a_i dt = Σ_i f_i dt, so the momentum changes by the impulse
    // of the load and of the damping force −c Σ_i p_i = −c P. What remains is the round-off of sums of
    // nodal forces ~100 times the net force (σ V G per node), a few ε each: 1e-12 of the momentum scale
    // (measured 2.7e-15 serial, 1.1e-15 on 2 ranks; a traction counted on one half twice: ~1e-2).
    double scale = 0.0, worst = 0.0;
    for (int d = 0; d < 2; ++d)
      for (double p : P[d]) scale = std::max(scale, std::fabs(p));
    for (std::size_t n = 0; n + 1 < t.size(); ++n)
      for (int d = 0; d < 2; ++d) {
        const double F = traction[d] * area + point[d] * std::min(t[n] / ramp, 1.0);
        const double expected = P[d][n] + dt[n + 1] * (F - c * P[d][n]);
        worst = std::max(worst, std::fabs(P[d][n + 1] - expected));
      }
    EXPECT_LE(worst, 1e-12 * scale) << file;
    std::printf("  %s: impulse balance max residual %.3g of the momentum scale %.6g\n", file, worst / scale, scale);
    // The books: the loads did work and the damping removed energy.
    EXPECT_GT(column(file, "external_work").back(), 0.0) << file;
    EXPECT_GT(column(file, "damping_work").back(), 0.0) << file;
  }
}

// The examples with loads and damping, cut to their first steps.
TEST_F(MpirunLoads, PressedAndSlidingBlocksMatchSerial) {
  // 1e-9 of each column's scale, as above: the contact of these blocks sticks or slides smoothly in
  // these steps (no chaos), so the summation order changes only the last digits.
  run_both("examples/pressed_block.json", " --set run.max_steps=300 --set output.series_interval=0");
  // (Its momentum_x is round-off about 0 and its block sticks: no frictional work in these steps.)
  for (const char* c : {"time", "kinetic_energy", "momentum_y", "external_work", "damping_work"})
    expect_same_column(c, 1e-9);
  run_both("examples/sliding_block.json", " --set run.max_steps=300 --set output.series_interval=0");
  for (const char* c : {"time", "kinetic_energy", "momentum_x", "momentum_y", "external_work", "friction_work_first",
                        "friction_work_second"})
    expect_same_column(c, 1e-9);
}

// `validate` says the examples with loads and damping decompose.
TEST_F(MpirunLoads, ValidateSaysTheyDecompose) {
  for (const char* scene : {"examples/pressed_block.json", "examples/sliding_block.json",
                            "tests/coupling/scenes/decomposed_loaded_block.json"}) {
    const Result v = shell(exe() + " validate " + source(scene));
    EXPECT_EQ(v.code, 0) << v.output;
    EXPECT_THAT(v.output, HasSubstr("mpirun -n K frictherm run decomposes it")) << scene;
  }
}

}  // namespace
