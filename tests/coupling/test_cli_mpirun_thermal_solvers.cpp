// The thermal solver options a decomposed run used to refuse (issue 32), serially and on 2 ranks: the
// decomposed sliding block (tests/coupling/scenes/decomposed_sliding_block.json, conduction every step
// of 3.0 µs), 60 steps.
//   * thermal.forward_euler.stability "unguarded" and "refuse": every window on the assembled rows
//     (as the serial Coupler), the serial forward Euler Scheme on the distributed ODE with the limit
//     reduced over ranks. "unguarded" (one step per window) and "refuse" with max_dt below the limit
//     run as serially (temperatures within 1e-9 of the rise, the same thermal step count); "refuse"
//     beyond the limit (in the first window, or a later one with max_dt 1e-7 s) stops every rank at
//     the serial run's step and time with the serial message and numbers.
//   * thermal.forward_euler.limit_estimate "power": the serial power iteration with reduced dot
//     products from the serial start vector (the unknowns in the serial numbering); the sub-step
//     counts equal the serial run's, the temperatures within 1e-9 of the rise.
//   * thermal.linear_solver "klu" with cvode_bdf: MUMPS' sparse direct LU of P = I − γJ preconditioning
//     PCG; the serial KLU run against it within the error control's resolution (below).
// Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "mpirun_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace {

using frictherm::test::read_doubles;
using ::testing::HasSubstr;
using frictherm::test::Result;
using frictherm::test::shell;
using frictherm::test::mpirun_command;

const std::string kScene = "tests/coupling/scenes/decomposed_sliding_block.json";
const std::string kSteps = " --set run.max_steps=60 --set output.series_interval=0";
// The scene's conductivities 1000 times larger (conduction limits the steps of both solvers).
const std::string kFastConduction =
    " --set 'thermal.materials={\"base\":{\"heat_capacity\":100,\"conductivity\":50000},"
    "\"block\":{\"heat_capacity\":150,\"conductivity\":20000}}'";

}  // namespace

class MpirunThermalSolvers : public frictherm::test::MpirunCompare {
 protected:
  // Serial and split series: the temperatures within `tolerance` of the rise, the books' energy change
  // within max(tolerance, 1e-9) of its scale; returns the difference over the rise.
  double same_temperatures(double tolerance, double least_rise = 0.1) {
    const std::vector<double> T = column("serial.h5", "max_temperature");
    const double rise = *std::max_element(T.begin(), T.end()) - T.front();
    EXPECT_GT(rise, least_rise);  // measured 0.35 K (the scene's conductivities)
    const double top = *std::max_element(T.begin(), T.end());
    const double diff = expect_same_column("max_temperature", tolerance * rise / top) * top / rise;
    expect_same_column("thermal_energy_change", std::max(tolerance, 1e-9));
    return diff;
  }
  void same_thermal_steps(const std::string& what) {
    EXPECT_EQ(read_doubles(path("split.h5"), "/meta/thermal_steps"),
              read_doubles(path("serial.h5"), "/meta/thermal_steps"))
        << what;
  }
};

TEST_F(MpirunThermalSolvers, UnguardedAndRefuseRunAsSerially) {
  // "unguarded": one step per 3.0 µs window, 28 Gershgorin limits (1.07e-7 s with fe_safety): stable
  // here all the same, the gather and map back every window damping the nodal modes. "refuse" with
  // max_dt 5e-8 s: 61 sub-steps per window, below the limit (at least 6.09e-8 s in these windows).
  for (const std::string sets : {"{\"stability\":\"unguarded\"}", "{\"stability\":\"refuse\",\"max_dt\":5e-8}"}) {
    run_both(kScene, kSteps + " --set 'thermal.forward_euler=" + sets + "'", 2);
    if (HasFatalFailure()) return;
    same_temperatures(1e-9);
    same_thermal_steps(sets);
  }
}

TEST_F(MpirunThermalSolvers, BeyondTheLimitEveryRankStopsAsTheSerialRun) {
  // Without max_dt the first window is refused (3.0 µs against 1.07e-7 s); with max_dt 1e-7 s a later
  // one, where the limit has fallen to 6.09e-8 s: the limit reduced over ranks, the same verdict.
  for (const char* fe : {"{\"stability\":\"refuse\"}", "{\"stability\":\"refuse\",\"max_dt\":1e-7}"}) {
    const std::string sets = kSteps + " --set 'thermal.forward_euler=" + fe + "'";
    const Result s =
        shell(exe() + " run " + source(kScene) + sets + " -q --threads 1 --force -o '" + path("serial.h5") + "'");
    const Result d = shell(mpirun_command(2) + " " + exe() + " run " + source(kScene) + sets + " -q --force -o '" +
                           path("split.h5") + "'");
    EXPECT_EQ(s.code, 1) << fe << ": " << s.output;
    EXPECT_EQ(d.code, s.code) << fe << ": " << d.output;
    // The serial message with the same numbers: "step H s exceeds the stability limit ... refusing".
    const auto verdict = [](const std::string& out) {
      const auto a = out.find("step "), b = out.find("refusing (fe_stability_policy \"refuse\")");
      return a == std::string::npos || b == std::string::npos || b < a ? std::string() : out.substr(a, b - a);
    };
    EXPECT_THAT(s.output, HasSubstr("thermal integration unstable")) << fe;
    EXPECT_THAT(d.output, HasSubstr("thermal integration unstable")) << fe;
    EXPECT_FALSE(verdict(s.output).empty()) << s.output;
    EXPECT_EQ(verdict(d.output), verdict(s.output)) << fe;
    // Failed at the serial run's step and time, every rank (the series file holds rank 0's word).
    EXPECT_EQ(frictherm::test::read_text(path("serial.h5"), "/meta/status"), "failed") << fe;
    EXPECT_EQ(frictherm::test::read_text(path("split.h5"), "/meta/status"), "failed") << fe;
    const std::vector<double> steps = read_doubles(path("serial.h5"), "/meta/steps");
    EXPECT_EQ(read_doubles(path("split.h5"), "/meta/steps"), steps) << fe;
    EXPECT_EQ(read_doubles(path("split.h5"), "/meta/final_time"), read_doubles(path("serial.h5"), "/meta/final_time"))
        << fe;
    std::printf("  %s: serial and 2 ranks end with code %d after step %g: %s\n", fe, s.code,
                steps.empty() ? -1.0 : steps[0], verdict(s.output).c_str());
  }
}

TEST_F(MpirunThermalSolvers, PowerEstimateAsSerially) {
  // The scene's power limit is above its 3.0 µs windows (one step each, Gershgorin: 28); with the
  // conductivities 1000 times larger the power limit decides: 354 sub-steps in the 60 windows (about
  // 6 a window), which a limit off by more than round-off would change (the serial Gershgorin limit
  // is some 5000 times smaller there).
  run_both(kScene, kSteps + kFastConduction + " --set 'thermal.forward_euler={\"limit_estimate\":\"power\"}'", 2);
  if (HasFatalFailure()) return;
  same_temperatures(1e-9, 0.02);  // the rise: 0.040 K
  same_thermal_steps("power");
  EXPECT_GT(read_doubles(path("serial.h5"), "/meta/thermal_steps").at(0), 300.0);  // measured 354
}

TEST_F(MpirunThermalSolvers, KluAsSerially) {
  // cvode_bdf at rtol = atol = 1e-6 (the defaults), the conductivities 1000 times larger (about 900
  // CVODE steps, 1150 Newton iterations): serial KLU (a direct Newton solve, CVODE's matrix reuse)
  // against PCG preconditioned by MUMPS' exact LU of the current P = I − γJ (at most one Krylov
  // iteration per Newton iteration). The two accept each step once the Newton iteration has converged
  // to 0.1 of the error weights rtol·|T_i| + atol, so they differ by where those iterations stopped
  // (docs/distributed_run.md: the same bound as PCG on both sides): within 0.1 (rtol T_max + atol).
  run_both(kScene, kSteps + kFastConduction + " --set thermal.integrator=cvode_bdf --set thermal.linear_solver=klu", 2);
  if (HasFatalFailure()) return;
  const std::vector<double> T = column("serial.h5", "max_temperature");
  const double top = *std::max_element(T.begin(), T.end());
  const double diff = expect_same_column("max_temperature", 0.1 * (1e-6 * top + 1e-6) / top) * top;
  expect_same_column("thermal_energy_change", 1e-9);
  const double linear = read_doubles(path("split.h5"), "/meta/thermal_linear_iters").at(0);
  const double newton = read_doubles(path("split.h5"), "/meta/thermal_nonlinear_iters").at(0);
  EXPECT_LE(linear, newton);  // the preconditioner solves: at most one Krylov iteration per Newton iteration
  std::printf("  klu: max_temperature %.3g K from the serial run's; %g Krylov iterations in %g Newton iterations\n",
              diff, linear, newton);
}
