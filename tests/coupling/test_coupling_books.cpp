// Verification (issue 4): energy books of a whole run with frictional heating — the sliding-block
// example with a thermal section, through the runner, for every window policy.
#include "h5_test_support.hpp"
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace fc = frictherm::coupling;
namespace fs = std::filesystem;
using fc::Json;

namespace {

using frictherm::test::read_doubles;

}  // namespace

// Issue 4's energy books end to end: the sliding-block example (Coulomb friction between a block and
// its base) with a thermal section, for every window policy. The frictional work the mechanics
// reports (second order), the heat the coupler delivered and Σ_p m_p C_p ΔT_p agree to 1e-9 relative.
// (Q matches W to round-off; Σ m C ΔT carries the round-off of adding ~1e-5 K increments to ~293 K
// particle temperatures every window: ~4e-10 with 10^4 windows.)
TEST(SceneThermalRun, SlidingBlockEnergyBooksCloseForEveryWindowPolicy) {
  std::ifstream in(std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block.json");
  ASSERT_TRUE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  const Json base = fc::parse_json_text(text.str());
  const fs::path dir = fs::temp_directory_path() / ("frictherm_thermal_books_" + std::to_string(getpid()));
  fs::create_directories(dir);
  // cvode_bdf for every policy, and the scene default "auto" (matrix-free forward Euler with the
  // gather reused, issue 13) with a window every step; last, an insulating block (conductivity 0:
  // the nodes only it reaches have a zero row in K, summed from round-off).
  const struct {
    const char* integrator;
    const char* window;
    const char* insulator;
  } cases[] = {{"cvode_bdf", R"("every_step")", ""},
               {"cvode_bdf", R"({"policy": "every_n_steps", "steps": 25})", ""},
               {"cvode_bdf", R"({"policy": "adaptive", "max_temperature_rise": 0.05})", ""},
               {"auto", R"("every_step")", ""},
               {"cvode_bdf", R"({"policy": "adaptive", "max_temperature_rise": 0.05})", "block"}};
  for (const auto& [integrator, window, insulator] : cases) {
    SCOPED_TRACE(std::string(integrator) + " " + window + " " + insulator);
    Json s = base;
    Json mats = Json::object();
    for (auto it = s["materials"].begin(); it != s["materials"].end(); ++it)
      if (it.value()["type"] != "rigid")
        mats[it.key()] = Json::parse(it.key() == insulator ? R"({"heat_capacity": 1000, "conductivity": 0})"
                                                           : R"({"heat_capacity": 1000, "conductivity": 1})");
    s["thermal"] = Json::parse(R"({"rtol": 1e-8, "atol": 1e-8})");
    s["thermal"]["integrator"] = integrator;
    s["thermal"]["materials"] = mats;
    s["coupling"] = Json::object();
    s["coupling"]["window"] = Json::parse(window);
    s["coupling"]["heating_order"] = "second";  // the column read below
    s["output"] = Json::parse(R"({"snapshot_count": 2})");
    fc::RunOptions opt;
    opt.output = (dir / "books.h5").string();
    opt.overwrite = true;  // one file for the three window policies, read before the next run
    opt.quiet = true;
    const fc::RunResult r = fc::run_scene(fc::parse_scene(s.dump()), opt);
    ASSERT_EQ(r.status, fc::RunResult::Status::completed) << r.message;
    const double W = read_doubles(r.output, "/series/friction_work_second").back();
    const double Q = read_doubles(r.output, "/series/heat_delivered").back();
    const double E = read_doubles(r.output, "/series/thermal_energy_change").back();
    std::cout << "[sliding block books] " << integrator << " " << window << ": W2 = " << W << " J, |Q - W|/W = " << std::fabs(Q - W) / W
              << ", |ΣmCΔT - W|/W = " << std::fabs(E - W) / W << ", windows "
              << read_doubles(r.output, "/meta/thermal_windows").at(0) << '\n';
    ASSERT_GT(W, 0.0);
    EXPECT_LT(std::fabs(Q - W), 1e-9 * W);
    EXPECT_LT(std::fabs(E - W), 1e-9 * W);
  }
  fs::remove_all(dir);
}
