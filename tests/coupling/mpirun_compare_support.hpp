// A scene run by `frictherm run` and by `mpirun -n K frictherm run`, and their series compared column
// by column (tests/coupling/test_cli_mpirun_loads.cpp, test_cli_mpirun_musl.cpp).
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
};

}  // namespace frictherm::test
