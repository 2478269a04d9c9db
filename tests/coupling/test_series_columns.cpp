// Series columns users ask for (issue 14): each body's mean temperature and mean displacement, and
// the contact heat rate per pair, checked against a rigid translation and the energy books.
#include "h5_test_support.hpp"
#include <frictherm/coupling/csv_export.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fc = frictherm::coupling;
namespace fs = std::filesystem;
using fc::Json;
using frictherm::test::read_doubles;

namespace {

class SeriesColumns : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("frictherm_series_" + std::string(info->name()) + "_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fc::RunResult run(const Json& scene, const std::string& name) {
    fc::RunOptions opt;
    opt.output = (dir_ / name).string();
    opt.quiet = true;
    return fc::run_scene(fc::parse_scene(scene.dump()), opt);
  }
  fs::path dir_;
};

std::vector<double> column(const fc::SeriesTable& s, const std::string& name) {
  const auto it = std::find(s.names.begin(), s.names.end(), name);
  if (it == s.names.end()) {
    ADD_FAILURE() << "no series column " << name;
    return {};
  }
  return s.columns[static_cast<std::size_t>(it - s.names.begin())];
}

}  // namespace

// A free elastic block with a uniform velocity translates rigidly (zero velocity gradient, zero
// stress): its mean displacement is v t in every row, its mean temperature the initial one. Positions
// advance by dt times the grid velocity interpolated back, v to round-off, so 1e-10 of v t is ample.
TEST_F(SeriesColumns, MeanDisplacementOfARigidlyTranslatingBodyIsVt) {
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const std::vector<double> v = {1.0, -0.5, 0.25};
    Json s = Json::parse(dim == 2 ? R"({"dimension": 2, "grid": {"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0.01},
        "bodies": [{"name": "block", "material": "soft", "velocity": [1, -0.5], "temperature": 310,
                    "shape": {"type": "rectangle", "lo": [0.02, 0.02], "hi": [0.06, 0.04]}}]})"
                                  : R"({"dimension": 3, "grid": {"lo": [0, 0, 0], "hi": [0.1, 0.05, 0.05], "cell_size": 0.01},
        "bodies": [{"name": "block", "material": "soft", "velocity": [1, -0.5, 0.25], "temperature": 310,
                    "shape": {"type": "box", "lo": [0.02, 0.02, 0.01], "hi": [0.06, 0.04, 0.03]}}]})");
    s["materials"] = Json::parse(R"({"soft": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3}})");
    s["run"] = Json::parse(R"({"end_time": 2e-3, "threads": 1})");
    s["output"] = Json::parse(R"({"snapshot_count": 2, "series_interval": 0})");
    const fc::RunResult r = run(s, "translate" + std::to_string(dim) + "d.h5");
    ASSERT_EQ(r.status, fc::RunResult::Status::completed) << r.message;
    const fc::SeriesTable series = fc::read_series(r.output);
    const std::vector<double> t = column(series, "time");
    ASSERT_GT(t.size(), 10u);
    const char* axes[3] = {"x", "y", "z"};
    for (int d = 0; d < dim; ++d) {
      const std::vector<double> u = column(series, std::string("mean_displacement_") + axes[d] + ".block");
      ASSERT_EQ(u.size(), t.size());
      for (std::size_t i = 0; i < t.size(); ++i)
        ASSERT_NEAR(u[i], v[static_cast<std::size_t>(d)] * t[i], 1e-10 * std::abs(v[static_cast<std::size_t>(d)]) * t.back())
            << axes[d] << " row " << i;
    }
    for (const double T : column(series, "mean_temperature.block")) ASSERT_DOUBLE_EQ(T, 310.0);
  }
}

// The sliding block with frictional heating (examples/sliding_block_heating.json, a short
// continuation): contact_heat_rate.base.block times the row intervals adds up to the pair's
// second-order frictional work (the heat handed to the thermal solver) to round-off; averaged over the
// end of the sliding it is mu N v_rel (Nairn et al. 2018's rigid-block model); and the bodies' mean
// temperatures close the
// energy books: sum_b M_b C_b (mean T_b - T_b(0)) = thermal_energy_change in every row.
TEST_F(SeriesColumns, ContactHeatRateIntegratesToTheFrictionalWorkAndMeanTemperaturesCloseTheBooks) {
  std::ifstream in(std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block_heating.json");
  ASSERT_TRUE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  Json s = fc::parse_json_text(text.str());
  s["coupling"]["continuation"] = Json::parse(R"({"duration": 0.002, "intervals": 5})");
  s["output"] = Json::parse(R"({"snapshot_count": 2, "series_interval": 2e-5})");
  const fc::RunResult r = run(s, "heating.h5");
  ASSERT_EQ(r.status, fc::RunResult::Status::completed) << r.message;
  const fc::SeriesTable series = fc::read_series(r.output);
  const std::vector<double> t = column(series, "time");
  const std::vector<double> rate = column(series, "contact_heat_rate.base.block");
  const std::vector<double> total_rate = column(series, "contact_heat_rate");
  const std::vector<double> work = column(series, "friction_work_second.base.block");
  ASSERT_EQ(rate.size(), t.size());
  double integral = 0.0, integral_total = 0.0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    integral += rate[i] * (t[i] - t[i - 1]);
    integral_total += total_rate[i] * (t[i] - t[i - 1]);
  }
  EXPECT_EQ(rate.front(), 0.0);
  EXPECT_GT(work.back(), 1e-3);  // the block slid: about 0.1 J of frictional work
  EXPECT_NEAR(integral, work.back(), 1e-12 * work.back());
  EXPECT_NEAR(integral_total, column(series, "friction_work_second").back(), 1e-12 * work.back());
  std::printf("[series] contact heat: integral of the rate %.15g J, frictional work %.15g J\n", integral, work.back());

  // Against mu N v_rel (the rigid-block model): the rate is bursty from row to row (nodes entering and
  // leaving contact hand over their work in lumps: 0.3 to 1.6 times mu N v_rel per 2e-5 s row late in
  // the sliding), so it is compared averaged over the last 2 ms of the sliding: measured 1.1 % low,
  // within 3 %. The continuation rows (thermal only, the mechanics stopped) have no contact heat.
  const std::vector<double> step = column(series, "step");
  const std::vector<double> vblock = column(series, "mean_velocity_x.block");
  const std::vector<double> vbase = column(series, "mean_velocity_x.base");
  std::size_t last = 0;
  for (std::size_t i = 0; i < step.size(); ++i)
    if (step[i] > step[last]) last = i;
  const double N = 146847.05882352946 * 0.040 * 0.001;  // normal stress x block length x thickness (1 mm)
  double heat = 0.0, model = 0.0;
  for (std::size_t i = 1; i <= last; ++i) {
    if (t[i] <= t[last] - 2e-3) continue;
    heat += rate[i] * (t[i] - t[i - 1]);
    model += 0.2 * N * (vblock[i] - vbase[i]) * (t[i] - t[i - 1]);
  }
  std::printf("[series] last 2 ms of sliding: contact heat %.6g J, mu N v_rel dt %.6g J\n", heat, model);
  EXPECT_NEAR(heat, model, 0.03 * model);
  for (std::size_t i = last + 1; i < t.size(); ++i) EXPECT_EQ(rate[i], 0.0) << "continuation row " << i;

  // Books: body masses from the first snapshot; C = 200 J/(kg K) for both bodies (the scene).
  const std::vector<double> mass = read_doubles(r.output, "/snapshots/000000/mass");
  const std::vector<double> body = read_doubles(r.output, "/snapshots/000000/body");
  ASSERT_EQ(mass.size(), body.size());
  double M[2] = {0.0, 0.0};
  for (std::size_t k = 0; k < mass.size(); ++k) M[static_cast<int>(body[k])] += mass[k];
  const std::vector<double> Tbase = column(series, "mean_temperature.base");
  const std::vector<double> Tblock = column(series, "mean_temperature.block");
  const std::vector<double> E = column(series, "thermal_energy_change");
  ASSERT_GT(E.back(), 0.01);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double books = 200.0 * (M[0] * (Tbase[i] - Tbase[0]) + M[1] * (Tblock[i] - Tblock[0]));
    ASSERT_NEAR(books, E[i], 1e-9 * E.back()) << "row " << i << ", t = " << t[i];
  }
}
