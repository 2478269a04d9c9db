// Builds against the installed headers and libraries through the front door: a scene file, run_scene
// with a per-step observer, and the series read back. A block falls freely under gravity; its
// mass-weighted mean velocity is v = g t exactly (a uniform body force on an unconstrained body), and
// the kinetic energy the observer records each step is the series' kinetic_energy column.
#include <frictherm/coupling.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <vector>

namespace fc = frictherm::coupling;

int main() {
  const char* scene_path = "consumer_scene.json";
  std::ofstream(scene_path) << R"({
    "units": "SI", "dimension": 2, "grid": {"lo": [0, 0], "hi": [0.1, 0.1], "cell_size": 0.01},
    "materials": {"block": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e7, "poisson_ratio": 0.3}},
    "bodies": [{"name": "block", "material": "block", "shape": {"type": "rectangle", "lo": [0.03, 0.05], "hi": [0.07, 0.09]}}],
    "loads": {"gravity": [0, -9.81]},
    "run": {"end_time": 1e-3},
    "output": {"snapshot_count": 2, "series_interval": 0}
  })";
  fc::RunOptions opt;
  opt.output = "consumer_run.h5";
  opt.overwrite = true;  // a rerun of the test replaces its own result
  opt.quiet = true;
  std::vector<double> ke;
  double t = 0.0, vy = 0.0;
  opt.observer = [&](const fc::StepView& s) {
    ke.push_back(s.kinetic_energy());
    const auto& p = s.simulation<2>().particles();
    double m = 0.0, mv = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) m += p.mass[k], mv += p.mass[k] * p.velocity[k][1];
    t = s.time(), vy = mv / m;
  };
  const fc::RunResult r = fc::run_scene(fc::load_scene(scene_path), opt);
  const fc::SeriesTable series = fc::read_series(r.output);
  const std::vector<double>& series_ke = series.column("kinetic_energy");
  bool same = series_ke.size() == ke.size() + 1;  // the series also has the row of t = 0
  for (std::size_t k = 0; same && k < ke.size(); ++k) same = series_ke[k + 1] == ke[k];
  std::printf("consumer: %ld steps, v = %.9g m/s after t = %.6g s (expected %.9g); observer KE %s the series\n",
              r.steps, vy, t, -9.81 * t, same ? "matches" : "DIFFERS FROM");
  return r.exit_code() == 0 && same && t == r.time && std::abs(vy + 9.81 * t) < 1e-9 ? 0 : 1;
}
