// `mpirun -n 2 frictherm run SCENE` (issue 16, "the same command"; coupling/src/distributed_run/,
// coupling/app/cli_run_mpi.cpp) against `frictherm run SCENE` on the same scene:
//   * the 2D sliding block with frictional heating (tests/coupling/scenes/decomposed_sliding_block.json,
//     the scene of test_heat_distributed.cpp): time, kinetic energy, momentum, first- and second-order
//     frictional work, heat delivered and the largest temperature rise agree at every step within 1e-9
//     of each column's largest magnitude (the sliding phase has no chaos: the decomposed step is the
//     serial arithmetic, the sums only change order); the books summed over ranks close to 1e-9 of the
//     work (work received = heat delivered = Σ_i M_i ΔT_i = Σ_p m_p C_p ΔT_p) and the work received
//     equals the serial run's second-order work; the last snapshot, read from the rank files, holds
//     every particle exactly once at the serial position and temperature; the hot spots above a 0.3 K
//     rise, tracked across the ranks, are the serial run's (count, ids, members, birth times exactly;
//     peak, mean, centroid, size and excess energy within 1e-9); issue 32: every serial series column
//     (per-body means, per-pair frictional work, mean velocities, contact heat rates) is in the
//     decomposed series within 1e-9 of its scale, and every serial snapshot field (displacement,
//     initial_position, stress, stress_zz, mass, volume, body, ...) in every rank file, each particle's
//     values within 1e-9 of the field's scale, total mass and volume the serial totals;
//   * the same block with cvode_bdf (PCG) and the serial default window (adaptive, 0.1 K) on 2 and 4
//     ranks, and with the hypre (BoomerAMG) preconditioner on 4: the mechanics series within 1e-12, the
//     temperatures (series and last snapshot) within 0.1 (rtol T_max + atol), the CVODE Newton
//     iteration's stopping test, the same thermal step count (Jacobi); the same with a window every 7
//     steps (every_n_steps) on 2 ranks; books: heat delivered = work
//     received to 1e-12, Σ M ΔT = Σ m C ΔT_p = heat delivered to the round-off of the heat content;
//   * a 3D sliding block without heat (decomposed_sliding_block_3d.json): the same series checks;
//   * the 3D block with heating (decomposed_heated_block_3d.json): series, hot-spot counts, books;
//   * the 2D PBX compaction example (examples/pbx_compaction.json: Mie-Grüneisen/J2 HMX grains, each
//     its own material, in a Mie-Grüneisen binder, rigid boundary walls and a piston, Coulomb contact,
//     second-order heating, its cvode_bdf and adaptive windows, its PIC blend and sub-grid relaxation)
//     made decomposable by --set (no reaction, no continuation) and cut to 0.2 us: the series within
//     1e-9, the temperatures (largest, every particle's at the end) within the CVODE bound above, the
//     books closed;
//   * plastic heating without friction (decomposed_plastic_impact.json: a Mie-Grüneisen/J2 block
//     impact) on 2 and 4 ranks: the series within 1e-9, the plastic heat books within 1e-9 of the heat;
//   * the 3D PBX-like scene (examples/pbx_3d.json) for 40 steps: the series within 1e-9, the books,
//     every particle once in the rank files;
//   * mpirun -n 1 is the serial program (its file layout and the same numbers);
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_mpirun_test_support.hpp"
#include "h5_test_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using namespace frictherm::test;  // exe, scene, shell, Result, read_doubles, read_text, ...
constexpr auto mpirun = mpirun_command;

namespace {

class CliMpirun : public frictherm::test::CliMpirunTest {
 protected:

  // Runs the scene (with `sets`: --set options) serially into serial.h5 (once: kept if it exists) and under
  // mpirun -n `ranks` into split.h5 (replaced).
  void run_both(const char* name, const std::string& sets = "", int ranks = 2) {
    if (!fs::exists(path("serial.h5"))) {
      const Result s = shell(exe() + " run " + scene(name) + sets + " -q --threads 1 -o '" + path("serial.h5") + "'");
      ASSERT_EQ(s.code, 0) << s.output;
    }
    const Result d =
        shell(mpirun(ranks) + " " + exe() + " run " + scene(name) + sets + " --force -o '" + path("split.h5") + "'");
    ASSERT_EQ(d.code, 0) << d.output;
    EXPECT_THAT(d.output, HasSubstr("particles on " + std::to_string(ranks) + " ranks"));
    for (const char* f : {"split.h5", "split.xdmf"}) EXPECT_TRUE(fs::exists(path(f))) << f;
    for (int r = 0; r < ranks; ++r) EXPECT_TRUE(fs::exists(path("split.rank" + std::to_string(r) + ".h5"))) << r;
  }

  // The snapshot `snap` ("/snapshots/NNNNNN/") over the rank files against serial.h5's: how many of the
  // serial particles are held exactly once, the largest position (m) and temperature (K) differences.
  struct SnapshotDifference {
    long once = 0;
    std::size_t particles = 0;
    double dx = 0.0, dT = 0.0;
  };
  SnapshotDifference compare_snapshot(const std::string& snap, int ranks, std::size_t dim = 2) const {
    SnapshotDifference r;
    const std::vector<double> xs = read_doubles(path("serial.h5"), snap + "position");
    const std::vector<double> Ts = read_doubles(path("serial.h5"), snap + "temperature");
    const std::size_t n = Ts.size();
    r.particles = n;
    std::vector<int> seen(n, 0);
    for (int rank = 0; rank < ranks; ++rank) {
      const std::string f = "split.rank" + std::to_string(rank) + ".h5";
      const std::vector<double> id = read_doubles(path(f), snap + "id");
      const std::vector<double> x = read_doubles(path(f), snap + "position");
      const std::vector<double> T = read_doubles(path(f), snap + "temperature");
      EXPECT_EQ(x.size(), dim * id.size()) << f;
      EXPECT_EQ(T.size(), id.size()) << f;
      if (x.size() != dim * id.size() || T.size() != id.size()) return r;
      for (std::size_t k = 0; k < id.size(); ++k) {
        const auto i = static_cast<std::size_t>(id[k]);
        EXPECT_LT(i, n) << f;
        if (i >= n) return r;
        ++seen[i];
        for (std::size_t d = 0; d < dim; ++d) r.dx = std::max(r.dx, std::fabs(x[dim * k + d] - xs[dim * i + d]));
        r.dT = std::max(r.dT, std::fabs(T[k] - Ts[i]));
      }
    }
    r.once = std::count(seen.begin(), seen.end(), 1);
    return r;
  }

  // Every row of `column` in both files within `tolerance` of the serial column's largest magnitude;
  // returns the largest difference relative to that magnitude.
  double expect_same_column(const std::string& column, double tolerance, double offset = 0.0) {
    const std::vector<double> a = read_doubles(path("serial.h5"), "/series/" + column);
    const std::vector<double> b = read_doubles(path("split.h5"), "/series/" + column);
    EXPECT_FALSE(a.empty()) << column;
    EXPECT_EQ(a.size(), b.size()) << column;
    double scale = 0.0, diff = 0.0;
    for (double x : a)
      if (!std::isnan(x)) scale = std::max(scale, std::fabs(x - offset));
    long nan_mismatch = 0;  // NaN (no hot spot) in one file only
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
      if (std::isnan(a[k]) || std::isnan(b[k]))
        nan_mismatch += std::isnan(a[k]) != std::isnan(b[k]);
      else
        diff = std::max(diff, std::fabs(a[k] - b[k]));
    }
    EXPECT_EQ(nan_mismatch, 0) << column;
    EXPECT_GT(scale, 0.0) << column;
    EXPECT_LE(diff, tolerance * scale) << column;
    std::printf("  %-22s max |serial - split| = %.3g of %.6g\n", column.c_str(), diff / scale, scale);
    return diff / scale;
  }

  // Issue 32: every column of the serial series is in the decomposed one (besides its own columns)
  // and agrees within `tolerance` of the column's largest magnitude (a column the serial run keeps at
  // 0: exactly; temperatures relative to their largest rise over 300 K). The per-body means are sums
  // over particles and the per-pair work sums over nodes, the serial kernels' arithmetic in another
  // order, like the columns compared above (~1e-15 of their scale). The one loss is a mean
  // temperature's: Σ m_p T_p / Σ m_p of ~300 K values carries ~ε·300 K·√n round-off, ~1e-12 K, against
  // the base's mean rise of 0.03 K: ~3e-11 of that scale, under the 1e-9 bound by 30. The heat rates
  // (differences of the cumulative work between rows over the row interval) measure ~2e-14.
  void expect_every_serial_column(double tolerance) {
    const std::vector<std::string> split = names_in(path("split.h5"), "/series");
    double worst = 0.0;
    std::string worst_column;
    for (const std::string& c : names_in(path("serial.h5"), "/series")) {
      EXPECT_NE(std::find(split.begin(), split.end(), c), split.end()) << c << " is not in the decomposed series";
      const std::vector<double> a = read_doubles(path("serial.h5"), "/series/" + c);
      const std::vector<double> b = read_doubles(path("split.h5"), "/series/" + c);
      EXPECT_EQ(a.size(), b.size()) << c;
      const double offset = c.find("temperature") != std::string::npos ? 300.0 : 0.0;
      double scale = 0.0, diff = 0.0;
      long nan_mismatch = 0;
      for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
        if (!std::isnan(a[k])) scale = std::max(scale, std::fabs(a[k] - offset));
        if (std::isnan(a[k]) || std::isnan(b[k]))
          nan_mismatch += std::isnan(a[k]) != std::isnan(b[k]);
        else
          diff = std::max(diff, std::fabs(a[k] - b[k]));
      }
      EXPECT_EQ(nan_mismatch, 0) << c;
      EXPECT_LE(diff, tolerance * scale) << c << " (scale " << scale << ")";
      if (scale > 0.0 && diff / scale > worst) worst = diff / scale, worst_column = c;
    }
    std::printf("  every serial series column: largest |serial - split| = %.3g of the column's scale (%s)\n", worst,
                worst_column.c_str());
  }

  // Issue 32: every field of the serial snapshot `snap` is in every rank file, each particle's values
  // (by id) within `tolerance` of the field's largest magnitude, and the total mass and volume over
  // the ranks the serial totals within `tolerance`.
  void expect_every_serial_field(const std::string& snap, int ranks, double tolerance) {
    const std::vector<double> ids = [&] {
      std::vector<double> all;
      for (int r = 0; r < ranks; ++r) {
        const std::vector<double> id = read_doubles(path("split.rank" + std::to_string(r) + ".h5"), snap + "id");
        all.insert(all.end(), id.begin(), id.end());
      }
      return all;
    }();
    const std::size_t n = read_doubles(path("serial.h5"), snap + "mass").size();
    ASSERT_EQ(ids.size(), n);
    for (const std::string& f : names_in(path("serial.h5"), snap)) {
      const std::vector<double> a = read_doubles(path("serial.h5"), snap + f);
      std::vector<double> b;
      for (int r = 0; r < ranks; ++r) {
        const std::string file = path("split.rank" + std::to_string(r) + ".h5");
        EXPECT_THAT(names_in(file, snap), ::testing::Contains(f)) << "rank " << r;
        const std::vector<double> v = read_doubles(file, snap + f);
        b.insert(b.end(), v.begin(), v.end());
      }
      ASSERT_EQ(a.size(), b.size()) << f;
      const std::size_t columns = a.size() / n;
      double scale = 0.0, diff = 0.0, sum_a = 0.0, sum_b = 0.0;
      for (std::size_t k = 0; k < n; ++k)
        for (std::size_t c = 0; c < columns; ++c) {
          const double x = a[static_cast<std::size_t>(ids[k]) * columns + c], y = b[k * columns + c];
          scale = std::max(scale, std::fabs(x));
          diff = std::max(diff, std::fabs(x - y));
          sum_a += x, sum_b += y;
        }
      EXPECT_LE(diff, tolerance * scale) << f;
      if (f == "mass" || f == "volume") {
        EXPECT_NEAR(sum_b, sum_a, tolerance * sum_a) << f;
      }
      std::printf("  snapshot field %-16s max |serial - split| = %.3g of %.6g; sums %.12g / %.12g\n", f.c_str(),
                  scale > 0.0 ? diff / scale : diff, scale, sum_a, sum_b);
    }
  }

  double meta(const std::string& file, const std::string& key) const {
    const std::vector<double> v = read_doubles(path(file), "/meta/" + key);
    return v.empty() ? std::nan("") : v[0];
  }

  // The books over the ranks (J): the work received (above `w_min`) equals the serial run's final
  // second-order frictional work, and the heat delivered and the nodal and particle energy changes
  // equal it, each within `tolerance` of the work.
  void expect_books_closed(double tolerance, double w_min) {
    const double w = meta("split.h5", "work_received");
    const std::vector<double> w2 = read_doubles(path("serial.h5"), "/series/friction_work_second");
    ASSERT_FALSE(w2.empty());
    EXPECT_GT(w, w_min);
    EXPECT_NEAR(w, w2.back(), tolerance * w);
    for (const char* k : {"heat_delivered", "nodal_energy_change", "particle_energy_change"})
      EXPECT_NEAR(meta("split.h5", k), w, tolerance * w) << k;
  }

  // The books of a run whose windows the distributed integrator takes (J): the work received equals the
  // serial run's final second-order work and the heat delivered equals it, both to 1e-12 (sums of the
  // same nodal values in another order); Σ_i M_i ΔT_i and Σ_p m_p C_p ΔT_p equal the heat delivered to
  // the round-off of the heat content, not of the work: the conservative Krylov solve keeps Σ M T
  // exactly but for round-off, and on y = M^{1/2} T of ~300 K every CVODE step rewrites its history
  // (at most 6 vectors of ~|y|) and every window converts T to y and back, each a few ε |T_i| per node,
  // so the bound is 8 ε (thermal steps + windows) Σ_p m_p C_max T_p (`content`, from the last
  // snapshot). Returns |Σ M ΔT − heat delivered| / work.
  double expect_implicit_books_closed(double content) {
    const double w = meta("split.h5", "work_received"), q = meta("split.h5", "heat_delivered");
    const std::vector<double> w2 = read_doubles(path("serial.h5"), "/series/friction_work_second");
    EXPECT_FALSE(w2.empty());
    EXPECT_GT(w, 0.0);
    if (w2.empty() || !(w > 0.0)) return 0.0;
    EXPECT_NEAR(w, w2.back(), 1e-12 * w);
    EXPECT_NEAR(q, w, 1e-12 * w);
    const double windows = meta("split.h5", "thermal_windows"), steps = meta("split.h5", "thermal_steps");
    const double bound = 8.0 * (steps + windows) * 2.220446049250313e-16 * content;
    const double nodal = meta("split.h5", "nodal_energy_change"), particle = meta("split.h5", "particle_energy_change");
    EXPECT_NEAR(nodal, q, bound);
    EXPECT_NEAR(particle, q, bound);
    std::printf("  books: |heat delivered - work| = %.3g, |sum M dT - heat delivered| = %.3g, |sum m C dT_p - heat "
                "delivered| = %.3g of the work (bound %.3g: %g windows, %g steps)\n",
                std::fabs(q - w) / w, std::fabs(nodal - q) / w, std::fabs(particle - q) / w, bound / w, windows, steps);
    return std::fabs(nodal - q) / w;
  }

  // Σ_p m_p T_p C_max over serial.h5's snapshot `snap` (J): a bound of the heat content Σ_p m_p C_p T_p.
  double content_bound(const std::string& snap, double c_max) const {
    const std::vector<double> m = read_doubles(path("serial.h5"), snap + "mass");
    const std::vector<double> T = read_doubles(path("serial.h5"), snap + "temperature");
    double e = 0.0;
    for (std::size_t k = 0; k < std::min(m.size(), T.size()); ++k) e += m[k] * c_max * T[k];
    return e;
  }

  // A heated sliding block whose windows cvode_bdf takes, against the serial run of the same scene
  // (`rtol`, `atol` its tolerances): the mechanics series (the heat does not act on the mechanics) within
  // 1e-12 of each column's largest magnitude; the series' largest temperature and the last snapshot's
  // particle temperatures within 0.1 (rtol T_max + atol): CVODE accepts a step once its Newton
  // iteration has converged to 0.1 of the error weights rtol |T_i| + atol (the nonlinear convergence
  // coefficient) and its Krylov solves to 0.05 of that, so two runs that take the same steps (the same
  // count: `same_steps`) differ by where those iterations stopped, below 0.1 weight per node; every
  // window assembled; the books closed. `snap`: the last snapshot, of `particles` particles in `dim` D.
  // Returns the temperature difference (K).
  double expect_cvode_run_as_serial(int ranks, double rtol, double atol, double c_max, bool same_steps,
                                    const std::string& snap = "/snapshots/000004/", std::size_t particles = 512,
                                    std::size_t dim = 2) {
    for (const char* c : {"time", "kinetic_energy", "momentum_x", "momentum_y", "friction_work_first",
                          "friction_work_second", "heat_delivered", "thermal_windows"})
      expect_same_column(c, 1e-12);
    const double windows = meta("split.h5", "thermal_windows"), steps = meta("split.h5", "steps");
    EXPECT_GT(windows, 1.0);
    EXPECT_LT(windows, steps) << "the windows span several steps";
    EXPECT_EQ(meta("split.h5", "thermal_assembled_windows"), windows);
    EXPECT_EQ(meta("serial.h5", "thermal_windows"), windows);
    if (same_steps) {
      EXPECT_EQ(meta("split.h5", "thermal_steps"), meta("serial.h5", "thermal_steps"));
    }
    const std::vector<double> Tmax = read_doubles(path("serial.h5"), "/series/max_temperature");
    EXPECT_FALSE(Tmax.empty());
    if (Tmax.empty()) return 0.0;
    const double T_max = *std::max_element(Tmax.begin(), Tmax.end()), rise = T_max - 300.0;
    const double tolerance = 0.1 * (rtol * T_max + atol);  // K
    expect_same_column("max_temperature", tolerance / rise, 300.0);  // relative to the largest rise
    const SnapshotDifference d = compare_snapshot(snap, ranks, dim);
    EXPECT_EQ(d.particles, particles);
    EXPECT_EQ(d.once, static_cast<long>(d.particles));
    EXPECT_LE(d.dx, 1e-12 * 1e-3);  // of the 1 mm cell
    EXPECT_LE(d.dT, tolerance);
    std::printf("  %d ranks: last snapshot temperatures %.3g K from the serial run (bound %.3g K, rise %.3g K); "
                "thermal steps %g / serial %g, %g windows over %g steps\n",
                ranks, d.dT, tolerance, rise, meta("split.h5", "thermal_steps"), meta("serial.h5", "thermal_steps"),
                windows, steps);
    expect_implicit_books_closed(content_bound(snap, c_max));
    return d.dT;
  }
};

}  // namespace

TEST_F(CliMpirun, SlidingBlockWithHeatingEqualsTheSerialRun) {
  run_both("decomposed_sliding_block.json");
  if (HasFatalFailure()) return;
  constexpr double kTol = 1e-9;
  expect_same_column("time", kTol);
  for (const char* c : {"kinetic_energy", "momentum_x", "momentum_y", "friction_work_first", "friction_work_second",
                        "heat_delivered", "thermal_windows"})
    expect_same_column(c, kTol);
  expect_same_column("max_temperature", kTol, 300.0);  // relative to the largest rise (≈ 0.79 K)
  // Hot spots above a 0.3 K rise, tracked across the ranks: the series columns and the /hotspots table.
  expect_same_column("hotspot_count", 0.0);
  expect_same_column("hottest_hotspot_temperature", kTol, 300.0);
  expect_same_column("hottest_hotspot_size", kTol);
  for (const char* c : {"time", "id", "particle_count", "birth_time"}) {
    const std::vector<double> a = read_doubles(path("serial.h5"), std::string("/hotspots/") + c);
    EXPECT_FALSE(a.empty()) << c << ": the scene makes hot spots";
    EXPECT_EQ(a, read_doubles(path("split.h5"), std::string("/hotspots/") + c)) << c;
  }
  for (const char* c : {"peak_temperature", "mean_temperature", "centroid_x", "centroid_y", "excess_energy"}) {
    const std::vector<double> a = read_doubles(path("serial.h5"), std::string("/hotspots/") + c);
    const std::vector<double> b = read_doubles(path("split.h5"), std::string("/hotspots/") + c);
    ASSERT_EQ(a.size(), b.size()) << c;
    double scale = 0.0, diff = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      scale = std::max(scale, std::fabs(a[k] - (std::string(c).find("temperature") != std::string::npos ? 300.0 : 0.0)));
      diff = std::max(diff, std::fabs(a[k] - b[k]));
    }
    EXPECT_LE(diff, kTol * scale) << c;
    std::printf("  /hotspots/%-18s max |serial - split| = %.3g of %.6g (%zu rows)\n", c, diff / scale, scale, a.size());
  }
  // Books over both ranks (J), relative to the work received.
  expect_books_closed(kTol, 0.1);
  if (HasFatalFailure()) return;
  // The last snapshot over the rank files: every particle once, at the serial position and temperature.
  const SnapshotDifference d = compare_snapshot("/snapshots/000004/", 2);
  EXPECT_EQ(d.particles, 512u);
  EXPECT_EQ(d.once, static_cast<long>(d.particles));
  EXPECT_LE(d.dx, kTol * 1e-3);  // of the 1 mm cell
  EXPECT_LE(d.dT, kTol * 0.79);  // of the largest temperature rise
  std::printf("  last snapshot: positions %.3g m, temperatures %.3g K from the serial run\n", d.dx, d.dT);
  expect_every_serial_column(kTol);
  expect_every_serial_field("/snapshots/000004/", 2, kTol);
}

// The same block with the serial run's default window (adaptive: a window closes once the pending heat
// would raise some node by 0.1 K, and at every snapshot) and cvode_bdf on the assembled rows (PCG with
// the Jacobi preconditioner on both sides: the serial default KLU has no decomposed counterpart), on 2
// and 4 ranks (oversubscribed).
const char* const kCvodeAdaptive =
    " --set thermal.integrator=cvode_bdf --set thermal.linear_solver=pcg --set thermal.rtol=1e-6"
    " --set thermal.atol=1e-6 --set coupling.window=adaptive";

TEST_F(CliMpirun, HeatedBlockWithCvodeAndAdaptiveWindowsEqualsTheSerialRun) {
  for (int ranks : {2, 4}) {
    run_both("decomposed_sliding_block.json", kCvodeAdaptive, ranks);
    if (HasFatalFailure()) return;
    expect_cvode_run_as_serial(ranks, 1e-6, 1e-6, 150.0, true);  // the block's C = 150 J/(kg K) is the larger
  }
}

// A window every 7 steps (coupling.window every_n_steps) with cvode_bdf on 2 ranks: the same checks.
TEST_F(CliMpirun, HeatedBlockWithEveryNStepsWindowsEqualsTheSerialRun) {
  run_both("decomposed_sliding_block.json",
           std::string(kCvodeAdaptive) + " --set 'coupling.window={\"policy\":\"every_n_steps\",\"steps\":7}'", 2);
  if (HasFatalFailure()) return;
  expect_cvode_run_as_serial(2, 1e-6, 1e-6, 150.0, true);
}

// The same with BoomerAMG (thermal.preconditioner "hypre") preconditioning the decomposed Krylov solves,
// against the serial Jacobi-preconditioned run: other Krylov iterates, the same bound.
TEST_F(CliMpirun, HeatedBlockWithHyprePreconditionerEqualsTheSerialRun) {
  run_both("decomposed_sliding_block.json", std::string(kCvodeAdaptive) + " --set thermal.preconditioner=hypre", 4);
  if (HasFatalFailure()) return;
  expect_cvode_run_as_serial(4, 1e-6, 1e-6, 150.0, false);
}

TEST_F(CliMpirun, ThreeDimensionalSlidingBlockEqualsTheSerialRun) {
  run_both("decomposed_sliding_block_3d.json");
  if (HasFatalFailure()) return;
  for (const char* c : {"time", "kinetic_energy", "momentum_x", "momentum_y", "friction_work_first", "friction_work_second"})
    expect_same_column(c, 1e-9);
}

// The 3D block with frictional heating and conduction every step: the series, the hot spots and
// the books as the 2D case (the interface warms by a fraction of a kelvin).
TEST_F(CliMpirun, ThreeDimensionalHeatedSlidingBlockEqualsTheSerialRun) {
  run_both("decomposed_heated_block_3d.json");
  if (HasFatalFailure()) return;
  constexpr double kTol = 1e-9;
  for (const char* c : {"time", "kinetic_energy", "momentum_x", "momentum_y", "friction_work_first",
                        "friction_work_second", "heat_delivered", "thermal_windows"})
    expect_same_column(c, kTol);
  expect_same_column("max_temperature", kTol, 300.0);  // relative to the largest rise
  expect_same_column("hotspot_count", 0.0);
  expect_books_closed(kTol, 0.0);
}

// The 3D block with cvode_bdf (PCG) and adaptive windows on 2 ranks: as the 2D case (the assembled rows of
// a 3D stencil: up to 125 columns, summed over the ranks).
TEST_F(CliMpirun, ThreeDimensionalHeatedBlockWithCvodeEqualsTheSerialRun) {
  run_both("decomposed_heated_block_3d.json", kCvodeAdaptive, 2);
  if (HasFatalFailure()) return;
  expect_cvode_run_as_serial(2, 1e-6, 1e-6, 150.0, true, "/snapshots/000003/", 2048, 3);
}

// The PBX specimen of Nairn et al. 2018 (examples/pbx_compaction.json) with the overrides that make it
// decomposable (no reaction, no continuation, no sub-cell interface temperature; its FLIP/PIC blend, its sub-grid relaxation, its cvode_bdf
// with PCG at rtol 1e-8 and its adaptive windows run as they are), for 0.2 us of compaction (about 360 steps
// at the Mie-Grüneisen CFL step: the piston has moved 0.6 nm, the grains touch the walls and each other,
// no chaos yet): the time steps (each particle's current wave speed counts, as in the serial run),
// kinetic energy and momentum of the deformable particles, frictional work and heat delivered agree
// with the serial run within 1e-9; the largest temperature (≈ 9 mK above 293.15 K at the walls) and
// every particle's at the end within 0.1 (rtol T_max + atol) (expect_cvode_run_as_serial: the same
// thermal steps); the books closed.
TEST_F(CliMpirun, PbxCompactionEqualsTheSerialRun) {
  const std::string sets =
      " --set thermal.reaction=null --set coupling.continuation=null --set coupling.interface_temperature=null"
      " --set run.end_time=2e-7 --set output.series_interval=null"
      " --set output.snapshot_count=1";
  const std::string pbx = std::string("'") + FRICTHERM_SOURCE_DIR + "/examples/pbx_compaction.json'" + sets;
  const Result s = shell(exe() + " run " + pbx + " -q --threads 1 -o '" + path("serial.h5") + "'");
  ASSERT_EQ(s.code, 0) << s.output;
  const Result d = shell(mpirun(2) + " " + exe() + " run " + pbx + " -o '" + path("split.h5") + "'");
  ASSERT_EQ(d.code, 0) << d.output;
  EXPECT_THAT(d.output, HasSubstr("particles on 2 ranks"));
  constexpr double kTol = 1e-9;
  EXPECT_GT(read_doubles(path("serial.h5"), "/series/time").size(), 300u) << "a row every step";
  for (const char* c : {"time", "dt", "kinetic_energy", "momentum_x", "momentum_y", "friction_work_first",
                        "friction_work_second", "heat_delivered", "thermal_windows"})
    expect_same_column(c, kTol);
  EXPECT_EQ(meta("split.h5", "thermal_assembled_windows"), meta("serial.h5", "thermal_windows"));
  EXPECT_EQ(meta("split.h5", "thermal_steps"), meta("serial.h5", "thermal_steps"));
  const std::vector<double> Tmax = read_doubles(path("serial.h5"), "/series/max_temperature");
  ASSERT_FALSE(Tmax.empty());
  const double T0 = Tmax.front(), T_max = *std::max_element(Tmax.begin(), Tmax.end());  // 293.15 K, ≈ +9 mK
  ASSERT_GT(T_max, T0);
  const double tolerance = 0.1 * (1e-8 * T_max + 1e-6);  // K: the example's rtol, atol
  expect_same_column("max_temperature", tolerance / (T_max - T0), T0);
  // Every particle at the end, over both rank files: the sub-grid relaxation (τ = 1.6 us) moves them by up
  // to 8e-5 K (the serial run without it), the largest temperature by 1.3e-5 K, both beyond the bound.
  const SnapshotDifference snap = compare_snapshot("/snapshots/000001/", 2);
  EXPECT_EQ(snap.particles, 15376u);
  EXPECT_EQ(snap.once, static_cast<long>(snap.particles));
  EXPECT_LE(snap.dT, tolerance);
  std::printf("  last snapshot: temperatures %.3g K from the serial run (bound %.3g K)\n", snap.dT, tolerance);
  expect_implicit_books_closed(content_bound("/snapshots/000001/", 2280.0));  // the binder's C is the largest
}

// The 3D PBX-like scene (examples/pbx_3d.json: 17 ellipsoidal HMX grains, binder, five rigid walls
// and a piston, 85,184 particles) for its first 40 steps (21 ns: the piston's wave crosses the binder
// and reaches the first grains): the series within 1e-9 of the serial run, the books closed to 1e-9,
// and the last snapshot over both rank files holds every particle once.
TEST_F(CliMpirun, Pbx3dSceneEqualsTheSerialRun) {
  const std::string pbx = std::string("'") + FRICTHERM_SOURCE_DIR + "/examples/pbx_3d.json'" +
                          " --set run.max_steps=40 --set output.series_interval=null --set output.snapshot_count=1";
  const Result s = shell(exe() + " run " + pbx + " -q --threads 1 -o '" + path("serial.h5") + "'");
  ASSERT_EQ(s.code, 0) << s.output;
  const Result d = shell(mpirun(2) + " " + exe() + " run " + pbx + " -q -o '" + path("split.h5") + "'");
  ASSERT_EQ(d.code, 0) << d.output;
  constexpr double kTol = 1e-9;
  EXPECT_EQ(read_doubles(path("serial.h5"), "/series/time").size(), 41u) << "a row every step";
  for (const char* c : {"time", "dt", "kinetic_energy", "momentum_z", "friction_work_first", "friction_work_second",
                        "heat_delivered"})
    expect_same_column(c, kTol);
  expect_same_column("max_temperature", kTol, 300.0);
  const double w = meta("split.h5", "work_received");
  EXPECT_GT(w, 0.0);
  for (const char* k : {"heat_delivered", "nodal_energy_change", "particle_energy_change"})
    EXPECT_NEAR(meta("split.h5", k), w, kTol * w) << k;
  const std::string snap = "/snapshots/000001/id";  // at the stop (step 40)
  std::vector<int> seen(85184, 0);
  for (const char* f : {"split.rank0.h5", "split.rank1.h5"})
    for (double id : read_doubles(path(f), snap)) {
      ASSERT_LT(id, 85184.0);
      ++seen[static_cast<std::size_t>(id)];
    }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), 85184L);
}

// Plastic heating without friction (decomposed_plastic_impact.json: a Mie-Grüneisen/J2 block thrown onto
// a rigid wall, β = 0.9, matrix-free forward Euler): on 2 ranks with a window every 5 steps and on 4 with
// adaptive windows (0.5 K of pending rise: the plastic heat's estimate over every node holding heat),
// the series (time steps, kinetic energy, momentum, plastic work and heat, heat delivered, windows,
// largest temperature rise) within 1e-9 of the serial run (the decomposed step is the serial arithmetic,
// sums in another order); the books over the ranks: plastic heat = β × plastic work received to 1e-12
// (the shares of one particle sum to β Δw_p but for round-off), the plastic work the serial run's, no
// frictional work, and the plastic heat delivered, the heat delivered, Σ_i M_i ΔT_i and Σ_p m_p C_p ΔT_p
// equal to the plastic heat within 1e-9 of it (adiabatic edges: conduction moves heat, keeps it); the last
// snapshot holds every particle once at the serial position and temperature.
TEST_F(CliMpirun, PlasticImpactEqualsTheSerialRun) {
  const std::pair<int, std::string> runs[] = {
      {2, ""}, {4, " --set 'coupling.window={\"policy\":\"adaptive\",\"max_temperature_rise\":0.5}'"}};
  for (const auto& [ranks, sets] : runs) {
    fs::remove(path("serial.h5"));
    run_both("decomposed_plastic_impact.json", sets, ranks);
    if (HasFatalFailure()) return;
    constexpr double kTol = 1e-9;
    for (const char* c : {"time", "dt", "kinetic_energy", "momentum_x", "momentum_y", "plastic_work", "plastic_heat",
                          "heat_delivered", "thermal_windows"})
      expect_same_column(c, kTol);
    expect_same_column("max_temperature", kTol, 300.0);  // relative to the largest rise
    const double windows = meta("split.h5", "thermal_windows");
    EXPECT_EQ(meta("serial.h5", "thermal_windows"), windows);
    EXPECT_GT(windows, 2.0);
    const double wp = meta("split.h5", "plastic_work_received"), P = meta("split.h5", "plastic_heat_received");
    EXPECT_GT(wp, 0.0) << "the block yields";
    EXPECT_NEAR(wp, read_doubles(path("serial.h5"), "/series/plastic_work").back(), kTol * wp);
    EXPECT_NEAR(P, 0.9 * wp, 1e-12 * wp);
    EXPECT_EQ(meta("split.h5", "work_received"), 0.0);
    for (const char* k : {"plastic_heat_delivered", "heat_delivered", "nodal_energy_change", "particle_energy_change"})
      EXPECT_NEAR(meta("split.h5", k), P, kTol * P) << k;
    const std::vector<double> Tmax = read_doubles(path("serial.h5"), "/series/max_temperature");
    ASSERT_FALSE(Tmax.empty());
    const double rise = *std::max_element(Tmax.begin(), Tmax.end()) - 300.0;
    ASSERT_GT(rise, 0.0);
    const SnapshotDifference d = compare_snapshot("/snapshots/000002/", ranks);
    EXPECT_GT(d.particles, 0u);
    EXPECT_EQ(d.once, static_cast<long>(d.particles));
    EXPECT_LE(d.dx, kTol * 2e-4);  // of the 0.2 mm cell
    EXPECT_LE(d.dT, kTol * rise);
    std::printf("  %d ranks, %g windows: plastic work %.9g J, heat %.9g J (T rise %.3g K); |Q - P| = %.3g, "
                "|sum M dT - P| = %.3g, |sum m C dT_p - P| = %.3g of P; snapshot dT %.3g K\n",
                ranks, windows, wp, P, rise, std::fabs(meta("split.h5", "heat_delivered") - P) / P,
                std::fabs(meta("split.h5", "nodal_energy_change") - P) / P,
                std::fabs(meta("split.h5", "particle_energy_change") - P) / P, d.dT);
  }
}

TEST_F(CliMpirun, OneRankRunsTheSerialProgram) {
  // mpirun -n 1: today's serial program (one file with its snapshots, no rank files), the same numbers.
  const std::string sc = scene("decomposed_sliding_block_3d.json") + " -q --set run.end_time=5e-5";
  const Result s = shell(exe() + " run " + sc + " --threads 1 -o '" + path("serial.h5") + "'");
  const Result d = shell(mpirun(1) + " " + exe() + " run " + sc + " --threads 1 -o '" + path("one.h5") + "'");
  ASSERT_EQ(s.code, 0) << s.output;
  ASSERT_EQ(d.code, 0) << d.output;
  EXPECT_FALSE(fs::exists(path("one.rank0.h5")));
  EXPECT_FALSE(read_doubles(path("one.h5"), "/snapshots/000000/position").empty());
  for (const char* c : {"time", "kinetic_energy", "friction_work_second"}) {
    const std::vector<double> a = read_doubles(path("serial.h5"), std::string("/series/") + c);
    EXPECT_FALSE(a.empty()) << c;
    EXPECT_EQ(a, read_doubles(path("one.h5"), std::string("/series/") + c)) << c;
  }
}
