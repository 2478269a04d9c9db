// The sub-cell interface temperature in a decomposed run (issue 32; coupling.interface_temperature,
// decomposed_interface.cpp): `mpirun -n 2 frictherm run` against `frictherm run --threads 1` on the PBX
// specimen (examples/pbx_compaction.json) shortened to 0.2 us of compaction (about 360 steps) and
// 1 us of conduction alone in 4 intervals, without its reaction (thermal.reaction: serial only). Its
// FLIP/PIC blend, sub-grid relaxation, cvode_bdf (PCG, rtol 1e-8) and adaptive windows as written.
// The interface temperature T_int,i = T_i + Σ (flux history ⊛ R_x) of every heated node: each rank
// keeps the histories of its owned nodes; the per-material sums of pass 1 are completed at the owners;
// particles read the ghosted corrections. Checked against the serial run:
//   * the series column max_interface_temperature every row (loading and continuation);
//   * the snapshot field interface_temperature of every particle (by id over both rank files) at the
//     end of loading and at the continuation's end;
//   * with hot spots judged by the interface temperature (coupling.hotspots.temperature "interface", a
//     threshold the interface reaches and the grid does not): the hot-spot columns and /hotspots rows;
//   * the books: the histories received the frictional work (metadata interface_heat_recorded);
//   * with patch_length (hot spots of a given size), the patches and the single node's column.
// Tolerance: T_int = T_i + correction. The correction is the serial arithmetic on the same histories
// (the steps' work to ~1e-13 of its scale, another summation order of pass 1's sums); T_i comes from
// CVODE with PCG on both sides, converged to 0.1 of the error weights rtol |T| + atol (test_cli_mpirun.cpp,
// PbxCompactionEqualsTheSerialRun): bound 0.1 (rtol T_max + atol) + 1e-9 of the largest correction.
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gtest/gtest.h>

#include "mpirun_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using frictherm::test::read_doubles;

const char* const kScene = "examples/pbx_compaction.json";
const char* const kSets =
    " --set thermal.reaction=null --set run.end_time=2e-7 --set output.series_interval=null"
    " --set output.snapshot_count=1 --set 'coupling.continuation={\"duration\":1e-6,\"intervals\":4}'";
constexpr double kT0 = 293.15;  // K, the specimen's initial temperature
constexpr double kRtol = 1e-8, kAtol = 1e-6;  // the example's thermal.rtol and the default atol (K)

class MpirunInterface : public frictherm::test::MpirunCompare {
 protected:
  double meta(const std::string& file, const std::string& key) const {
    const std::vector<double> v = read_doubles(path(file), "/meta/" + key);
    return v.empty() ? std::nan("") : v[0];
  }

  // The snapshot's `field` of every particle over both rank files, in the serial order (by id).
  std::vector<double> split_field(const std::string& snap, const std::string& field, std::size_t count) const {
    std::vector<double> out(count, std::nan(""));
    long seen = 0;
    for (int r = 0; r < 2; ++r) {
      const std::string f = "split.rank" + std::to_string(r) + ".h5";
      const std::vector<double> id = read_doubles(path(f), snap + "id");
      const std::vector<double> v = read_doubles(path(f), snap + field);
      EXPECT_EQ(id.size(), v.size()) << f << " " << field;
      for (std::size_t k = 0; k < std::min(id.size(), v.size()); ++k) {
        EXPECT_TRUE(std::isnan(out.at(static_cast<std::size_t>(id[k])))) << "particle " << id[k] << " twice";
        out.at(static_cast<std::size_t>(id[k])) = v[k];
        ++seen;
      }
    }
    EXPECT_EQ(seen, static_cast<long>(count)) << snap;
    return out;
  }

  // Largest |serial − split| of a temperature-like series (NaN rows equal in both); returns it in K.
  double max_difference(const std::vector<double>& a, const std::vector<double>& b, const std::string& what) const {
    EXPECT_FALSE(a.empty()) << what;
    EXPECT_EQ(a.size(), b.size()) << what;
    double diff = 0.0;
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
      if (std::isnan(a[k]) || std::isnan(b[k])) {
        EXPECT_TRUE(std::isnan(a[k]) && std::isnan(b[k])) << what << " row " << k;
        continue;
      }
      diff = std::max(diff, std::fabs(a[k] - b[k]));
    }
    return diff;
  }

  // Everything above.
  void compare() {
    const std::vector<double> Tint = column("serial.h5", "max_interface_temperature");
    ASSERT_GT(Tint.size(), 300u) << "a row every step";
    double t_int_rise = 0.0, rise = 0.0;
    for (double t : Tint)
      if (!std::isnan(t)) t_int_rise = std::max(t_int_rise, t - kT0);
    for (double t : read_doubles(path("serial.h5"), "/snapshots/000001/temperature")) rise = std::max(rise, t - kT0);
    // The interface model acts: its hottest node is well above the grid's hottest particle at the end
    // of loading (0.24 K against 9 mK).
    EXPECT_GT(t_int_rise, 10.0 * rise);
    const double bound = 0.1 * (kRtol * (kT0 + t_int_rise) + kAtol) + 1e-9 * t_int_rise;
    const double series = max_difference(Tint, column("split.h5", "max_interface_temperature"), "series");
    EXPECT_LE(series, bound);
    std::printf("  max_interface_temperature: %.3g K from the serial run (rise %.4g K, grid rise %.3g K; bound %.3g K)\n",
                series, t_int_rise, rise, bound);
    for (const char* snap : {"/snapshots/000001/", "/snapshots/000002/"}) {
      const std::vector<double> a = read_doubles(path("serial.h5"), std::string(snap) + "interface_temperature");
      ASSERT_EQ(a.size(), 15376u) << snap;
      const std::vector<double> b = split_field(snap, "interface_temperature", a.size());
      const std::vector<double> T = read_doubles(path("serial.h5"), std::string(snap) + "temperature");
      double correction = 0.0;
      for (std::size_t k = 0; k < a.size(); ++k) correction = std::max(correction, a[k] - T[k]);
      EXPECT_GT(correction, 0.0) << snap;
      const double d = max_difference(a, b, snap);
      EXPECT_LE(d, bound) << snap;
      std::printf("  %s interface_temperature: %.3g K from the serial run (largest correction %.4g K)\n", snap, d,
                  correction);
    }
    // The books: every joule of frictional work entered some rank's histories once.
    const double work = meta("split.h5", "work_received");
    EXPECT_GT(work, 0.0);
    EXPECT_NEAR(meta("split.h5", "interface_heat_recorded"), work, 1e-12 * work);
    EXPECT_NEAR(meta("split.h5", "heat_delivered"), work, 1e-12 * work);
    EXPECT_EQ(meta("split.h5", "thermal_continuation_intervals"), 4.0);
  }
};

// The interface temperature of the PBX specimen, hot spots judged by the grid temperature (as written).
TEST_F(MpirunInterface, PbxInterfaceTemperatureEqualsTheSerialRun) {
  run_both(kScene, kSets, 2);
  if (HasFatalFailure()) return;
  compare();
}

// Hot spots of a given size (patch_length 16 um, four cells): each node reports the patch of the
// heated nodes within 8 um, which straddle the ranks' boundary where the interface crosses it (every
// rank's heated nodes are gathered, decomposed_interface.cpp). The patch columns, the particles'
// interface temperatures (the patch corrections) and the single node's column
// max_node_interface_temperature equal the serial run's within the bound of compare().
TEST_F(MpirunInterface, PbxInterfacePatchesEqualTheSerialRun) {
  run_both(kScene, std::string(kSets) + " --set 'coupling.interface_temperature={\"patch_length\":16e-6}'", 2);
  if (HasFatalFailure()) return;
  compare();
  const std::vector<double> node = column("serial.h5", "max_node_interface_temperature");
  const std::vector<double> patch = column("serial.h5", "max_interface_temperature");
  ASSERT_EQ(node.size(), patch.size());
  double node_rise = 0.0, patch_rise = 0.0;
  for (std::size_t k = 0; k < node.size(); ++k)
    if (!std::isnan(node[k])) node_rise = std::max(node_rise, node[k] - kT0), patch_rise = std::max(patch_rise, patch[k] - kT0);
  EXPECT_LT(patch_rise, node_rise) << "a patch spreads the hottest node's heat";
  const double bound = 0.1 * (kRtol * (kT0 + node_rise) + kAtol) + 1e-9 * node_rise;
  EXPECT_LE(max_difference(node, column("split.h5", "max_node_interface_temperature"), "node column"), bound);
  std::printf("  hottest patch rise %.4g K, hottest node rise %.4g K\n", patch_rise, node_rise);
}

// The same with hot spots judged by the interface temperature: a rise of 0.05 K, which the interface
// reaches at the walls and the grid temperature (≈ 9 mK) does not; the same hot spots (count, peak,
// size every row), the same /hotspots rows and the same fates in the continuation. Measured: 44 hot
// spots at the end of loading, 67 /hotspots rows, all dying.
TEST_F(MpirunInterface, PbxHotSpotsByInterfaceTemperatureEqualTheSerialRun) {
  run_both(kScene,
           std::string(kSets) +
               " --set 'coupling.hotspots={\"temperature\":\"interface\",\"mode\":\"rise\",\"threshold\":0.05,"
               "\"min_particles\":2}'",
           2);
  if (HasFatalFailure()) return;
  compare();
  const std::vector<double> count = column("serial.h5", "hotspot_count");
  EXPECT_GT(*std::max_element(count.begin(), count.end()), 0.0) << "the interface makes hot spots";
  EXPECT_EQ(count, column("split.h5", "hotspot_count"));
  const double bound = 0.1 * (kRtol * 293.2 + kAtol) + 1e-9;
  EXPECT_LE(max_difference(column("serial.h5", "hottest_hotspot_temperature"),
                           column("split.h5", "hottest_hotspot_temperature"), "hottest"),
            bound);
  expect_same_column("hottest_hotspot_size", 1e-12);
  for (const char* c : {"id", "particle_count"})  // the same spots of the same particles
    EXPECT_EQ(read_doubles(path("serial.h5"), std::string("/hotspots/") + c),
              read_doubles(path("split.h5"), std::string("/hotspots/") + c))
        << c;
  // Times and sizes to round-off (the decomposed steps' times agree to an ulp or so; the particles'
  // volumes to the mechanics' round-off).
  for (const char* c : {"time", "size"}) {
    const std::vector<double> a = read_doubles(path("serial.h5"), std::string("/hotspots/") + c);
    const std::vector<double> b = read_doubles(path("split.h5"), std::string("/hotspots/") + c);
    ASSERT_EQ(a.size(), b.size()) << c;
    ASSERT_FALSE(a.empty()) << c;
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-12 * std::fabs(a[k])) << c << " row " << k;
  }
  // The continuation's fates, judged by the interface temperature: the same spots, fates and times.
  for (const char* c : {"id", "fate", "particle_count", "start_time", "decision_time"}) {
    const std::vector<double> x = read_doubles(path("serial.h5"), std::string("/hotspot_fates/") + c);
    EXPECT_FALSE(x.empty()) << c;
    EXPECT_EQ(x, read_doubles(path("split.h5"), std::string("/hotspot_fates/") + c)) << c;
  }
}

}  // namespace
