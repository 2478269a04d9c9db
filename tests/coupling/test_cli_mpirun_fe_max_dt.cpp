// thermal.forward_euler.max_dt in a decomposed run (issue 32): the cap on forward Euler's sub-step, in
// the matrix-free windows (more sub-steps of the same window, as the serial Coupler's count) and on the
// assembled path (the serial Scheme on the distributed ODE). The decomposed sliding block with
// conduction every step (steps of 3.0 µs), 60 steps, serially and on 2 ranks: with 2e-7 s every
// window stays matrix-free (16 sub-steps), with 4e-8 s a window needs 77, more than
// matrix_free_max_substeps (64), and goes assembled (4415 thermal steps). Temperatures within 1e-9 of
// the rise (0.35 K), the books' energy change within 1e-9 of its scale, the thermal step counts equal;
// without the cap the temperatures differ by 2.6e-4 K (4e-8 s), so a run that ignored it could not
// match.
// Labels verification;mpi.
#include <gtest/gtest.h>

#include "mpirun_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace {

using MpirunForwardEuler = frictherm::test::MpirunCompare;
using frictherm::test::read_doubles;

TEST_F(MpirunForwardEuler, MaxDtCapsTheSubStepsAsSerially) {
  const std::string scene = "tests/coupling/scenes/decomposed_sliding_block.json";
  const std::string steps = " --set run.max_steps=60 --set output.series_interval=0";
  const frictherm::test::Result plain = frictherm::test::shell(exe() + " run " + source(scene) + steps +
                                                               " -q --threads 1 --force -o '" + path("plain.h5") + "'");
  ASSERT_EQ(plain.code, 0) << plain.output;
  for (const char* max_dt : {"2e-7", "4e-8"}) {
    run_both(scene, steps + " --set 'thermal.forward_euler={\"max_dt\":" + max_dt + "}'", 2);
    if (HasFatalFailure()) return;
    const std::vector<double> T = column("serial.h5", "max_temperature"), Tp = column("plain.h5", "max_temperature");
    const double rise = *std::max_element(T.begin(), T.end()) - T.front();
    ASSERT_GT(rise, 0.1);  // measured 0.35 K
    expect_same_column("max_temperature", 1e-9 * rise / *std::max_element(T.begin(), T.end()));
    expect_same_column("thermal_energy_change", 1e-9);
    EXPECT_EQ(read_doubles(path("split.h5"), "/meta/thermal_steps"), read_doubles(path("serial.h5"), "/meta/thermal_steps"))
        << max_dt;
    double moved = 0.0;
    for (std::size_t k = 0; k < std::min(T.size(), Tp.size()); ++k) moved = std::max(moved, std::fabs(T[k] - Tp[k]));
    EXPECT_GT(moved, 1e-5) << max_dt << ": the cap should change the temperatures";
  }
}

}  // namespace
