// Coupled throughput (issue 13): the sliding-block twin scene (plane strain, base 140 x 25 mm fixed at
// its bottom, block 40 x 15 mm on it with v0 = 10 m/s, uGIMP 2 x 2 particles per cell, E = 2500 MPa,
// nu = 0.33, rho = 1000, Coulomb mu = 0.2, AVG normals, gravity 1000 g, k = 0.4 W/(m K),
// C_v = 1000 J/(kg K), forward-Euler conduction, dt pinned) at 5 mm and 1 mm cells, run through
// run_scene exactly as `frictherm run` does (output to a scratch HDF5 file with one snapshot at the start
// and one at the end). For each case: mechanics only, a window every step and an adaptive window, on
// 1 and 2 threads, and 2 threads while a busy child process spins on one core. Prints wall time, CPU
// time of this process (getrusage: all its threads), particle-steps per wall second and per CPU-second,
// and the ratios coupled/mechanics and (2 threads)/(1 thread). Asserts nothing.
// The 3D case (issue 35): examples/pbx_3d.json (85,184 particles, 17 HMX grains in binder, second-order
// frictional heating, forward-Euler conduction, USL, uGIMP) stopped after --steps3 steps (run.max_steps),
// on 1 thread: mechanics only (thermal and coupling removed), a window every step (the scene's own
// reuse_distance 0: M and G' gathered every window), a window every step with the default reuse
// (0.01 cells) and the default adaptive window; the same figures and ratios.
//   bench_coupled [--quick] [--cells 5,1] [--end5 S] [--end1 S] [--repeat N] [--scratch DIR]
//                 [--dims 2,3] [--steps3 N] [--scene3 PATH]
// --quick: 5 mm only, 2 ms, 3D 50 steps. The default end times are 10 ms at 5 mm and 1 ms at 1 mm;
// 3D: 100 steps. --repeat N (default 3): the idle cases N times, interleaved; the median-CPU run of
// each stands for it. --dims 2 or 3: one of the two cases only.
#include "cpu_time.hpp"
#include <frictherm/coupling/instruction_set.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>
#include <frictherm/coupling/thread_policy.hpp>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sched.h>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace frictherm::coupling;

namespace {

using frictherm::bench::cpu_seconds;

enum class Mode { mechanics, every_step, adaptive, every_step_gather };
const char* name(Mode m) {
  return m == Mode::mechanics    ? "mechanics only"
         : m == Mode::every_step ? "window every step"
         : m == Mode::adaptive   ? "adaptive window"
                                 : "every step, no reuse";
}

std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

// The twin scene as JSON. dt is pinned (cfl 1 with max_time_step below the CFL limit): 1.2989663 us at
// 5 mm, scaled with the cell size at 1 mm.
std::string twin_scene(double h, double end_time, Mode mode, const std::string& output) {
  const double dt = 1.2989663e-6 * h / 0.005;
  std::string s = R"({"units": "SI", "dimension": 2, "analysis": "plane_strain", "thickness": 0.001,
    "grid": {"lo": [0.0, 0.0], "hi": [0.150, 0.045], "cell_size": )" + num(h) + R"(},
    "materials": {
      "base": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 2.5e9, "poisson_ratio": 0.33},
      "block": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 2.5e9, "poisson_ratio": 0.33}},
    "bodies": [
      {"name": "base", "material": "base", "shape": {"type": "rectangle", "lo": [0.0, 0.0], "hi": [0.140, 0.025]}},
      {"name": "block", "material": "block", "velocity": [10, 0],
       "shape": {"type": "rectangle", "lo": [0.010, 0.025], "hi": [0.050, 0.040]}}],
    "boundary": {"fixed": [{"face": "y_min"}]},
    "loads": {"gravity": [0, -9806.65]},
    "contact": {"normal": "avg",
      "pairs": [{"materials": ["base", "block"], "law": {"type": "coulomb", "mu": 0.2}}]},
    "solver": {"shape_function": "ugimp", "cfl": 1.0, "max_time_step": )" + num(dt) + R"(},
    "run": {"end_time": )" + num(end_time) + R"(},
    "output": {"file": ")" + output + R"(", "snapshot_count": 1, "series_interval": )" + num(end_time / 100) +
                  R"(})";
  if (mode != Mode::mechanics) {
    s += R"(, "thermal": {"integrator": "forward_euler",
      "materials": {"base": {"heat_capacity": 1000, "conductivity": 0.4},
                    "block": {"heat_capacity": 1000, "conductivity": 0.4}}},
    "coupling": {"window": )";
    s += mode == Mode::adaptive ? R"({"policy": "adaptive", "max_temperature_rise": 0.05})" : R"("every_step")";
    if (mode == Mode::every_step_gather) s += R"(, "reuse_distance": 0)";  // gather M and G' every window
    s += "}";
  }
  return s + "}";
}

struct Figures {
  double wall = 0, cpu = 0, rate_wall = 0, rate_cpu = 0;
  double heating_share = 0, heating_per_step = 0;
};

std::string scratch_file(const std::string& scratch) {
  return scratch + "/bench_coupled_" + std::to_string(getpid()) + ".h5";
}

Figures run_scene_case(const Scene& scene, const std::string& label, const char* mode, int threads,
                       const std::string& scratch);

Figures run_case(double h, double end_time, Mode mode, int threads, const std::string& scratch) {
  const Scene scene = parse_scene(twin_scene(h, end_time, mode, scratch_file(scratch)), "bench_coupled twin");
  char label[32];
  std::snprintf(label, sizeof label, "%4.1f mm", h * 1e3);
  return run_scene_case(scene, label, name(mode), threads, scratch);
}

Figures run_scene_case(const Scene& scene, const std::string& label, const char* mode, int threads,
                       const std::string& scratch) {
  RunOptions opt;
  opt.output = scratch_file(scratch);
  opt.threads = threads;
  opt.quiet = true;
  opt.overwrite = true;  // one scratch file per process, rewritten by every case
  const double c0 = cpu_seconds();
  const RunResult r = run_scene(scene, opt);
  Figures f;
  f.cpu = cpu_seconds() - c0;
  f.wall = r.wall_time;
  const double ps = static_cast<double>(r.particles) * static_cast<double>(r.steps);
  f.rate_wall = ps / f.wall;
  f.rate_cpu = ps / f.cpu;
  double heating = 0;
  for (const auto& [phase, sec] : r.phase_seconds)
    if (phase == "heating" || phase == "thermal_solve") heating += sec;
  f.heating_share = heating / f.wall;
  f.heating_per_step = r.steps > 0 ? heating / static_cast<double>(r.steps) : 0.0;
  std::printf("  %s  %-18s %d thr%s  %6zu particles %6ld steps  wall %7.3f s  cpu %7.3f s  "
              "%6.2f M p-steps/s  %6.2f M p-steps/cpu-s  heating+solve %4.1f %% (%5.1f us/step)\n",
              label.c_str(), mode, threads, threads > 1 ? "s" : " ", r.particles, r.steps, f.wall, f.cpu,
              f.rate_wall / 1e6, f.rate_cpu / 1e6, 100 * f.heating_share, 1e6 * f.heating_per_step);
  std::fflush(stdout);
  if (r.status == RunResult::Status::failed) std::printf("  FAILED: %s\n", r.message.c_str());
  return f;
}

Figures median_by_cpu(std::vector<Figures> runs) {
  std::sort(runs.begin(), runs.end(), [](const Figures& a, const Figures& b) { return a.cpu < b.cpu; });
  return runs[runs.size() / 2];
}

// A child process that spins on one core (CPU 0 when affinity can be set) for at most `limit` seconds.
pid_t start_busy(double limit) {
  const pid_t pid = fork();
  if (pid == 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(0, &set);
    sched_setaffinity(0, sizeof(set), &set);
    alarm(static_cast<unsigned>(limit) + 1);  // bounded even if the parent dies
    volatile unsigned long x = 0;
    for (;;) x = x + 1;
  }
  return pid;
}

void stop_busy(pid_t pid) {
  if (pid <= 0) return;
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
}

// The 3D PBX-like case on 1 thread: the modes interleaved `repeat` times, medians by CPU time.
void run_3d(const std::string& path, long steps, int repeat, const std::string& scratch) {
  const std::string max_steps = std::to_string(steps);
  struct Case3 {
    const char* mode;
    std::vector<SceneOverride> set;
  };
  const std::vector<Case3> cases = {
      {"mechanics only", {{"thermal", "null"}, {"coupling", "null"}}},
      {"every step (scene)", {}},  // reuse_distance 0: gathered every window
      {"every step, reuse", {{"coupling.reuse_distance", "null"}}},  // the default 0.01 cells
      {"adaptive window", {{"coupling.reuse_distance", "null"}, {"coupling.window", "\"adaptive\""}}},
  };
  std::printf("3D: %s, %ld steps, 1 thread\n", path.c_str(), steps);
  std::vector<Scene> scenes;
  for (const Case3& c : cases) {
    std::vector<SceneOverride> set = c.set;
    set.push_back({"run.max_steps", max_steps});
    scenes.push_back(load_scene(path, set));
  }
  std::vector<std::vector<Figures>> runs(cases.size());
  for (int r = 0; r < repeat; ++r)
    for (std::size_t m = 0; m < cases.size(); ++m)
      runs[m].push_back(run_scene_case(scenes[m], "3D PBX", cases[m].mode, 1, scratch));
  std::vector<Figures> f;
  for (auto& v : runs) f.push_back(median_by_cpu(v));
  std::printf("  medians of %d runs, 1 thread:\n", repeat);
  for (std::size_t m = 0; m < cases.size(); ++m)
    std::printf("  3D %-20s wall %7.3f s  cpu %7.3f s  %6.3f M p-steps/s  %6.3f M p-steps/cpu-s  "
                "coupled/mechanics wall %.2fx cpu %.2fx\n",
                cases[m].mode, f[m].wall, f[m].cpu, f[m].rate_wall / 1e6, f[m].rate_cpu / 1e6,
                f[m].wall / f[0].wall, f[m].cpu / f[0].cpu);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  frictherm::coupling::ensure_passive_wait(argv);  // as frictherm run does; OMP_WAIT_POLICY=active to compare
  std::vector<double> cells = {0.005, 0.001};
  double end5 = 0.010, end1 = 0.001;
  std::string scratch = "/tmp";
  int repeat = 3;
  bool dim2 = true, dim3 = true;
  long steps3 = 100;
  std::string scene3 = std::string(FRICTHERM_SOURCE_DIR) + "/examples/pbx_3d.json";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      cells = {0.005};
      end5 = 0.002;
      steps3 = 50;
    } else if (a == "--dims" && i + 1 < argc) {
      const std::string d = argv[++i];
      dim2 = d.find('2') != std::string::npos;
      dim3 = d.find('3') != std::string::npos;
    } else if (a == "--steps3" && i + 1 < argc) {
      steps3 = std::max(1L, std::atol(argv[++i]));
    } else if (a == "--scene3" && i + 1 < argc) {
      scene3 = argv[++i];
    } else if (a == "--cells" && i + 1 < argc) {
      cells.clear();
      std::string l = argv[++i];
      for (std::size_t p = 0; p < l.size();) {
        const std::size_t q = l.find(',', p);
        cells.push_back(1e-3 * std::atof(l.substr(p, q - p).c_str()));
        p = q == std::string::npos ? l.size() : q + 1;
      }
    } else if (a == "--end5" && i + 1 < argc) {
      end5 = std::atof(argv[++i]);
    } else if (a == "--end1" && i + 1 < argc) {
      end1 = std::atof(argv[++i]);
    } else if (a == "--scratch" && i + 1 < argc) {
      scratch = argv[++i];
    } else if (a == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_coupled [--quick] [--cells 5,1] [--end5 S] [--end1 S] [--repeat N] [--scratch DIR]\n"
                           "                     [--dims 2,3] [--steps3 N] [--scene3 PATH]\n");
      return 2;
    }
  }
  const char* wp = std::getenv("OMP_WAIT_POLICY");
  std::printf("bench_coupled: sliding-block twin; OMP_WAIT_POLICY=%s; %ld online CPUs; %s\n", wp ? wp : "(unset)",
              sysconf(_SC_NPROCESSORS_ONLN),
              frictherm::coupling::instruction_set());
  if (!dim2) cells.clear();
  for (const double h : cells) {
    const double end_time = h > 0.003 ? end5 : end1;
    std::printf("cell %.1f mm, end time %g s\n", h * 1e3, end_time);
    // Each case `repeat` times, the cases interleaved (the machine's drift hits them alike); the run
    // with the median CPU time stands for the case.
    std::vector<Figures> runs1[4], runs2[3];
    for (int r = 0; r < repeat; ++r) {
      for (int m = 0; m < 4; ++m) runs1[m].push_back(run_case(h, end_time, static_cast<Mode>(m), 1, scratch));
      for (int m = 0; m < 3; ++m) runs2[m].push_back(run_case(h, end_time, static_cast<Mode>(m), 2, scratch));
    }
    Figures f1[4], f2[3];
    for (int m = 0; m < 4; ++m) f1[m] = median_by_cpu(runs1[m]);
    for (int m = 0; m < 3; ++m) f2[m] = median_by_cpu(runs2[m]);
    if (repeat > 1) {
      std::printf("  medians of %d runs (CPU s): 1 thread: mechanics %.3f, every step %.3f, adaptive %.3f, no reuse %.3f; "
                  "2 threads: %.3f, %.3f, %.3f\n",
                  repeat, f1[0].cpu, f1[1].cpu, f1[2].cpu, f1[3].cpu, f2[0].cpu, f2[1].cpu, f2[2].cpu);
      std::printf("  M p-steps per CPU-second (medians): mechanics %.2f, every step %.2f (1 thread); %.2f, %.2f (2 threads)\n",
                  f1[0].rate_cpu / 1e6, f1[1].rate_cpu / 1e6, f2[0].rate_cpu / 1e6, f2[1].rate_cpu / 1e6);
    }
    std::printf("  with a busy process on CPU 0:\n");
    const pid_t busy = start_busy(20.0 * f1[1].wall + 60.0);
    Figures fb1 = run_case(h, end_time, Mode::every_step, 1, scratch);
    Figures fb2 = run_case(h, end_time, Mode::every_step, 2, scratch);
    stop_busy(busy);
    std::printf("  1 thread: every step without reuse (M, G' gathered every window): coupled/mechanics cpu %.2fx\n",
                f1[3].cpu / f1[0].cpu);
    for (int t = 0; t < 2; ++t) {
      const Figures* f = t == 0 ? f1 : f2;
      std::printf("  %d thread%s: coupled/mechanics wall  every step %.2fx  adaptive %.2fx;  cpu  every step %.2fx  "
                  "adaptive %.2fx\n",
                  t + 1, t ? "s" : " ", f[1].wall / f[0].wall, f[2].wall / f[0].wall, f[1].cpu / f[0].cpu,
                  f[2].cpu / f[0].cpu);
    }
    std::printf("  2 threads / 1 thread wall (window every step): idle %.2fx, busy core %.2fx (busy 2 thr / idle 1 thr "
                "%.2fx)\n",
                f2[1].wall / f1[1].wall, fb2.wall / fb1.wall, fb2.wall / f1[1].wall);
  }
  if (dim3) run_3d(scene3, steps3, repeat, scratch);
  return 0;
}
