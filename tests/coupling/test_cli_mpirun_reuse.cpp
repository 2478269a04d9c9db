// coupling.reuse_distance in a decomposed run (issue 32, the last refusal gone): the serial reuse of the
// last matrix-free gather (ExplicitConduction::refresh) with the decisions made over all ranks
// (DecomposedHeat::reuse_window) and each particle's gather position carried with it across ranks.
// The decomposed sliding block (forward Euler, conduction every step, the block crossing the rank
// split at 10 m/s: 0.03 cells a step) with reuse_distance 0.1, 120 steps, serially and on 2 and 4
// ranks: every series column within 1e-9 of its scale, the matrix-free gathers, refreshes, windows and
// sub-steps counted alike (refreshes and gathers > 0: both kinds of decision happen), the energy books
// closed; and the reuse changes the temperatures against the gather every window (so a run that
// ignored it could not match). Then with conduction 100 times the scene's (KeptBoundsAndAssembledWindows).
// Labels verification;mpi.
#include <gtest/gtest.h>

#include "mpirun_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using MpirunReuse = frictherm::test::MpirunCompare;
using frictherm::test::read_doubles;

TEST_F(MpirunReuse, ReuseDistanceDecidesAsSerially) {
  const std::string scene = "tests/coupling/scenes/decomposed_sliding_block.json";
  const std::string steps = " --set run.max_steps=120 --set output.series_interval=0";
  const frictherm::test::Result fresh = frictherm::test::shell(
      exe() + " run " + source(scene) + steps + " -q --threads 1 --force -o '" + path("fresh.h5") + "'");
  ASSERT_EQ(fresh.code, 0) << fresh.output;
  for (int ranks : {2, 4}) {
    run_both(scene, steps + " --set coupling.reuse_distance=0.1", ranks);
    if (HasFatalFailure()) return;
    EXPECT_GT(compare_series(1e-9), 20) << ranks;
    const auto meta = [&](const char* file, const std::string& name) {
      const std::vector<double> v = read_doubles(path(file), "/meta/" + name);
      return v.empty() ? std::nan("") : v.front();
    };
    for (const std::string name : {"thermal_matrix_free_gathers", "thermal_matrix_free_refreshes",
                                   "thermal_matrix_free_windows", "thermal_matrix_free_substeps", "thermal_windows"}) {
      EXPECT_EQ(meta("split.h5", name), meta("serial.h5", name)) << name << " on " << ranks << " ranks";
      std::printf("  %-30s serial %g, %d ranks %g\n", name.c_str(), meta("serial.h5", name), ranks, meta("split.h5", name));
    }
    EXPECT_GT(meta("serial.h5", "thermal_matrix_free_refreshes"), 0.0);
    EXPECT_GT(meta("serial.h5", "thermal_matrix_free_gathers"), 1.0);
    EXPECT_LT(meta("serial.h5", "thermal_matrix_free_gathers"), meta("serial.h5", "thermal_matrix_free_windows"));
    // The books closed: the heat delivered, the nodal and the particle energy change each equal the
    // frictional work received (no heat pending after the last window: every step closes one).
    const double work = meta("split.h5", "work_received");
    ASSERT_GT(work, 0.0);
    for (const char* name : {"heat_delivered", "nodal_energy_change", "particle_energy_change"})
      EXPECT_NEAR(meta("split.h5", name), work, 1e-9 * work) << name << " on " << ranks << " ranks";
    // The reuse matters: the temperatures differ from those of the gather every window.
    const std::vector<double> T = column("serial.h5", "max_temperature"), Tf = column("fresh.h5", "max_temperature");
    double moved = 0.0;
    for (std::size_t k = 0; k < std::min(T.size(), Tf.size()); ++k) moved = std::max(moved, std::fabs(T[k] - Tf[k]));
    std::printf("  reuse against the gather every window: max temperature up to %.3g K apart\n", moved);
    EXPECT_GT(moved, 1e-9 * T.back() * 1e3);
  }
}

// Conduction 100 times the scene's: windows of several sub-steps, so that the exact bounds of M⁻¹K are
// made after a gather and then kept through refreshes (the Rayleigh terms made with M of their time,
// scaled by max M_peak / M), and one window beyond matrix_free_max_substeps goes to the assembled path
// (forward Euler on the assembled rows) and the next gathers anew. Measured: 18 gathers, 32
// refreshes, 686 sub-steps in 149 matrix-free windows of 150, every column within 1.3e-11.
TEST_F(MpirunReuse, KeptBoundsAndAssembledWindowsAsSerially) {
  run_both("tests/coupling/scenes/decomposed_sliding_block.json",
           " --set run.max_steps=150 --set output.series_interval=0 --set coupling.reuse_distance=0.1"
           " --set 'thermal.materials={\"base\":{\"heat_capacity\":100,\"conductivity\":5000},"
           "\"block\":{\"heat_capacity\":150,\"conductivity\":2000}}'",
           2);
  if (HasFatalFailure()) return;
  EXPECT_GT(compare_series(1e-9), 20);
  const auto meta = [&](const char* file, const std::string& name) {
    const std::vector<double> v = read_doubles(path(file), "/meta/" + name);
    return v.empty() ? std::nan("") : v.front();
  };
  for (const std::string name : {"thermal_matrix_free_gathers", "thermal_matrix_free_refreshes",
                                 "thermal_matrix_free_windows", "thermal_matrix_free_substeps", "thermal_windows",
                                 "thermal_steps"}) {
    EXPECT_EQ(meta("split.h5", name), meta("serial.h5", name)) << name;
    std::printf("  %-30s serial %g, 2 ranks %g\n", name.c_str(), meta("serial.h5", name), meta("split.h5", name));
  }
  EXPECT_GT(meta("serial.h5", "thermal_matrix_free_refreshes"), 0.0);
  EXPECT_GT(meta("serial.h5", "thermal_matrix_free_substeps"), 2.0 * meta("serial.h5", "thermal_matrix_free_windows"));
  EXPECT_LT(meta("serial.h5", "thermal_matrix_free_windows"), meta("serial.h5", "thermal_windows"));  // one assembled
}

}  // namespace
