// A scene run by `frictherm run` and by `mpirun -n K frictherm run`, and their series compared column
// by column, and the last snapshot's particles by id (tests/coupling/test_cli_mpirun_loads.cpp,
// test_cli_mpirun_musl.cpp, test_cli_mpirun_ebs.cpp).
#pragma once

#include "cli_test_support.hpp"
#include "h5_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace frictherm::test {

class MpirunCompare : public MpirunScratchTest {
 protected:
  MpirunCompare() : MpirunScratchTest("frictherm_mpirun_compare_") {}

  static std::string exe() { return std::string("'") + FRICTHERM_EXE + "'"; }
  static std::string source(const std::string& relative) {
    return std::string("'") + FRICTHERM_SOURCE_DIR + "/" + relative + "'";
  }

  // The scene (a path below the source tree, with `sets`: --set options) serially into serial.h5 and
  // under mpirun -n `ranks` into split.h5.
  void run_both(const std::string& scene, const std::string& sets, int ranks = 2) {
    const Result s = shell(exe() + " run " + source(scene) + sets + " -q --threads 1 --force -o '" + path("serial.h5") + "'");
    ASSERT_EQ(s.code, 0) << s.output;
    const Result d = shell(mpirun_command(ranks) + " " + exe() + " run " + source(scene) + sets + " -q --force -o '" +
                           path("split.h5") + "'");
    ASSERT_EQ(d.code, 0) << d.output;
  }

  std::vector<double> column(const std::string& file, const std::string& name) const {
    return read_doubles(path(file), "/series/" + name);
  }

  // Every row of `name` in both files within `tolerance` of the serial column's largest magnitude
  // (which must be positive: the column measures something); returns the difference over the scale.
  double expect_same_column(const std::string& name, double tolerance) const {
    const std::vector<double> a = column("serial.h5", name), b = column("split.h5", name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_EQ(a.size(), b.size()) << name;
    double scale = 0.0, diff = 0.0;
    for (double x : a) scale = std::max(scale, std::fabs(x));
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) diff = std::max(diff, std::fabs(a[k] - b[k]));
    EXPECT_GT(scale, 0.0) << name;
    EXPECT_LE(diff, tolerance * scale) << name;
    std::printf("  %-22s max |serial - split| = %.3g of %.6g\n", name.c_str(), diff / scale, scale);
    return diff / scale;
  }

  // Every column both files hold within `tolerance` of the serial column's largest magnitude (a column
  // that is 0 throughout in the serial run must be 0 in the split one); returns how many were compared.
  int compare_series(double tolerance, double floor = 1e-6) {
    const std::vector<std::string> serial = names_in(path("serial.h5"), "/series");
    int compared = 0;
    double worst = 0.0;
    for (const std::string& c : names_in(path("split.h5"), "/series")) {
      if (std::find(serial.begin(), serial.end(), c) == serial.end()) continue;
      const std::vector<double> a = column("serial.h5", c), b = column("split.h5", c);
      EXPECT_EQ(a.size(), b.size()) << c;
      double scale = 0.0, diff = 0.0;
      for (double x : a) scale = std::max(scale, std::fabs(x));
      // energy_lost and numerical_dissipation are differences of the energies, and the contact's and
      // the walls' stop work sums of impulse × velocity products of the nodes' momenta: their
      // round-off is the total energy's (a scene whose contact rests books ~1e-16 J of normal work).
      if (c == "energy_lost" || c == "numerical_dissipation" || c == "contact_normal_work" ||
          c == "boundary_stop_work" || c == "stored_energy_lead")
        for (double x : column("serial.h5", "total_energy")) scale = std::max(scale, std::fabs(x));
      for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) diff = std::max(diff, std::fabs(a[k] - b[k]));
      // A column below `floor` in magnitude is zero up to round-off in the scene (the EBS Hertz disks:
      // the momenta of the symmetric pair, ~1e-16 kg m/s; the strain energy's first rows): bounded as
      // if it were `floor`.
      EXPECT_LE(diff, tolerance * std::max(scale, floor)) << c;
      const double rel = scale > 0.0 ? diff / scale : diff;
      worst = std::max(worst, rel);
      std::printf("  %-34s max |serial - split| = %.3g of %.6g\n", c.c_str(), rel, scale);
      ++compared;
    }
    std::printf("  largest relative difference over %d columns: %.3g\n", compared, worst);
    return compared;
  }

  // The last snapshot's positions over the rank files against serial.h5's, by id: every particle held
  // once, the largest difference (m).
  double compare_positions(int ranks) {
    const std::vector<std::string> snaps = names_in(path("serial.h5"), "/snapshots");
    EXPECT_FALSE(snaps.empty());
    if (snaps.empty()) return std::nan("");
    const std::string snap = "/snapshots/" + snaps.back() + "/";
    const std::vector<double> xs = read_doubles(path("serial.h5"), snap + "position");
    const std::size_t n = xs.size() / 2;
    std::vector<int> seen(n, 0);
    double dx = 0.0;
    for (int r = 0; r < ranks; ++r) {
      const std::string f = "split.rank" + std::to_string(r) + ".h5";
      const std::vector<double> id = read_doubles(path(f), snap + "id");
      const std::vector<double> x = read_doubles(path(f), snap + "position");
      EXPECT_EQ(x.size(), 2 * id.size()) << f;
      if (x.size() != 2 * id.size()) return std::nan("");
      for (std::size_t k = 0; k < id.size(); ++k) {
        const auto i = static_cast<std::size_t>(id[k]);
        EXPECT_LT(i, n) << f;
        if (i >= n) return std::nan("");
        ++seen[i];
        for (std::size_t d = 0; d < 2; ++d) dx = std::max(dx, std::fabs(x[2 * k + d] - xs[2 * i + d]));
      }
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(n)) << "every particle once in " << snap;
    std::printf("  %s: %zu particles, largest position difference %.3g m\n", snap.c_str(), n, dx);
    return dx;
  }
};

}  // namespace frictherm::test
