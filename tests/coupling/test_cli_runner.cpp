// The run loop behind `frictherm run`, called as a library: step clamping onto snapshot times and
// end_time, max_steps, and a failing run's result.
#include <frictherm/coupling/csv_export.hpp>
#include <frictherm/coupling/runner.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <hdf5.h>

#include "cli_test_support.hpp"

#include <filesystem>
#include <sstream>
#include <unistd.h>

namespace fc = frictherm::coupling;
namespace fs = std::filesystem;

namespace {

// The program tests' small scene (cli_test_support.hpp) with snapshots every 0.3 ms and no series.
fc::Json tiny_scene() {
  fc::Json j = fc::Json::parse(frictherm::test::kTinyScene);
  j["output"] = fc::Json::parse(R"({"snapshot_interval": 3e-4, "series_interval": 0})");
  return j;
}

/// (step, time) of every regular snapshot, in order.
std::vector<std::pair<long, double>> snapshot_times(const std::string& h5) {
  std::vector<std::pair<long, double>> out;
  const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  const hid_t g = H5Gopen2(f, "/snapshots", H5P_DEFAULT);
  H5G_info_t info;
  H5Gget_info(g, &info);
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%06llu", static_cast<unsigned long long>(i));
    const hid_t s = H5Gopen2(g, name, H5P_DEFAULT);
    double t = -1;
    long long step = -1;
    hid_t a = H5Aopen(s, "time", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, &t);
    H5Aclose(a);
    a = H5Aopen(s, "step", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_LLONG, &step);
    H5Aclose(a);
    H5Gclose(s);
    out.emplace_back(static_cast<long>(step), t);
  }
  H5Gclose(g);
  H5Fclose(f);
  return out;
}

class Runner : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("frictherm_runner_" + std::string(info->name()) + "_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fc::RunResult run(const fc::Json& scene, const std::string& name) {
    fc::RunOptions opt;
    opt.output = (dir_ / name).string();
    opt.quiet = true;
    opt.log = &log_;
    return fc::run_scene(fc::parse_scene(scene.dump()), opt);
  }
  fs::path dir_;
  std::ostringstream log_;
};

}  // namespace

TEST_F(Runner, LandsExactlyOnSnapshotTimesAndEndTime) {
  const fc::RunResult r = run(tiny_scene(), "a.h5");
  ASSERT_EQ(r.status, fc::RunResult::Status::completed);
  EXPECT_EQ(r.exit_code(), 0);
  EXPECT_EQ(r.time, 2e-3);
  const auto snaps = snapshot_times(r.output);
  ASSERT_EQ(snaps.size(), 8u);  // 0, 3e-4, ..., 1.8e-3, and end_time 2e-3
  for (std::size_t k = 0; k + 1 < snaps.size(); ++k)
    EXPECT_NEAR(snaps[k].second, 3e-4 * static_cast<double>(k), 1e-18) << k;
  EXPECT_EQ(snaps.back().second, 2e-3);
  EXPECT_EQ(snaps.back().first, r.steps);
  // series_interval 0: one row per step plus t = 0.
  const fc::SeriesTable series = fc::read_series(r.output);
  EXPECT_EQ(series.rows(), static_cast<std::size_t>(r.steps) + 1);
  ASSERT_EQ(series.names.size(), 20u);
  EXPECT_EQ(series.names[0], "time");
  EXPECT_EQ(series.names[8], "momentum_y");
  EXPECT_EQ(series.names[9], "rigid_work");  // the energy balance follows the momenta
  EXPECT_EQ(series.names[13], "numerical_dissipation");
  EXPECT_EQ(series.names[14], "contact_normal_work");
  EXPECT_EQ(series.names[15], "boundary_stop_work");
  EXPECT_EQ(series.names[16], "stored_energy_lead");
  EXPECT_EQ(series.names[17], "mean_temperature.block");
  EXPECT_EQ(series.names[19], "mean_displacement_y.block");
  // momentum of the freely moving block is conserved
  EXPECT_NEAR(series.columns[7].back(), series.columns[7].front(), 1e-12);
}

TEST_F(Runner, StopsAtMaxStepsWithAFinalSnapshot) {
  fc::Json s = tiny_scene();
  s["run"]["max_steps"] = 5;
  const fc::RunResult r = run(s, "b.h5");
  EXPECT_EQ(r.status, fc::RunResult::Status::stopped_at_max_steps);
  EXPECT_EQ(r.exit_code(), 0);
  EXPECT_EQ(r.steps, 5);
  EXPECT_EQ(snapshot_times(r.output).back().first, 5);
  EXPECT_EQ(log_.str(), "");  // quiet
}

TEST_F(Runner, FailureIsReportedNotThrown) {
  fc::Json s = tiny_scene();
  s["bodies"][0]["velocity"] = {500, 0};
  const fc::RunResult r = run(s, "c.h5");
  EXPECT_EQ(r.status, fc::RunResult::Status::failed);
  EXPECT_EQ(r.exit_code(), 1);
  EXPECT_THAT(r.message, ::testing::HasSubstr("left the grid"));
  EXPECT_GE(r.snapshots, 1u);
  EXPECT_EQ(snapshot_times(r.output).size(), r.snapshots);
}
