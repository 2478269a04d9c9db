// MUSL in a decomposed run (issue 32, step 3): `mpirun -n 2 frictherm run` against `frictherm run` on the
// MUSL examples without contact, which the decomposed step runs as its USL phases with the remap of
// the momenta from the updated particles and its exchange inserted (DecomposedMpm, usl_phases.cpp),
// and (below) on contact scenes run with MUSL:
//   * two aluminium bars meeting (examples/bars_impact.json, made asymmetric: the right bar at
//     −5 m/s), 300 steps: the series within 1e-9 of each column's scale, and the momentum of the free
//     bars kept on both runs to 1e-12 of Σ m|v|;
//   * a rigid platen pushing a block on a roller floor (examples/rigid_push.json: the driven nodes
//     and a fixed face in the remap's velocity conditions), 300 steps, and the 3D rubber sphere
//     dropped on a fixed floor (examples/sphere_3d.json), 40 steps: the series within 1e-9.
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

using MpirunMusl = frictherm::test::MpirunCompare;

// 1e-9 of each column's scale: the decomposed step is the serial arithmetic, its nodal sums split
// between two ranks (another summation order: a few ε per step, carried by the elastic waves of a few
// hundred steps), far below what a missing or doubled remap term would change (the remapped momenta
// are O(1) of the columns).
TEST_F(MpirunMusl, BarsImpactMatchesSerialAndKeepsMomentum) {
  run_both("examples/bars_impact.json",
           " --set 'bodies[1].velocity=[-5,0]' --set run.max_steps=300 --set output.series_interval=0");
  for (const char* c : {"time", "dt", "kinetic_energy", "momentum_x"}) expect_same_column(c, 1e-9);
  // Nothing acts on the bars from outside: Σ_i f_i = 0 every step and the remap moves momentum
  // between nodes only, so P stays at its start, to the round-off of sums of ~2000 particle momenta
  // of Σ m|v| = 15.1 kg m/s over 300 steps: 1e-12 of Σ m|v|.
  const double mass = 2700.0 * 0.935 * 0.02 * 0.02;  // one bar (kg): density × length × height × thickness
  const double scale = mass * (10.0 + 5.0);
  for (const char* file : {"serial.h5", "split.h5"}) {
    const std::vector<double> P = column(file, "momentum_x");
    ASSERT_GT(P.size(), 100u) << file;
    EXPECT_NEAR(P.front(), mass * (10.0 - 5.0), 1e-12 * scale) << file;
    double drift = 0.0;
    for (double p : P) drift = std::max(drift, std::fabs(p - P.front()));
    EXPECT_LE(drift, 1e-12 * scale) << file;
    std::printf("  %s: momentum drift %.3g of sum m|v| = %.6g\n", file, drift / scale, scale);
  }
}

TEST_F(MpirunMusl, RigidPushAndSphere3dMatchSerial) {
  run_both("examples/rigid_push.json", " --set run.max_steps=300 --set output.series_interval=0");
  for (const char* c : {"time", "kinetic_energy", "momentum_x", "momentum_y"}) expect_same_column(c, 1e-9);
  run_both("examples/sphere_3d.json", " --set run.max_steps=40 --set output.series_interval=0");
  for (const char* c : {"time", "kinetic_energy", "momentum_z"}) expect_same_column(c, 1e-9);
}

// MUSL with multimaterial contact (issue 32): the decomposed MUSL list runs the contact passes where the
// serial one does (simulation_step.cpp): on the extrapolated momenta, on the updated momenta (forces
// and frictional work) and on the remapped momenta after their exchange to the owners
// (contact_phases.cpp, contact_remapped). Three scenes under MUSL on 2 ranks:
//   * the sliding block (examples/sliding_block.json: two tractions, Coulomb μ = 0.3, position
//     separation), 300 steps: it slides (2–4 sliding nodes, the frictional work grows);
//   * the rigid pushers (examples/oscillating_block.json: rigid contact partners, displacement
//     separation, adhesion, damping), 1100 steps: the pushers have met the block (rigid_work > 0);
//   * the sliding block with extent separation (examples/sliding_block_expression.json), 600 steps.
// Every series column both runs write within 1e-9 of its own largest magnitude (the decomposed step
// is the serial arithmetic with the nodal sums split between the ranks; measured ≤ 1.7e-13, the
// pushers' rigid_work), every particle's last position by id within 1e-9 of a cell (measured
// ≤ 2.1e-17 m). With the remapped pass left out of the decomposed list (tried by hand) the kinetic
// energy differs by 0.99 (sliding block) and 1.9 (pushers) of its scale, the frictional work by 0.68
// and 6.8.
TEST_F(MpirunMusl, MuslWithMultimaterialContactMatchesSerial) {
  const std::string musl = " --set solver.scheme=musl --set output.series_interval=0";
  run_both("examples/sliding_block.json", musl + " --set run.max_steps=300");
  if (HasFatalFailure()) return;
  EXPECT_GE(compare_series(1e-9, 0.0), 10);
  const std::vector<double> work = column("split.h5", "friction_work_first");
  const std::vector<double> sliding = column("serial.h5", "sliding_nodes");
  ASSERT_FALSE(work.empty());
  EXPECT_GT(work.back(), 0.0) << "the block slides";
  EXPECT_GT(*std::max_element(sliding.begin(), sliding.end()), 0.0) << "the block slides";
  std::printf("  frictional work after 300 steps: %.6g J\n", work.back());
  EXPECT_LE(compare_positions(2), 1e-9 * 0.005);
  run_both("examples/oscillating_block.json", musl + " --set run.max_steps=1100");
  if (HasFatalFailure()) return;
  EXPECT_GE(compare_series(1e-9, 0.0), 10);
  const std::vector<double> rigid = column("serial.h5", "rigid_work");
  EXPECT_GT(rigid.empty() ? 0.0 : rigid.back(), 0.0) << "the rigid pushers have met the block";
  EXPECT_LE(compare_positions(2), 1e-9 * 0.0025);
  run_both("examples/sliding_block_expression.json", musl + " --set run.max_steps=600");
  if (HasFatalFailure()) return;
  EXPECT_GE(compare_series(1e-9, 0.0), 10);
  EXPECT_LE(compare_positions(2), 1e-9 * 0.005);
}

// `validate` says every MUSL example decomposes, and a MUSL scene with multimaterial contact too.
TEST_F(MpirunMusl, MuslExamplesDecompose) {
  const Result v = shell(exe() + " validate " + source("examples/sliding_block.json") + " --set solver.scheme=musl");
  EXPECT_EQ(v.code, 0) << v.output;
  EXPECT_THAT(v.output, HasSubstr("mpirun -n K frictherm run decomposes it"));
  for (const char* scene : {"examples/bars_impact.json", "examples/rigid_push.json", "examples/sphere_3d.json",
                            "examples/granular_waves.json", "examples/half_disk_plane.json", "examples/hertz_disks.json",
                            "examples/neo_hookean_rings.json"}) {
    const Result ok = shell(exe() + " validate " + source(scene));
    EXPECT_THAT(ok.output, HasSubstr("mpirun -n K frictherm run decomposes it")) << scene;
  }
}

}  // namespace
