// MUSL in a decomposed run (issue 32, step 3): `mpirun -n 2 frictherm run` against `frictherm run` on the
// MUSL examples without contact, which the decomposed step runs as its USL phases with the remap of
// the momenta from the updated particles and its exchange inserted (DecomposedMpm, usl_phases.cpp):
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

// MUSL with multimaterial contact stays serial: the refusal names the key (MUSL with penalty contact
// runs decomposed: test_cli_mpirun_ebs.cpp).
TEST_F(MpirunMusl, MuslWithContactIsRefused) {
  const Result v = shell(exe() + " validate " + source("examples/sliding_block.json") + " --set solver.scheme=musl");
  EXPECT_EQ(v.code, 0) << v.output;
  EXPECT_THAT(v.output, HasSubstr("serial only (solver.scheme: \"musl\" with multimaterial contact is not supported in a decomposed run"));
  for (const char* scene : {"examples/bars_impact.json", "examples/rigid_push.json", "examples/sphere_3d.json",
                            "examples/granular_waves.json", "examples/half_disk_plane.json", "examples/hertz_disks.json",
                            "examples/neo_hookean_rings.json"}) {
    const Result ok = shell(exe() + " validate " + source(scene));
    EXPECT_THAT(ok.output, HasSubstr("mpirun -n K frictherm run decomposes it")) << scene;
  }
}

}  // namespace
