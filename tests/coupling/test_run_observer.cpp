// The per-step observer of run_scene (runner.hpp, issue 14 item 4): called once after every
// mechanics step with the state the series row was made from, so a diagnostic recorded there equals
// the series column bit for bit.
#include <frictherm/coupling.hpp>

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <stdexcept>

namespace fc = frictherm::coupling;
namespace fs = std::filesystem;

namespace {

// An elastic block thrown at 2 m/s against a fixed wall face: its kinetic energy changes every step
// once it is squeezed, so equality cannot come from a constant.
const char* kScene = R"({
  "units": "SI", "dimension": 2, "grid": {"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0.005},
  "materials": {"rubber": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3}},
  "bodies": [{"name": "block", "material": "rubber", "velocity": [-2.0, 0.0],
              "shape": {"type": "rectangle", "lo": [0.006, 0.01], "hi": [0.046, 0.04]}}],
  "boundary": {"fixed": [{"face": "x_min"}]},
  "run": {"end_time": 2e-3},
  "output": {"snapshot_count": 2, "series_interval": 0}
})";

// One folder per process, emptied first: outputs are never replaced (issue 15), so a file left by
// an earlier or concurrent run would make this one refuse to write.
fs::path scratch() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / ("frictherm_test_run_observer_" + std::to_string(getpid()));
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
  }();
  return d;
}

}  // namespace

TEST(RunObserver, KineticEnergyRecordedEachStepMatchesTheSeries) {
  fc::RunOptions o;
  o.output = (scratch() / "observer.h5").string();
  o.quiet = true;
  o.overwrite = true;  // a fixed scratch path: the test must run again (outputs are not replaced silently)
  o.threads = 1;
  std::vector<long> steps;
  std::vector<double> ke, time;
  o.observer = [&](const fc::StepView& s) {
    EXPECT_EQ(s.dim(), 2);
    steps.push_back(s.step());
    ke.push_back(s.kinetic_energy());
    time.push_back(s.time());
  };
  const fc::RunResult r = fc::run_scene(fc::parse_scene(kScene), o);
  ASSERT_EQ(r.status, fc::RunResult::Status::completed);
  ASSERT_EQ(steps.size(), static_cast<std::size_t>(r.steps));
  const fc::SeriesTable s = fc::read_series(r.output);
  ASSERT_EQ(s.rows(), steps.size() + 1);  // plus the row of t = 0
  const auto& series_ke = s.column("kinetic_energy");
  const auto& series_step = s.column("step");
  const auto& series_time = s.column("time");
  double lowest = series_ke.front(), highest = series_ke.front();
  for (std::size_t k = 0; k < steps.size(); ++k) {
    EXPECT_EQ(steps[k], static_cast<long>(k + 1));
    EXPECT_EQ(series_step[k + 1], static_cast<double>(steps[k]));
    EXPECT_EQ(series_time[k + 1], time[k]);
    EXPECT_EQ(series_ke[k + 1], ke[k]) << "step " << steps[k];  // the same state, the same sum
    lowest = std::min(lowest, ke[k]), highest = std::max(highest, ke[k]);
  }
  // The block hits the wall: at least a tenth of its 0.5 m v^2 = 2 J/kg x mass is turned into strain energy.
  EXPECT_LT(lowest, 0.9 * highest);
}

TEST(RunObserver, WrongDimensionAndObserverErrorsAreReported) {
  fc::RunOptions o;
  o.output = (scratch() / "observer_error.h5").string();
  o.quiet = true;
  o.overwrite = true;  // a fixed scratch path: the test must run again (outputs are not replaced silently)
  o.threads = 1;
  int calls = 0;
  o.observer = [&](const fc::StepView& s) {
    ++calls;
    EXPECT_THROW(s.simulation<3>(), std::logic_error);
    if (calls == 5) throw std::runtime_error("observer gave up");
  };
  EXPECT_THROW(
      {
        try {
          fc::run_scene(fc::parse_scene(kScene), o);
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "observer gave up");
          throw;
        }
      },
      std::runtime_error);
  EXPECT_EQ(calls, 5);
  EXPECT_GE(fc::read_series(o.output).rows(), 5u);  // what was written before stays readable
}
