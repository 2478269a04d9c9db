// Fixed-temperature faces in a decomposed run (issue 32; scene key thermal.fixed_temperature,
// DecomposedHeat with the serial face rule for_each_fixed_node, fixed_temperature.hpp): `mpirun -n K
// frictherm run` against `frictherm run` on the heated sliding block of test_cli_mpirun.cpp
// (tests/coupling/scenes/decomposed_sliding_block.json) with the grid cut at x = 25 mm, the base's right
// edge, so that two faces hold unknowns: y_min at 310 K (the base's bottom, across every rank's part)
// and x_max at 290 K (the base's right edge, on the last rank only; the corner node lies on both and
// takes the later face's 290 K). Checked:
//   * matrix-free forward Euler (the scene's) on 2 and 3 ranks, and the assembled rows (forward Euler
//     on the distributed problem, thermal.matrix_free_max_substeps = 0) on 2: the largest temperature
//     (relative to the largest rise |T − 300 K|), the thermal energy change, the heat delivered and the
//     kinetic energy at every step, every particle's temperature in every snapshot (by id) and the
//     books Σ_i M_i ΔT_i, Σ_p m_p C_p ΔT_p within 1e-9 of their scale;
//   * that the faces act in both runs: the heat conducted in through y_min makes Σ_i M_i ΔT_i more than
//     10 times the frictional work, particles at the bottom warm toward 310 K and those at the right
//     edge cool below 300 K. A face ignored on one rank leaves its particles there at ~300 K (a
//     difference of ~10 K, 0.4 of the 23 K scale).
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gtest/gtest.h>

#include "mpirun_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

// 1e-9 of each quantity's scale: the decomposed window is the serial arithmetic with the nodal and
// particle sums split between the ranks (another summation order; measured ≤ 5.3e-14 of the 22.9 K
// rise, ≤ 5.2e-13 of the thermal energy change: docs/distributed_thermal.md), while a face missing on
// one rank changes its particles by ~10 K (0.4 of the scale).
constexpr double kSame = 1e-9;

const char* const kScene = "tests/coupling/scenes/decomposed_sliding_block.json";
const char* const kFaces =
    " --set 'grid.hi=[0.025,0.012]'"
    " --set 'thermal.fixed_temperature=[{\"face\":\"y_min\",\"temperature\":310},{\"face\":\"x_max\",\"temperature\":290}]'";

class MpirunFixedTemperature : public frictherm::test::MpirunCompare {
 protected:
  // Largest |a − b| over the rows against the serial column's largest |a − offset|; checked and printed.
  void expect_same(const std::string& what, const std::vector<double>& a, const std::vector<double>& b,
                   double offset) const {
    ASSERT_FALSE(a.empty()) << what;
    ASSERT_EQ(a.size(), b.size()) << what;
    double scale = 0.0, diff = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      scale = std::max(scale, std::fabs(a[k] - offset));
      diff = std::max(diff, std::fabs(a[k] - b[k]));
    }
    EXPECT_GT(scale, 0.0) << what;
    EXPECT_LE(diff, kSame * scale) << what;
    std::printf("  %-34s max |serial - split| = %.3g of %.6g\n", what.c_str(), diff / scale, scale);
  }

  double meta(const std::string& file, const std::string& key) const {
    const std::vector<double> v = frictherm::test::read_doubles(path(file), "/meta/" + key);
    return v.empty() ? std::nan("") : v[0];
  }

  // serial.h5 against split.h5 (written on `ranks` ranks).
  void compare(int ranks) {
    using frictherm::test::read_doubles;
    expect_same("max_temperature", column("serial.h5", "max_temperature"), column("split.h5", "max_temperature"), 300.0);
    for (const char* c : {"thermal_energy_change", "heat_delivered", "kinetic_energy"})
      expect_same(c, column("serial.h5", c), column("split.h5", c), 0.0);
    for (const char* k : {"nodal_energy_change", "particle_energy_change", "heat_delivered"})
      expect_same(std::string("/meta/") + k, {meta("serial.h5", k)}, {meta("split.h5", k)}, 0.0);
    // Every snapshot's temperatures, the particles of the rank files put in the serial order by id.
    for (int s = 0; s <= 4; ++s) {
      char snap[32];
      std::snprintf(snap, sizeof snap, "/snapshots/%06d/", s);
      const std::vector<double> Ts = read_doubles(path("serial.h5"), snap + std::string("temperature"));
      ASSERT_EQ(Ts.size(), 512u) << snap;
      std::vector<double> T(Ts.size(), std::nan(""));
      for (int r = 0; r < ranks; ++r) {
        const std::string f = "split.rank" + std::to_string(r) + ".h5";
        const std::vector<double> id = read_doubles(path(f), snap + std::string("id"));
        const std::vector<double> t = read_doubles(path(f), snap + std::string("temperature"));
        ASSERT_EQ(id.size(), t.size()) << f << snap;
        for (std::size_t k = 0; k < id.size(); ++k) T.at(static_cast<std::size_t>(id[k])) = t[k];
      }
      for (double x : T) ASSERT_FALSE(std::isnan(x)) << snap << ": a particle missing from the rank files";
      if (s > 0) expect_same(std::string(snap) + "temperature", Ts, T, 300.0);
    }
    // The faces act: heat conducted in through y_min, the bottom warmed, the right edge cooled.
    const double work = meta("split.h5", "work_received");
    EXPECT_GT(meta("split.h5", "nodal_energy_change"), 10.0 * work);
    const std::vector<double> x = read_doubles(path("serial.h5"), "/snapshots/000004/position");
    const std::vector<double> Ts = read_doubles(path("serial.h5"), "/snapshots/000004/temperature");
    double bottom = 0.0, right = 1e300;
    for (std::size_t k = 0; k < Ts.size(); ++k) {
      if (x[2 * k + 1] < 5e-4 && x[2 * k] < 0.005) bottom = std::max(bottom, Ts[k]);  // rank 0's part
      if (x[2 * k] > 0.0245) right = std::min(right, Ts[k]);                          // the last rank's
    }
    EXPECT_GT(bottom, 305.0);
    EXPECT_LT(right, 295.0);
  }
};

TEST_F(MpirunFixedTemperature, MatrixFreeWindowsOnTwoAndThreeRanksEqualTheSerialRun) {
  for (const int ranks : {2, 3}) {
    run_both(kScene, kFaces, ranks);
    if (HasFatalFailure()) return;
    std::printf("  matrix-free forward Euler, %d ranks:\n", ranks);
    EXPECT_EQ(meta("split.h5", "thermal_matrix_free_substeps"), meta("serial.h5", "thermal_matrix_free_substeps"));
    EXPECT_EQ(meta("split.h5", "thermal_assembled_windows"), 0.0);
    compare(ranks);
  }
}

TEST_F(MpirunFixedTemperature, AssembledWindowsEqualTheSerialRun) {
  run_both(kScene, std::string(kFaces) + " --set thermal.matrix_free_max_substeps=0", 2);
  if (HasFatalFailure()) return;
  std::printf("  assembled forward Euler, 2 ranks:\n");
  EXPECT_EQ(meta("split.h5", "thermal_assembled_windows"), meta("serial.h5", "thermal_windows"));
  EXPECT_EQ(meta("split.h5", "thermal_steps"), meta("serial.h5", "thermal_steps"));  // the same stable sub-steps
  compare(2);
}

}  // namespace
