// Scene sections `thermal` and `coupling`: parsing, validation messages, and a whole run through
// the runner (conduction between two blocks at different temperatures, continuation, /hotspots).
#include "h5_test_support.hpp"
#include "test_scene_support.hpp"

#include <frictherm/coupling/csv_export.hpp>
#include <frictherm/coupling/decomposed_support.hpp>
#include <frictherm/coupling/runner.hpp>

#include <gmock/gmock.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace fc = frictherm::coupling;
using fc::Json;
using fc::test::good_scene;
using fc::test::scene_error;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

Json thermal_scene() {
  Json s = good_scene();
  s["materials"]["anvil"] = Json::parse(R"({"type": "rigid"})");
  s["thermal"] = Json::parse(R"({
    "integrator": "forward_euler", "rtol": 1e-5, "atol": 1e-3,
    "forward_euler": {"stability": "refuse", "safety": 0.5},
    "active_mass_fraction": 1e-8,
    "materials": {"steel": {"heat_capacity": 490, "conductivity": 45}},
    "fixed_temperature": [{"face": "y_min", "temperature": 310}]
  })");
  s["coupling"] = Json::parse(R"({
    "window": {"policy": "adaptive", "max_temperature_rise": 0.5, "max_duration": 1e-6, "max_steps": 100},
    "heating_order": "first",
    "continuation": {"duration": 1e-3, "intervals": 20},
    "hotspots": {"mode": "absolute", "threshold": 450, "link_factor": 2, "min_particles": 3}
  })");
  return s;
}

}  // namespace

TEST(SceneThermal, FullSectionsParse) {
  const fc::Scene s = fc::parse_scene(thermal_scene().dump());
  const fc::ThermalSceneSpec& t = s.thermal;
  ASSERT_TRUE(t.enabled);
  EXPECT_EQ(t.coupler.integrator, "forward_euler");
  EXPECT_EQ(t.coupler.integrator_options.rtol, 1e-5);
  EXPECT_EQ(t.coupler.integrator_options.atol, 1e-3);
  EXPECT_EQ(t.coupler.integrator_options.fe_stability_policy, "refuse");
  EXPECT_EQ(t.coupler.integrator_options.fe_safety, 0.5);
  EXPECT_EQ(t.coupler.assembly.active_mass_fraction, 1e-8);
  ASSERT_EQ(t.coupler.materials.size(), 2u);
  EXPECT_TRUE(t.coupler.materials[0].conducts);
  EXPECT_EQ(t.coupler.materials[0].heat_capacity, 490.0);
  EXPECT_EQ(t.coupler.materials[0].conductivity, 45.0);
  EXPECT_FALSE(t.coupler.materials[1].conducts);  // the rigid anvil may be left out
  ASSERT_EQ(t.coupler.fixed_faces.size(), 1u);
  EXPECT_EQ(t.coupler.fixed_faces[0].axis, 1);
  EXPECT_FALSE(t.coupler.fixed_faces[0].upper);
  EXPECT_EQ(t.coupler.fixed_faces[0].temperature, 310.0);
  EXPECT_EQ(t.coupler.window.kind, fc::WindowPolicy::Kind::adaptive);
  EXPECT_EQ(t.coupler.window.max_temperature_rise, 0.5);
  EXPECT_EQ(t.coupler.window.max_duration, 1e-6);
  EXPECT_EQ(t.coupler.window.max_steps, 100);
  EXPECT_EQ(t.heating_order, fc::HeatingOrder::first);
  EXPECT_EQ(t.continuation_duration, 1e-3);
  EXPECT_EQ(t.continuation_intervals, 20);
  EXPECT_EQ(t.coupler.hotspots.mode, fc::HotSpotOptions::Mode::absolute);
  EXPECT_EQ(t.coupler.hotspots.threshold, 450.0);
  EXPECT_EQ(t.coupler.hotspots.link_factor, 2.0);
  EXPECT_EQ(t.coupler.hotspots.min_particles, 3u);
  EXPECT_EQ(t.coupler.thickness, 1.0);
}

TEST(SceneThermal, DefaultsAndAbsence) {
  EXPECT_FALSE(fc::parse_scene(good_scene().dump()).thermal.enabled);  // nothing thermal without the section
  Json s = good_scene();
  s["thickness"] = 0.002;
  s["thermal"] = Json::parse(R"({"materials": {"steel": {"heat_capacity": 490, "conductivity": 45}}})");
  const fc::ThermalSceneSpec t = fc::parse_scene(s.dump()).thermal;
  EXPECT_TRUE(t.enabled);
  EXPECT_EQ(t.coupler.integrator, "auto");  // issue 13: matrix-free FE for short windows, cvode_bdf beyond
  EXPECT_EQ(t.coupler.reuse_distance, 0.01);
  EXPECT_EQ(t.coupler.window.kind, fc::WindowPolicy::Kind::adaptive);  // issue 13: adaptive by default
  EXPECT_EQ(t.coupler.window.max_temperature_rise, 0.1);
  EXPECT_EQ(t.heating_order, fc::HeatingOrder::second);
  EXPECT_EQ(t.continuation_duration, 0.0);
  EXPECT_EQ(t.coupler.hotspots.mode, fc::HotSpotOptions::Mode::rise);
  EXPECT_EQ(t.coupler.thickness, 0.002);
  s["coupling"] = Json::parse(R"({"window": "every_step"})");
  EXPECT_EQ(fc::parse_scene(s.dump()).thermal.coupler.window.kind, fc::WindowPolicy::Kind::every_step);
  s["coupling"] = Json::parse(R"({"window": {"policy": "every_n_steps", "steps": 12}})");
  EXPECT_EQ(fc::parse_scene(s.dump()).thermal.coupler.window.steps, 12);
}

// coupling.heating_order, when the scene names none, follows the update scheme (docs/coupling.md,
// "Which heating order"): first under USL and USF, second under MUSL; a named order is kept, and the
// books of a run without a thermal section use the same default.
TEST(SceneThermal, HeatingOrderDefaultFollowsTheScheme) {
  Json s = good_scene();
  s["thermal"] = Json::parse(R"({"materials": {"steel": {"heat_capacity": 490, "conductivity": 45}}})");
  const auto order = [&](const char* scheme) {
    s["solver"]["scheme"] = scheme;
    return fc::parse_scene(s.dump()).thermal.heating_order;
  };
  EXPECT_EQ(order("usl"), fc::HeatingOrder::first);
  EXPECT_EQ(order("usf"), fc::HeatingOrder::first);
  EXPECT_EQ(order("musl"), fc::HeatingOrder::second);
  s["coupling"] = Json::parse(R"({"heating_order": "second"})");
  EXPECT_EQ(order("usl"), fc::HeatingOrder::second);
  s["coupling"] = Json::parse(R"({"heating_order": "first"})");
  EXPECT_EQ(order("musl"), fc::HeatingOrder::first);
  s.erase("coupling");
  s.erase("thermal");
  EXPECT_EQ(order("usl"), fc::HeatingOrder::first);
}

TEST(SceneThermal, ErrorsNameTheKeyPath) {
  struct Bad {
    const char* pointer;
    Json value;
    const char* message;  // expected start of the error
  };
  const std::vector<Bad> cases{
      {"/thermal/rtol", 2.0, "thermal.rtol: expected a number in [1e-14, 1), got 2"},
      {"/thermal/atol", 0.0, "thermal.atol: expected a number > 0, got 0"},
      {"/thermal/integrator", "rk4", "thermal.integrator: expected one of \"auto\", \"forward_euler\", \"cvode_bdf\""},
      {"/thermal/materials/steel/heat_capacity", -1.0, "thermal.materials.steel.heat_capacity: expected a number > 0"},
      {"/thermal/materials/steel/conductivity", "high", "thermal.materials.steel.conductivity: expected a number >= 0"},
      {"/thermal/materials/steel/density", 1.0, "thermal.materials.steel.density: unknown key"},
      {"/thermal/materials/unobtanium", Json::parse(R"({"heat_capacity": 1, "conductivity": 1})"),
       "thermal.materials.unobtanium: no material of this name in \"materials\" (defined: steel, anvil)"},
      {"/thermal/linear_solver", "klu", "thermal.linear_solver: not used by the explicit integrator forward_euler"},
      {"/thermal/fixed_temperature/0/face", "x_mid", "thermal.fixed_temperature[0].face: expected one of"},
      {"/thermal/fixed_temperature/0/temperature", -3.0, "thermal.fixed_temperature[0].temperature: expected a number > 0"},
      {"/thermal/solver", "fast", "thermal.solver: unknown key"},
      {"/coupling/window/policy", "sometimes", "coupling.window.policy: expected one of \"every_step\""},
      {"/coupling/window/max_temperature_rise", 0.0, "coupling.window.max_temperature_rise: expected a number > 0"},
      {"/coupling/window/steps", 3, "coupling.window.steps: unknown key"},
      {"/coupling/heating_order", "third", "coupling.heating_order: expected one of \"first\", \"second\", got \"third\""},
      {"/coupling/continuation/duration", -1.0, "coupling.continuation.duration: expected a number in (0, 1e+12], got -1"},
      {"/coupling/continuation/intervals", 2.5, "coupling.continuation.intervals: expected an integer in [1, 100000]"},
      {"/coupling/hotspots/mode", "relative", "coupling.hotspots.mode: expected one of \"rise\", \"absolute\""},
      {"/coupling/hotspots/link_factor", 0.5, "coupling.hotspots.link_factor: expected a number in [1, 10]"},
      {"/coupling/mode", "two_way", "coupling.mode: unknown key"},
      {"/coupling/subgrid_relaxation_time", 0.0, "coupling.subgrid_relaxation_time: expected a number > 0"},
  };
  for (const Bad& b : cases) {
    SCOPED_TRACE(b.pointer);
    Json s = thermal_scene();
    s[Json::json_pointer(b.pointer)] = b.value;
    EXPECT_THAT(scene_error(s), StartsWith(b.message));
  }
  Json s = thermal_scene();
  s["thermal"]["materials"].erase("steel");
  EXPECT_THAT(scene_error(s), StartsWith("thermal.materials: missing material \"steel\""));
  s = thermal_scene();
  s.erase("thermal");
  EXPECT_THAT(scene_error(s), StartsWith("coupling: needs a \"thermal\" section"));
  s = thermal_scene();
  s["thermal"]["integrator"] = "cvode_bdf";
  EXPECT_THAT(scene_error(s), StartsWith("thermal.forward_euler: only for \"integrator\": \"forward_euler\""));
  s = thermal_scene();
  s["coupling"]["window"] = Json::parse(R"({"policy": "every_n_steps"})");
  EXPECT_THAT(scene_error(s), StartsWith("coupling.window.steps: required key missing"));
  s = thermal_scene();
  s["coupling"]["window"] = "adaptive";  // the default rise
  EXPECT_EQ(fc::parse_scene(s.dump()).thermal.coupler.window.kind, fc::WindowPolicy::Kind::adaptive);
  EXPECT_EQ(fc::parse_scene(s.dump()).thermal.coupler.window.max_temperature_rise, 0.1);
  s["coupling"]["window"] = Json::parse(R"({"policy": "adaptive", "max_duration": 1e-5})");
  EXPECT_EQ(fc::parse_scene(s.dump()).thermal.coupler.window.max_temperature_rise, 0.1);
  EXPECT_EQ(fc::parse_scene(s.dump()).thermal.coupler.window.max_duration, 1e-5);
}

namespace {

namespace fs = std::filesystem;

using frictherm::test::read_doubles;

std::string read_string(const std::string& file, const std::string& path) {
  std::string out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  if (d >= 0) {
    const hid_t t = H5Dget_type(d);
    out.assign(H5Tget_size(t), '\0');
    H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    out.erase(std::find(out.begin(), out.end(), '\0'), out.end());
    H5Tclose(t);
    H5Dclose(d);
  }
  H5Fclose(f);
  return out;
}

}  // namespace

// Two soft blocks in contact, 400 K and 300 K, same ρ C: conduction (α = 0.1 m²/s, so the 16 mm
// pair equilibrates in a few ms) during 2 ms of mechanics and a 5 ms thermal-only continuation.
// Adiabatic edges: Σ m C T stays constant and everything ends at 350 K (the sub-grid relaxation,
// τ = 0.2 ms, removes the particle-scale part of the initial step that the grid cannot see).
// With cvode_bdf, and with the default "auto" (matrix-free forward Euler windows, then a fresh
// cvode_bdf for the continuation: the default once failed there, asking the factory for "auto").
TEST(SceneThermalRun, ConductionBetweenBlocksThroughTheRunner) {
  for (const char* integrator : {"cvode_bdf", "auto"}) {
  SCOPED_TRACE(integrator);
  Json scene = Json::parse(R"({
    "dimension": 2, "thickness": 0.002,
    "grid": {"lo": [0, 0], "hi": [0.02, 0.01], "cell_size": 0.001},
    "materials": {"hot": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3},
                  "cold": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3}},
    "bodies": [{"name": "a", "material": "hot", "temperature": 400,
                "shape": {"type": "rectangle", "lo": [0.002, 0.002], "hi": [0.01, 0.008]}},
               {"name": "b", "material": "cold", "temperature": 300,
                "shape": {"type": "rectangle", "lo": [0.01, 0.002], "hi": [0.018, 0.008]}}],
    "run": {"end_time": 2e-3, "threads": 1},
    "output": {"snapshot_count": 2, "series_interval": 0},
    "thermal": {"integrator": "cvode_bdf", "rtol": 1e-8, "atol": 1e-6,
                "materials": {"hot": {"heat_capacity": 1, "conductivity": 100},
                              "cold": {"heat_capacity": 1, "conductivity": 100}}},
    "coupling": {"window": {"policy": "every_n_steps", "steps": 10},
                 "continuation": {"duration": 5e-3, "intervals": 10},
                 "subgrid_relaxation_time": 2e-4,
                 "hotspots": {"mode": "absolute", "threshold": 380}}
  })");
  scene["thermal"]["integrator"] = integrator;
  const fs::path dir = fs::temp_directory_path() / ("frictherm_thermal_run_" + std::to_string(getpid()));
  fs::create_directories(dir);
  fc::RunOptions opt;
  opt.output = (dir / "run.h5").string();
  opt.quiet = true;
  const fc::RunResult r = fc::run_scene(fc::parse_scene(scene.dump()), opt);
  ASSERT_EQ(r.status, fc::RunResult::Status::completed) << r.message;
  const fc::SeriesTable series = fc::read_series(r.output);
  auto column = [&](const std::string& name) {
    const auto it = std::find(series.names.begin(), series.names.end(), name);
    EXPECT_NE(it, series.names.end()) << name;
    return it == series.names.end() ? std::vector<double>{} : series.columns[static_cast<std::size_t>(it - series.names.begin())];
  };
  const auto time = column("time"), heat = column("heat_delivered"), de = column("thermal_energy_change"),
             tmax = column("max_temperature"), count = column("hotspot_count"), windows = column("thermal_windows");
  ASSERT_EQ(series.rows(), static_cast<std::size_t>(r.steps) + 1 + 10);  // + continuation rows
  EXPECT_NEAR(time.back(), 7e-3, 1e-15);
  // Σ m C T ≈ 2 blocks · 1000 kg/m³ · 4.8e-5 m² · 0.002 m · 1 · 350 K = 0.0336 J; its change stays at round-off.
  for (double x : heat) EXPECT_EQ(x, 0.0);
  for (double x : de) EXPECT_LT(std::fabs(x), 1e-12 * 0.0336);
  EXPECT_EQ(tmax.front(), 400.0);
  EXPECT_EQ(count.front(), 1.0);  // the hot block is one hot spot at t = 0
  EXPECT_LT(tmax.back(), 350.0 + 0.01);
  EXPECT_EQ(count.back(), 0.0);
  // Issue 14 item 6: with no hot spot the hottest_hotspot_* columns are undefined (NaN), with one they hold its peak.
  EXPECT_EQ(column("hottest_hotspot_temperature").front(), 400.0);
  for (const char* c : {"hottest_hotspot_temperature", "hottest_hotspot_size", "hottest_hotspot_diameter"})
    EXPECT_TRUE(std::isnan(column(c).back())) << c;
  for (std::size_t k = 1; k < tmax.size(); ++k) EXPECT_LE(tmax[k], tmax[k - 1] + 1e-6);  // maximum principle (to atol)
  // Windows of 10 steps, one cut short at the snapshot at t = 1 ms, then 10 continuation intervals.
  EXPECT_GE(windows.back(), static_cast<double>((r.steps + 9) / 10 + 10));
  EXPECT_LE(windows.back(), static_cast<double>((r.steps + 9) / 10 + 11));
  // Final snapshot (end of the continuation): everything at 350 K.
  char name[32];
  std::snprintf(name, sizeof name, "/snapshots/%06zu/temperature", r.snapshots - 1);
  const auto T = read_doubles(r.output, name);
  ASSERT_EQ(T.size(), r.particles);
  for (double x : T) EXPECT_NEAR(x, 350.0, 0.01);
  // /hotspots: the hot block (id 0, born at t = 0) while it stays above 380 K.
  const auto ids = read_doubles(r.output, "/hotspots/id"), birth = read_doubles(r.output, "/hotspots/birth_time"),
             hs_time = read_doubles(r.output, "/hotspots/time"), dur = read_doubles(r.output, "/hotspots/duration");
  ASSERT_FALSE(ids.empty());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    EXPECT_EQ(ids[k], 0.0);
    EXPECT_EQ(birth[k], 0.0);
    EXPECT_NEAR(dur[k], hs_time[k], 1e-18);
  }
  // Metadata.
  EXPECT_EQ(read_string(r.output, "/meta/thermal_integrator"), integrator);
  EXPECT_EQ(read_string(r.output, "/meta/thermal_window_policy"), "every_n_steps");
  EXPECT_EQ(read_string(r.output, "/meta/heating_order"), "second");
  EXPECT_GT(read_doubles(r.output, "/meta/thermal_steps").at(0), 0.0);
  EXPECT_EQ(read_doubles(r.output, "/meta/heat_delivered").at(0), 0.0);
  EXPECT_LT(read_doubles(r.output, "/meta/max_assembly_residual").at(0), 1e-12);
  fs::remove_all(dir);
  }
}

// The decomposed run reuses the last matrix-free gather as the serial run (DecomposedHeat::reuse_window):
// a scene that leaves coupling.reuse_distance at its serial default runs there with the default
// integrator ("auto", gathering every window), and so does one that sets it (issue 32: nothing refused).
TEST(SceneThermal, DecomposedRunTakesTheDefaultReuseDistanceAndAnExplicitOne) {
  Json scene = Json::parse(R"({
    "dimension": 2,
    "grid": {"lo": [0, 0], "hi": [0.02, 0.01], "cell_size": 0.001},
    "materials": {"soft": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3}},
    "bodies": [{"name": "a", "material": "soft", "shape": {"type": "rectangle", "lo": [0.002, 0.002], "hi": [0.018, 0.008]}}],
    "run": {"end_time": 1e-3},
    "solver": {"scheme": "usl"},
    "thermal": {"materials": {"soft": {"heat_capacity": 1, "conductivity": 1}}},
    "coupling": {}
  })");
  const fc::Scene defaults = fc::parse_scene(scene.dump());
  EXPECT_EQ(defaults.thermal.coupler.integrator, "auto");
  EXPECT_EQ(fc::decomposed_run_refusal(defaults), "");
  scene["coupling"]["reuse_distance"] = 0.02;
  EXPECT_EQ(fc::decomposed_run_refusal(fc::parse_scene(scene.dump())), "");
  scene["coupling"]["reuse_distance"] = 0.0;
  EXPECT_EQ(fc::decomposed_run_refusal(fc::parse_scene(scene.dump())), "");
}
